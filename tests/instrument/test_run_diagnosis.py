"""The run diagnosis on simulated runs (the exact path of ``simulate_calibration_run``): the
right verdict and side in each scenario, the residuals at the noise after adding what was named,
no false name on clean runs, the confounded cases said as such."""

from __future__ import annotations

import shlex

import numpy as np
import pytest

from conftest import EXAMPLES_DIR
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import CalibrationRun
from turntable_pin.core.units import arcsec_to_rad
from turntable_pin.instrument.diagnosis import diagnose_run
from turntable_pin.instrument.simulate import (
    TemperatureProfile,
    simulate_calibration_run,
)
from turntable_pin.model.paper_table import paper_table

LATITUDE_RAD = np.radians(45.75)
NOISE = 0.002


def _run(positions=None, seed=0, sigma=True, **hidden) -> CalibrationRun:
    positions = positions or PositionSet.grid(30)
    sim = simulate_calibration_run(
        positions, LATITUDE_RAD, noise_dph=(NOISE, NOISE), seed=seed, dwell_s=120.0, **hidden
    )
    extra = {} if sim.temperature_c is None else {"temperature_c": sim.temperature_c}
    return CalibrationRun(
        position_inputs(positions, LATITUDE_RAD),
        sim.outputs_dph,
        np.full(len(positions), NOISE) if sigma else None,
        sim.time_s,
        extra,
    )


SCENARIOS = {
    "orthogonality": ({"table_errors_rad": {"deps_x": arcsec_to_rad(60.0)}}, "table",
                      {"table:deps_x", "table:dalpha_x1"}),
    "inner_wobble": ({"table_effects": {"inner_wobble_harmonics": {"x_c1": 60.0}}}, "table",
                     {"table:inner_wobble_harmonics"}),
    "tilted_mount": ({"instrument": {"instrument_tilt": {"mx": 60.0, "my": -40.0}}},
                     "instrument", {"instrument_tilt"}),
    "bias_drift": ({"instrument": {"bias_drift": {"x": 0.004, "y": -0.003}}}, "instrument",
                   {"bias_drift"}),
    "temperature": ({"instrument": {"temperature_coefficient": {"x": 0.003}},
                     "temperature_c": TemperatureProfile(20.0, 1.0, 2.5, 3.0)}, "instrument",
                    {"temperature_coefficient"}),
    "g_squared": ({"instrument": {"g_squared_terms": {"x_xz": 0.03}}}, "instrument",
                  {"g_squared_terms"}),
    "earth_rate_scale": ({"instrument": {"earth_rate_scale": {"x": 1500.0, "y": -1000.0}}},
                         "instrument", {"earth_rate_scale"}),
}  # fmt: skip


@pytest.mark.parametrize("scenario", sorted(SCENARIOS))
def test_each_scenario_names_the_right_effect_on_the_right_side(scenario):
    hidden, side, names = SCENARIOS[scenario]
    diagnosis = diagnose_run(_run(seed=7, **hidden))
    d = diagnosis.to_dict()
    verdict = d["verdict"]
    assert verdict["missing_effect"] in names, verdict["missing_effect"]
    assert verdict["missing_effects"] == [verdict["missing_effect"]]
    assert verdict["side"] == side
    # the residuals at the noise once it is added
    assert not verdict["unexplained"]
    assert d["best"]["p_value"] > 1e-3
    assert d["best"]["rms_dph"] < 1.15 * NOISE < d["base"]["rms_dph"]
    assert d["outliers"] == []


def test_the_orthogonality_is_said_to_be_confounded_with_the_outer_wobble():
    hidden, _, _ = SCENARIOS["orthogonality"]
    d = diagnose_run(_run(seed=7, **hidden)).to_dict()
    # deps_x and dalpha_x1 turn the payload alike at every position (only their sum is seen)
    assert {"table:deps_x", "table:dalpha_x1"} <= {d["verdict"]["missing_effect"],
                                                   *d["verdict"]["alternatives"]}  # fmt: skip
    sums = [c["name"] for c in d["table_from_run"]["determined"]]
    assert "dalpha_x1 + deps_x" in sums
    value = next(c for c in d["table_from_run"]["determined"] if c["name"] == "dalpha_x1 + deps_x")
    assert abs(value["value"] - 60.0) < 4 * value["std"]


def test_a_tilted_mount_is_said_to_be_the_tables_payload_rotation_too():
    """On the paper's table dalpha_x2, dalpha_y2 are rotations in the payload frame, exactly a
    mounting tilt: the run cannot say which side it is, and no position separates them."""
    hidden, _, _ = SCENARIOS["tilted_mount"]
    d = diagnose_run(_run(seed=3, **hidden)).to_dict()
    rivals = {r["effect"]: r for r in d["verdict"]["other_side"]}
    assert "table:errors" in rivals
    assert rivals["table:errors"]["chi2_dense"] < 1e-6
    assert "no set of positions separates them" in rivals["table:errors"]["words"]
    from turntable_pin.report.diagnosis_text import diagnosis_lines

    text = "\n".join(diagnosis_lines(d))
    assert "confounded: the run alone cannot say which side it is" in text


def test_three_outliers_are_left_out_and_the_run_is_clean():
    run = _run(seed=11)
    bad = run.outputs_dph.copy()
    rows = [10, 50, 99]
    bad[rows, [0, 1, 0]] += np.array([30, -30, 30]) * NOISE
    d = diagnose_run(run.replace(outputs_dph=bad)).to_dict()
    assert sorted(o["row"] for o in d["outliers"]) == sorted(int(run.rows[i]) for i in rows)
    assert d["verdict"]["missing_effect"] is None
    assert not d["verdict"]["unexplained"]


DESIGNS = {
    "grid30": lambda seed: PositionSet.grid(30),
    "random100": lambda seed: PositionSet.random(100, paper_table(), 1000 + seed),
}


@pytest.mark.parametrize("design", sorted(DESIGNS))
def test_no_false_name_on_twenty_clean_runs(design):
    named = []
    for seed in range(20):
        diagnosis = diagnose_run(_run(DESIGNS[design](seed), seed=seed))
        verdict = diagnosis.to_dict()["verdict"]
        named += verdict["missing_effects"] + [t["term"] for t in verdict["remaining_structure"]]
    assert named == []


def test_without_sigma_the_verdict_holds_and_the_noise_is_estimated():
    hidden, _, _ = SCENARIOS["bias_drift"]
    d = diagnose_run(_run(seed=5, sigma=False, **hidden)).to_dict()
    assert d["verdict"]["missing_effect"] == "bias_drift"
    assert d["sigma_source"] == "estimated"
    assert abs(d["sigma_dph"] - NOISE) < 0.15 * NOISE


def test_table1_from_the_clean_noise_free_run_through_the_diagnosis():
    positions = PositionSet.grid(30)
    sim = simulate_calibration_run(positions, LATITUDE_RAD, seed=0)
    run = CalibrationRun(position_inputs(positions, LATITUDE_RAD), sim.outputs_dph)
    from turntable_pin.calibration.gyrowheel import GyroWheelModel
    from turntable_pin.instrument.model import fit_run

    model = GyroWheelModel.nominal()
    beta = np.stack([model.x.as_array(), model.y.as_array()])
    assert np.max(np.abs(fit_run(run).coefficients_dph - beta)) < 1e-9


def test_outputs_with_different_noise_get_their_own_level_and_no_false_name():
    """Without sigma, out_y three times noisier than out_x: the F test sees it, each output is
    weighted by its own noise, and a clean run still has nothing named."""
    positions = PositionSet.grid(30)
    for seed, hidden in ((21, {}), (22, SCENARIOS["bias_drift"][0])):
        sim = simulate_calibration_run(positions, LATITUDE_RAD, noise_dph=(NOISE, 3 * NOISE),
                                       seed=seed, dwell_s=120.0, **hidden)  # fmt: skip
        run = CalibrationRun(position_inputs(positions, LATITUDE_RAD), sim.outputs_dph, None,
                             sim.time_s)  # fmt: skip
        d = diagnose_run(run).to_dict()
        assert any("the two outputs' noise differ" in w for w in d["warnings"])
        assert d["verdict"]["missing_effects"] == ([] if not hidden else ["bias_drift"])


def test_the_design_command_is_a_python_call_or_under_the_cli_the_shell_command():
    from turntable_pin.calibration.run import read_run
    from turntable_pin.cli.words import CLI_WORDS
    from turntable_pin.core.words import speaking
    from turntable_pin.instrument.diagnosis import run_design_command

    path = EXAMPLES_DIR / "runs" / "run_bias_drift.csv"
    command = run_design_command(read_run(path, np.radians(30.0)), ("bias_drift", "table:deps_x"))
    assert str(command) == (
        f"design(separate='bias_drift,table:deps_x', run={str(path)!r}, latitude_deg='30')"
    )
    with speaking(CLI_WORDS):
        assert str(command) == (
            "turntable-pin design --separate bias_drift,table:deps_x --run "
            f"{shlex.quote(str(path))} --latitude-deg 30"
        )


SINGLES = {
    # two table singles: an orthogonality and an outer-axis wobble constant (70 and 60 arcsec)
    "two_singles": (
        {"table_errors_rad": {"deps_y": arcsec_to_rad(70.0), "dalpha_z1": arcsec_to_rad(60.0)}},
        [{"table:deps_y", "table:dphi_y1"},
         {"table:dalpha_z1", "table:dphi_z2", "instrument_heading"}],
    ),
    # three singles: two confounded table errors (one group on a run) and a heading error
    "three_singles": (
        {"table_errors_rad": {"deps_x": arcsec_to_rad(50.0), "dalpha_x1": arcsec_to_rad(45.0)},
         "instrument": {"instrument_heading": {"mz": 60.0}}},
        [{"table:deps_x", "table:dalpha_x1"},
         {"table:dalpha_z1", "table:dphi_z2", "instrument_heading"}],
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(SINGLES))
def test_several_table_singles_are_named_as_such_not_as_one_wobble(case):
    """The wobble series absorbs the singles and leads the first round; the set search names the
    singles (each a confounded group) and says which many-parameter effect it was compared with."""
    hidden, groups = SINGLES[case]
    for seed in range(3):
        d = diagnose_run(_run(seed=seed, **hidden))
        named = d.missing_effects
        assert len(named) == len(groups), (seed, named)
        for group in groups:
            assert sum(name in group for name in named) == 1, (seed, named)
        verdict = d.to_dict()["verdict"]
        chosen = [s for s in verdict["simpler_sets"] if s["set_named"]]
        assert chosen and "wobble_harmonics" in chosen[0]["effect"]
        assert chosen[0]["set_added_rank"] < chosen[0]["added_rank"]
        assert chosen[0]["set_delta_bic"] < chosen[0]["delta_bic"]


def test_a_true_wobble_is_still_named_against_the_simpler_sets():
    hidden = {"table_effects": {"inner_wobble_harmonics": {"x_c1": 60.0, "y_s2": 40.0}}}
    for seed in range(3):
        d = diagnose_run(_run(seed=seed, **hidden))
        assert d.missing_effects == ["table:inner_wobble_harmonics"]
        (comparison,) = d.set_comparisons
        assert not comparison.chosen and comparison.set_delta_bic > comparison.delta_bic
        assert d.to_dict()["candidates"][0]["implausible"] is None
