"""The closed loop of issue 19: a campaign where two effects are confounded -> ``design
--separate`` -> the new positions measured (simulated) with either effect hidden -> ``diagnose``
names the right one, where it was a coin toss before.

The campaign: the three-axis table's inner gimbal swept alone, 24 positions 15 degrees apart,
1 arcsec noise. There a sag about the inner axis (``gravity_sag`` k_xy = -3 arcsec/g) and the
inner encoder's 1/rev term that reproduces it (``encoder_harmonics@inner_gimbal``, its s1) make
the same data, so whichever the diagnosis names is right for one truth and wrong for the other.
The design is made from one campaign (seed 0, the sag hidden: each effect fitted there), its 24
positions added to the campaign's, and each truth simulated on both, 50 seeds each.
"""

import numpy as np
import pytest

from conftest import REPO_DIR
from turntable_pin.design.separate import design_separate
from turntable_pin.design.space import design_space
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.measurement.user_effects import resolve_effects
from turntable_pin.model.paper_table import table_of

ENCODER, SAG = "encoder_harmonics@inner_gimbal", "gravity_sag"
SEEDS = 50


def _rate(table, truths, schedule) -> dict[str, float]:
    """How often the diagnosis names each hidden effect, over the seeds."""
    out = {}
    for name, hidden in truths.items():
        named = sum(
            diagnose_measurements(
                simulate_measurements(
                    None, hidden, schedule=schedule, seed=100 + seed, turntable=table
                ).data,  # fmt: skip
                turntable=table,
            ).missing_effect
            == name
            for seed in range(SEEDS)
        )
        out[name] = named / SEEDS
    return out


@pytest.mark.slow
def test_design_settles_what_a_one_axis_sweep_leaves_to_chance():
    table = table_of(REPO_DIR / "models" / "three_axis_imu_table.urdf")
    sweep = Schedule(30.0, 30.0, 15.0, sweep=("phi3",))
    sag = {SAG: {"k_xy": -3.0}}
    # The encoder error that makes the same data on the sweep (fitted to the sag's prediction).
    clean = simulate_measurements(None, sag, schedule=sweep, seed=0, turntable=table)
    clean_data = clean.data.replace(angles_rad=clean.truth_rad)
    fit = fit_orientation(clean_data, resolve_effects([ENCODER], table), turntable=table)
    model = fit.model
    image = {
        name.split(".", 1)[1]: float(value / unit)
        for name, value, unit in zip(
            model.parameter_names, fit.result.params, model.per_user_unit, strict=True
        )  # fmt: skip
        if name.startswith(f"{ENCODER}.")
    }
    assert image["s1"] == pytest.approx(3.0, rel=1e-3)
    truths = {SAG: sag, ENCODER: {ENCODER: image}}

    before = _rate(table, truths, sweep)
    # a coin toss: right for one truth as often as wrong for the other
    assert 0.3 <= np.mean(list(before.values())) <= 0.7, before

    campaign = simulate_measurements(None, sag, schedule=sweep, seed=0, turntable=table).data
    space = design_space(table, resolve_effects([f"{ENCODER},{SAG}"], table), seed=0)
    design = design_separate(space, 24, from_data=campaign)
    assert design.power > 0.99 and all(h.power_measured < 0.8 for h in design.hypotheses)
    positions = np.concatenate([np.degrees(campaign.joint_rad), design.positions_deg])
    after = _rate(table, truths, Schedule(positions=tuple(map(tuple, positions))))
    print(f"named right: before {before}, after {after}")
    assert min(after.values()) >= 0.9, (before, after)
