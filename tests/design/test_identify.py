"""D-optimal identification designs on the bundled 1-, 2- and 3-axis tables (issue 19, item 1):
within the limits, at least as good as the 30-degree grid, and predicting the standard errors
that ``fit`` then reports on data simulated at the chosen positions."""

import re

import numpy as np
import pytest

from conftest import REPO_DIR
from turntable_pin.core.exceptions import InputError
from turntable_pin.design.identify import design_identify
from turntable_pin.design.space import design_space
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.measurement.user_effects import resolve_effects
from turntable_pin.model.paper_table import table_of

MODELS = REPO_DIR / "models"

# (URDF, effects to identify, hidden effect values, positions, limits)
TABLES = {
    "one axis": ("single_axis_rate_table.urdf", "encoder_harmonics@spindle",
                 {"encoder_harmonics@spindle": {"c1": 3.0, "s2": -2.0}}, 12, None),
    "two axes": ("turntable.urdf", "inner_encoder_harmonics,thermal_drift,backlash",
                 {"thermal_drift": {"rz": 4.0}, "backlash": {"b1": 2.0}}, 16, None),
    "three axes": ("three_axis_imu_table.urdf", "wobble_harmonics@middle_gimbal",
                   {"wobble_harmonics@middle_gimbal": {"a_c1": 2.0}}, 24, None),
    "alt-az, elevation 0..90": ("altaz_mount.urdf", "encoder_harmonics@elevation,backlash@azimuth",
                                {"encoder_harmonics@elevation": {"c2": 3.0}}, 24, None),
    "alt-az, elevation 15..90": ("altaz_mount.urdf", "TF", {"TF": {"TF": 5.0}}, 12,
                                 "elevation=15:90"),
}  # fmt: skip

_DESIGNS: dict = {}


def _design(key):
    if key not in _DESIGNS:
        urdf, effects, _, n, limits = TABLES[key]
        table = table_of(MODELS / urdf)
        chosen = resolve_effects([effects], table)
        space = design_space(table, chosen, limits_deg=limits, candidates=3000, seed=11)
        _DESIGNS[key] = design_identify(space, n, noise_arcsec=2.0, dwell_s=30.0)
    return _DESIGNS[key]


def _simulate(key, seed):
    design, hidden = _design(key), TABLES[key][2]
    plan = design.plan
    schedule = Schedule(
        positions=tuple(map(tuple, plan.rows.angles_deg())),
        positions_time_s=None if plan.rows.time_s is None else tuple(plan.rows.time_s),
        positions_dirs=tuple(None if d is None else tuple(d) for d in plan.rows.dirs),
    )
    return simulate_measurements(None, hidden, schedule=schedule, noise_arcsec=2.0, seed=seed,
                                 turntable=design.space.table)  # fmt: skip


@pytest.mark.parametrize("key", list(TABLES))
def test_the_positions_are_within_the_limits_and_chosen_once(key):
    design = _design(key)
    positions = design.positions_deg
    assert positions.shape == (TABLES[key][3], design.space.n_joints)
    for k, r in enumerate(design.space.ranges):
        if not r.full_turn:
            assert positions[:, k].min() >= r.low_deg - 1e-9
            assert positions[:, k].max() <= r.high_deg + 1e-9
    assert len({tuple(p) for p in positions}) == positions.shape[0]
    assert np.all([c["std"] > 0 for c in design.combinations])


@pytest.mark.slow
@pytest.mark.parametrize("key", list(TABLES))
def test_the_predicted_standard_errors_are_those_fit_reports(key):
    design = _design(key)
    predicted = {c["name"]: c["std"] for c in design.combinations}
    effects = design.space.effects
    estimated = {name: [] for name in predicted}
    for seed in range(5):
        sim = _simulate(key, seed)
        # Sigma known (the sigma column): the fit's standard errors are the design's.
        fit = fit_orientation(sim.data, effects, turntable=design.space.table)
        reported = {c["name"]: c["std"] for c in fit.result.combinations()}
        assert set(reported) == set(predicted)
        for name, std in reported.items():
            assert std == pytest.approx(predicted[name], rel=0.01), name
        # Sigma estimated from the residuals: right on average over a few seeds.
        blind = fit_orientation(sim.data.without_sigma(), effects, turntable=design.space.table)
        for c in blind.result.combinations():
            estimated[c["name"]].append(c["std"])
    for name, values in estimated.items():
        assert np.mean(values) == pytest.approx(predicted[name], rel=0.10), name


@pytest.mark.parametrize(
    "urdf, effects, limits, grid_size",
    [
        ("single_axis_rate_table.urdf", "encoder_harmonics@spindle", None, 12),
        ("turntable.urdf", "inner_encoder_harmonics", "phi1=0:90,phi2=0:180", 28),
        ("three_axis_imu_table.urdf", "", "phi1=-30:30,phi2=-30:30,phi3=-30:30", 27),
        ("altaz_mount.urdf", "", None, 48),
    ],
)
def test_the_design_is_no_worse_than_the_grid_of_as_many_positions(urdf, effects, limits,
                                                                   grid_size):  # fmt: skip
    table = table_of(MODELS / urdf)
    space = design_space(table, resolve_effects([effects], table), limits_deg=limits,
                         candidates=2000, seed=5)  # fmt: skip
    assert space.grid_deg.shape[0] == grid_size
    design = design_identify(space, grid_size)
    assert design.n_grid == grid_size
    assert design.log_det >= design.log_det_grid_same_n - 1e-9
    assert design.d_efficiency >= 1.0 - 1e-9


def test_a_narrow_range_the_grid_cannot_resolve_is_resolved_by_the_design():
    # Elevation 15..90: the grid has three elevations (30, 60, 90), too few for the elevation
    # encoder's two harmonics; positions between them determine them.
    design = _design_alt_az_harmonics()
    assert design.d_efficiency is None
    undetermined_by_grid = [c for c in design.combinations if c["std_grid"] is None]
    assert any("encoder_harmonics@elevation" in c["name"] for c in undetermined_by_grid)
    assert all(c["std"] is not None for c in design.combinations)


def _design_alt_az_harmonics():
    table = table_of(MODELS / "altaz_mount.urdf")
    space = design_space(table, resolve_effects(["encoder_harmonics@elevation"], table),
                         limits_deg="elevation=15:90", candidates=2000, seed=1)  # fmt: skip
    return design_identify(space, 24)


def test_combinations_no_position_determines_are_named():
    design = design_identify(design_space(table_of(None), candidates=500), 12)
    assert design.rank == 5
    assert set(design.undetermined) == {"dphi_y1 - deps_y", "dphi_z2 - dalpha_z1",
                                        "dalpha_x1 - deps_x"}  # fmt: skip
    assert "not determined by any position within the limits: dphi_y1 - deps_y" in (design.report())


def test_measured_positions_are_built_upon(tmp_path):
    table = table_of(None)
    space = design_space(table, resolve_effects(["inner_encoder_harmonics"], table),
                         candidates=1000)  # fmt: skip
    sweep = simulate_measurements(None, schedule=Schedule(sweep=("phi2",)), noise_arcsec=0.5)
    alone = design_identify(space, 12, noise_arcsec=0.5)
    after = design_identify(space, 12, from_data=sweep.data)
    assert after.n_from == 12 and after.noise_source == "the median sigma of the data measured"
    assert after.noise_arcsec == pytest.approx(0.5)
    for a, b in zip(alone.combinations, after.combinations, strict=True):
        assert b["std"] <= a["std"] + 1e-12
    # Without a sigma column, the noise is fitted on the data.
    blind = design_identify(space, 12, from_data=sweep.data.without_sigma())
    assert blind.noise_source == "fitted on the data measured"
    assert 0.3 < blind.noise_arcsec < 0.8


@pytest.mark.parametrize(
    "urdf, effects, limits, n, message",
    [
        ("single_axis_rate_table.urdf", "encoder_harmonics@spindle", None, 2,
         "2 positions give 6 measured angles, not more than the 9 combinations to identify: "
         "choose at least 4 positions"),
        ("single_axis_rate_table.urdf", "encoder_harmonics@spindle", None, 4,
         "4 positions within the limits cannot determine all 9 combinations; the fewest that "
         "do: 5"),
        ("altaz_mount.urdf", "encoder_harmonics@elevation", "elevation=45:45", 12,
         "effect 'encoder_harmonics@elevation' changes nothing that the base errors do not "
         "already explain at any position within the limits"),
        ("altaz_mount.urdf", "", "elevation=120:130", 12, "leaves no position"),
    ],
)  # fmt: skip
def test_bad_designs_are_refused_naming_the_reason(urdf, effects, limits, n, message):
    table = table_of(MODELS / urdf)
    with pytest.raises(InputError) as info:
        space = design_space(table, resolve_effects([effects], table), limits_deg=limits,
                             candidates=1000)  # fmt: skip
        design_identify(space, n)
    assert message in str(info.value) and "\n" not in str(info.value)


def test_an_effect_another_one_explains_everywhere_is_named_with_it():
    # Tube flexure (TF cos E) is the elevation encoder's first harmonic at every elevation.
    table = table_of(MODELS / "altaz_mount.urdf")
    effects = resolve_effects(["encoder_harmonics@elevation,TF"], table)
    reason = "effect 'TF' changes nothing that 'encoder_harmonics@elevation' (with the base errors)"
    with pytest.raises(InputError, match=re.escape(reason + " does not")):
        design_identify(design_space(table, effects, candidates=500), 12)
