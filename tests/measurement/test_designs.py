"""The diagnosis on the measurement designs engineers run: grids of 30, 45 and 60 degrees, random
positions, single-axis sweeps, forward/backward passes, unknown noise and uneven noise per row.

Each design (a) names a planted catalogued effect it can see, (b) says in ``warnings`` and the
verdict what it cannot see, and (c) raises no false alarm on clean data: no ``missing_effect``
and ``unexplained`` false on 50 seeds per design, with every angle measured and with empty cells
(the whole dtheta column on even seeds, a random 20 % of the cells on odd ones).

Data: the paper's table, random turntable errors of +-10 arcsec, 1 arcsec noise (spread or per
angle where the design says so); the designs are small (24 to 72 rows) so that the 50-seed loops
stay quick.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from conftest import random_errors
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.measurement.user_effects import inline_effect

N_SEEDS = 50

DESIGNS = {
    "grid60": {"schedule": Schedule(60, 60)},
    "grid45": {"schedule": Schedule(45, 45)},
    "grid30": {"schedule": Schedule(30, 30)},
    "random_positions": {"schedule": Schedule(random_positions=40)},
    "sweeps": {"schedule": Schedule(30, 30, sweep=("phi1", "phi2"), starts_deg=(0, 90))},
    "passes": {"schedule": Schedule(60, 60, passes=1)},
    "unknown_noise": {"schedule": Schedule(60, 60), "sigma": False},
    "uneven_noise": {"schedule": Schedule(60, 60), "noise_spread": 3.0},
}
"""Each design: ``simulate_measurements`` keywords, and ``sigma: False`` to drop the sigmas."""

KNOWN_FALSE_ALARMS: dict[tuple[str, int, str], str] = {
    ("unknown_noise", 4, "empty"): "names base_tilt (delta_bic -11.8 with the noise estimated "
    "from m = 72 angles; threshold -9.9): an improvement whose exact F-test tail probability is "
    "3.8e-5, the smallest of 1200 simulated data sets of this design",
}
"""(design, seed, cells) -> the false alarm found there, a chance event the decision rule is
meant to allow rarely: with K = 7 candidates of two parameters on m = 72 angles, about 7e-4 of
the clean data sets pass the threshold, and this one is the most extreme of 1200 simulated
(its base_tilt improvement is a 1-in-26,000 event for one candidate). Two other alarms of the
same design were the textbook profiled ratio ``m ln(rss ratio)`` overstating the evidence on
small samples; the small-sample weight of ``stats.structure_search.profiled_weight`` removed
them, and the catalogue's look-elsewhere penalty (delta_bic <= -6 - 2 ln K) removed the three
alarms of the 60-degree grid and the random positions with sigma given. Each remaining one is an
xfail(strict) test below; the loops skip them and hold every other data set to zero."""


def simulate(design: str, seed: int, effects=None):
    """The design's data at ``seed`` (errors drawn from the seed too), with hidden ``effects``."""
    options = dict(DESIGNS[design])
    with_sigma = options.pop("sigma", True)
    rng = np.random.default_rng(7000 + seed)
    data = simulate_measurements(random_errors(rng), effects, seed=seed, **options).data
    return data if with_sigma else data.without_sigma()


def with_empty_cells(data, seed: int):
    """Even seeds: no dtheta at all; odd seeds: a random 20 % of the cells empty (each row keeps
    at least one angle)."""
    angles = data.angles_rad.copy()
    if seed % 2 == 0:
        angles[:, 1] = np.nan
    else:
        empty = np.random.default_rng(seed).random(angles.shape) < 0.2
        empty[empty.all(axis=1), 0] = False
        angles[empty] = np.nan
    return data.replace(angles_rad=angles)


def with_outliers(data, seed: int):
    """Two gross outliers (30 arcsec, on random angles of random rows) in ``data``."""
    rng = np.random.default_rng(10_000 + seed)
    angles = data.angles_rad.copy()
    rows = rng.choice(data.n_positions, 2, replace=False)
    columns = rng.integers(0, 3, 2)
    angles[rows, columns] += rng.choice([-1.0, 1.0], 2) * 30.0 / 206264.80624709636
    return data.replace(angles_rad=angles)


def alarm(data) -> str | None:
    """What the diagnosis of clean ``data`` wrongly says, or None."""
    verdict = diagnose_measurements(data).to_dict()["verdict"]
    if verdict["missing_effect"]:
        return f"names {verdict['missing_effect']}"
    if verdict["unexplained"]:
        terms = [t["term"] for t in verdict["remaining_structure"]]
        return "unexplained: " + (", ".join(terms) if terms else "fails the fit test")
    return None


@pytest.mark.slow
@pytest.mark.parametrize("design", list(DESIGNS))
def test_no_false_alarm_on_clean_data(design, capsys):
    start = time.perf_counter()
    alarms = {}
    for seed in range(N_SEEDS):
        data = simulate(design, seed)
        samples = (
            ("all", data),
            ("empty", with_empty_cells(data, seed)),
            ("outliers", with_outliers(data, seed)),
        )
        for cells, sample in samples:
            if (design, seed, cells) in KNOWN_FALSE_ALARMS:
                continue
            found = alarm(sample)
            if found:
                alarms[(seed, cells)] = found
    with capsys.disabled():
        print(
            f"\n{design}: {data.n_positions} rows, {len(alarms)} false alarms in "
            f"{3 * N_SEEDS} clean data sets ({time.perf_counter() - start:.1f} s)"
        )
    assert alarms == {}


@pytest.mark.xfail(
    strict=True,
    reason="a chance pass of the catalogue's threshold (tail probability 3.8e-5 for one "
    "candidate, the most extreme of 1200 simulated data sets of the design)",
)
@pytest.mark.parametrize("key", list(KNOWN_FALSE_ALARMS), ids=lambda k: f"{k[0]}-{k[1]}-{k[2]}")
def test_known_false_alarm(key):
    design, seed, cells = key
    data = simulate(design, seed)
    variant = {"all": data, "empty": with_empty_cells(data, seed)}.get(cells)
    assert alarm(variant if variant is not None else with_outliers(data, seed)) is None


def test_no_remainder_probe_on_a_sweep_without_dtheta():
    """With dtheta not measured, dphi_z2 (seen in dtheta alone) enters dpsi and dgamma only to
    second order: its probes are left out (an unresponsive error), where a 3/rev of that
    remainder was once accepted with an amplitude of ~3e4 arcsec."""
    schedule = Schedule(30, 30, sweep=("phi1", "phi2"), starts_deg=(0, 90))
    sim = simulate_measurements(random_errors(np.random.default_rng(1019)), seed=19,
                                schedule=schedule)  # fmt: skip
    angles = sim.data.angles_rad.copy()
    angles[:, 1] = np.nan
    assert alarm(sim.data.replace(angles_rad=angles)) is None


def test_no_false_alarm_with_noise_per_angle_and_sigma_estimated():
    """Noise of 0.5, 2 and 1 arcsec on the three angles and no sigma given: the diagnosis sees
    that the angles' noise differ and weights each by its own (it once took dtheta's larger
    noise for structure on 2 of 20 seeds)."""
    found = {seed: alarm(_per_angle_noise(seed).without_sigma()) for seed in range(20)}
    assert {k: v for k, v in found.items() if v} == {}  # found: seeds 3 and 7


def _per_angle_noise(seed: int):
    rng = np.random.default_rng(7000 + seed)
    return simulate_measurements(random_errors(rng), seed=seed, schedule=Schedule(60, 60),
                                 noise_arcsec=(0.5, 2.0, 1.0)).data  # fmt: skip


def test_no_false_alarm_with_noise_per_angle_given():
    found = {seed: alarm(_per_angle_noise(seed)) for seed in range(20)}
    assert {k: v for k, v in found.items() if v} == {}


# --- (a) a planted effect the design can see is named ------------------------------------------

VISIBLE = [
    ("grid60", "inner_encoder_harmonics", {"c1": 3.0, "s2": -2.5}),
    ("grid45", "outer_wobble_harmonics", {"x_c1": 2.5, "z_s2": -2.5}),
    ("grid30", "backlash", {"b1": 3.0, "b2": -2.0}),
    ("random_positions", "inner_encoder_harmonics", {"c1": 3.0, "s2": -2.5}),
    ("random_positions", "backlash", {"b1": 3.0, "b2": -2.0}),
    ("sweeps", "outer_wobble_harmonics", {"x_c1": 2.5, "z_s2": -2.5}),
    ("sweeps", "inner_encoder_harmonics", {"c1": 3.0, "s2": -2.5}),
    ("passes", "backlash", {"b1": 3.0, "b2": -2.0}),
    ("unknown_noise", "inner_encoder_harmonics", {"c1": 3.0, "s2": -2.5}),
    ("uneven_noise", "outer_wobble_harmonics", {"x_c1": 2.5, "z_s2": -2.5}),
]


@pytest.mark.parametrize(("design", "effect", "params"), VISIBLE,
                         ids=lambda v: v if isinstance(v, str) else "")  # fmt: skip
def test_a_planted_effect_the_design_sees_is_named(design, effect, params):
    for seed in (1, 2):
        data = simulate(design, seed, {effect: params})
        for sample in (data, with_empty_cells(data, 1)):
            verdict = diagnose_measurements(sample).to_dict()["verdict"]
            assert verdict["missing_effect"] == effect, (seed, verdict)
            assert not verdict["unexplained"]


# --- (b) what a design cannot see, it says ------------------------------------------------------


def _diagnosis(schedule: Schedule, effects, seed: int = 3) -> dict:
    errors = random_errors(np.random.default_rng(seed))
    inline = [inline_effect(name, None) for name in effects if "~" in name]
    sim = simulate_measurements(errors, effects, schedule=schedule, seed=seed, catalogue=inline)
    return diagnose_measurements(sim.data).to_dict()


def test_backlash_with_a_positive_only_approach_is_indistinguishable_and_said_so():
    d = _diagnosis(Schedule(30, 30, approach="positive"), {"backlash": {"b1": 3.0, "b2": -2.0}})
    verdict = d["verdict"]
    assert verdict["missing_effect"] is None
    assert "backlash" in verdict["indistinguishable_from_base"]
    [warning] = [w for w in d["warnings"] if "backlash" in w]
    assert warning.startswith(
        "dir1, dir2 are the same at every row (phi1 from below, phi2 from below)"
    )
    assert "approach the positions from both sides" in warning
    # the same positions approached from both sides see it
    both = _diagnosis(Schedule(30, 30, approach="random"), {"backlash": {"b1": 3.0, "b2": -2.0}})
    assert both["verdict"]["missing_effect"] == "backlash" and both["warnings"] == []


def test_second_harmonics_on_a_90_degree_grid_are_said_to_alias():
    d = _diagnosis(Schedule(90, 90), {"inner_encoder_harmonics": {"s2": -3.0}})
    assert d["verdict"]["missing_effect"] is None and not d["verdict"]["unexplained"]
    text = " ".join(d["warnings"])
    for axis in ("phi1", "phi2"):
        assert f"{axis} takes only 4 distinct angles" in text
    assert "terms of order 2 and above" in text and "5 or more angles" in text
    # a 60-degree grid (6 angles per axis) sees it
    six = _diagnosis(Schedule(60, 60), {"inner_encoder_harmonics": {"s2": -3.0}})
    assert six["verdict"]["missing_effect"] == "inner_encoder_harmonics"
    assert six["warnings"] == []


def test_a_sweep_that_holds_phi2_cannot_test_effects_of_phi2_and_says_so():
    schedule = Schedule(30, 30, sweep=("phi1",), starts_deg=(0, 90))
    d = _diagnosis(schedule, {"inner_encoder_harmonics": {"c1": 3.0, "s2": -2.5}})
    verdict = d["verdict"]
    assert verdict["missing_effect"] is None
    assert {"inner_encoder_harmonics", "inner_wobble_harmonics"} <= set(
        verdict["indistinguishable_from_base"]
    )
    text = " ".join(d["warnings"])
    assert "the rows hold phi2 at 90 deg: effects that vary with phi2 cannot be tested" in text
    assert "(simulate sweep phi1,phi2, or a grid)" in text  # the CLI says --sweep
    assert "so effects that vary with phi2 cannot be tested" in text  # the rank warning, precise
    # the reverse sweep added (one command: --sweep phi1,phi2) sees it
    both = _diagnosis(Schedule(30, 30, sweep=("phi1", "phi2"), starts_deg=(0, 90)),
                      {"inner_encoder_harmonics": {"c1": 3.0, "s2": -2.5}})  # fmt: skip
    assert both["verdict"]["missing_effect"] == "inner_encoder_harmonics"


def test_single_axis_sweeps_say_they_cannot_see_coupled_terms():
    schedule = Schedule(30, 30, sweep=("phi1", "phi2"), starts_deg=(0, 90))
    d = _diagnosis(schedule, {"dpsi~h1(phi1+phi2)": {"c1": 4.0}})
    [warning] = [w for w in d["warnings"] if "single-axis sweeps" in w]
    assert "phi1 swept at phi2 90 deg, phi2 swept at phi1 0 deg" in warning
    assert "phi1+phi2" in warning and "(a grid or random positions)" in warning
    # on the sweeps the coupled term looks like terms in one axis: no coupled shape is reported
    structure = [t["term"] for t in d["verdict"]["remaining_structure"]]
    assert not any("phi1+phi2" in t or "phi1-phi2" in t for t in structure)
    grid = _diagnosis(Schedule(30, 30), {"dpsi~h1(phi1+phi2)": {"c1": 4.0}})
    assert grid["warnings"] == []
    assert grid["verdict"]["remaining_structure"][0]["term"] == "dpsi 1/rev in phi1+phi2"


def test_no_design_warning_on_the_full_designs():
    for design in ("grid60", "grid45", "random_positions", "uneven_noise", "unknown_noise"):
        d = diagnose_measurements(simulate(design, 5)).to_dict()
        assert d["warnings"] == [], design
    passes = diagnose_measurements(simulate("passes", 5)).to_dict()
    assert passes["warnings"] == []


def test_missing_dtheta_is_said_and_leaves_the_inner_encoder_untested():
    data = with_empty_cells(simulate("grid60", 2, {"inner_encoder_harmonics": {"c1": 3.0}}), 2)
    d = diagnose_measurements(data).to_dict()
    assert d["verdict"]["missing_effect"] != "inner_encoder_harmonics"
    assert any("dtheta at 36 of 36 positions" in w for w in d["warnings"])
