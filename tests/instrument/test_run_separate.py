"""Calibration positions that separate two explanations of a run: the misfits against a direct
least-squares computation, the separable, nested and identical cases, the closed loop (the
designed positions make the diagnosis name the true effect), and the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, cli
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import CalibrationRun, read_run
from turntable_pin.core.exceptions import InputError
from turntable_pin.instrument.diagnosis import diagnose_run
from turntable_pin.instrument.separate import design_run_separation
from turntable_pin.instrument.simulate import simulate_calibration_run

LATITUDE_RAD = np.radians(45.75)
NOISE = 0.002


def _run(angles_deg, seed, **hidden):
    positions = PositionSet(np.radians(angles_deg))
    sim = simulate_calibration_run(positions, LATITUDE_RAD, noise_dph=NOISE, seed=seed, **hidden)
    return CalibrationRun(position_inputs(positions, LATITUDE_RAD), sim.outputs_dph,
                          np.full(len(positions), NOISE))  # fmt: skip


def _candidates(n=400, seed=0):
    return np.random.default_rng(seed).uniform(-np.pi, np.pi, (n, 2))


def _sweep(outer=(30.0, 60.0)):
    """A poor run: the inner axis swept at two angles of the outer axis only."""
    inner = np.arange(0.0, 360.0, 30.0)
    return np.concatenate([np.stack([np.full(12, o), inner], 1) for o in outer])


def test_the_misfit_on_the_run_is_the_least_squares_residual_of_the_rival():
    run = _run(_sweep(), 1, instrument={"g_squared_terms": {"x_xz": 0.03}})
    result = design_run_separation(run, ("g_squared_terms", "instrument_tilt"), _candidates(), 4)
    from turntable_pin.instrument.diagnosis import RunFamily
    from turntable_pin.instrument.model import RunModel

    family = RunFamily(run)
    a, b = (family.effect(n) for n in ("g_squared_terms", "instrument_tilt"))
    fit_a = family.fit([a])
    signal = np.einsum("ncp,p->nc", RunModel(family.context, [a]).columns[:, :, 14:],
                       fit_a.result.params[14:]).reshape(-1)  # fmt: skip
    rival = RunModel(family.context, [b]).columns.reshape(-1, 16)
    coef = np.linalg.lstsq(rival, signal, rcond=None)[0]
    expected = float(np.sum((signal - rival @ coef) ** 2)) / NOISE**2
    assert result.misfit_run[0] == pytest.approx(expected, rel=1e-6)


def test_designed_positions_raise_the_smaller_misfit_and_the_diagnosis_then_names_the_truth():
    """A two-sweep run leaves a g-squared term and a tilt within 25 of each other; six designed
    positions added to it make both misfits large, and the diagnosis of the run with them names
    the hidden effect."""
    hidden = {"instrument": {"g_squared_terms": {"x_xz": 0.02, "y_yz": -0.02}}}
    run = _run(_sweep(), 3, **hidden)
    result = design_run_separation(run, ("g_squared_terms", "instrument_tilt"), _candidates(), 6)
    assert result.separable
    assert min(result.misfit_design) > max(25.0, min(result.misfit_run))
    both = _run(np.concatenate([_sweep(), result.positions_deg]), 3, **hidden)
    assert diagnose_run(both).missing_effect == "g_squared_terms"


def test_nested_and_identical_pairs_are_said_so():
    run = _run(np.stack(np.meshgrid(np.arange(0, 360, 30.0), np.arange(0, 360, 30.0)),
                        -1).reshape(-1, 2), 2,
               instrument={"instrument_tilt": {"mx": 60.0, "my": -40.0}})  # fmt: skip
    nested = design_run_separation(run, ("instrument_tilt", "table:dalpha_x2"), _candidates(), 4)
    assert not nested.separable and "is a special case of instrument_tilt" in nested.words
    same = design_run_separation(run, ("table:deps_x", "table:dalpha_x1"), _candidates(), 4)
    assert not same.separable and "no positions within the limits separate them" in same.words
    assert same.positions_deg.shape == (0, 2)


def test_effects_of_time_or_temperature_are_refused():
    run = _run(_sweep(), 1)
    with pytest.raises(InputError, match="repeat positions late"):
        design_run_separation(run, ("bias_drift", "instrument_tilt"), _candidates(), 4)
    with pytest.raises(InputError, match="unknown run effect 'nope'"):
        design_run_separation(run, ("nope", "instrument_tilt"), _candidates(), 4)
    blind = _run(_sweep((0.0, 90.0)), 1)  # az*ax and az*ay vanish at every position
    with pytest.raises(InputError, match="the run does not see g_squared_terms"):
        design_run_separation(blind, ("g_squared_terms", "instrument_tilt"), _candidates(), 4)


def test_the_design_command_with_a_run(tmp_path):
    out = tmp_path / "next.csv"
    data = EXAMPLES_DIR / "runs" / "run_g_squared.csv"
    proc = cli("design", "--separate", "g_squared_terms,instrument_tilt", "--run", str(data),
               "-n", "4", "--candidates", "500", "-o", str(out), "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    result = json.loads(proc.stdout)
    assert result["separable"] and len(result["positions"]) == 4
    positions = read_run  # the CSV has the angle columns simulate --run --positions reads
    del positions
    assert out.read_text().splitlines()[1].startswith("phi1_deg,phi2_deg")
    bad = cli("design", "--run", str(data))
    assert bad.returncode == 2 and "--run goes with --separate" in bad.stderr


def test_the_diagnosis_prints_the_design_command_for_a_rival():
    proc = cli("calibrate", str(EXAMPLES_DIR / "runs" / "run_orthogonality.csv"), "--diagnose")
    assert proc.returncode == 0, proc.stderr
    assert "turntable-pin design --separate table:deps_x," in proc.stdout or (
        "turntable-pin design --separate table:dalpha_x1," in proc.stdout
    )


def test_an_effect_fitted_at_an_implausible_amplitude_is_flagged_not_planned():
    """Issue 29: a run made by a half-degree wobble fits it beyond any turntable bearing's; the
    design says what one would have to believe instead of choosing positions."""
    grid = np.array([[a, b] for a in range(0, 360, 30) for b in range(0, 360, 30)], float)
    positions = PositionSet(np.radians(grid))
    sim = simulate_calibration_run(positions, LATITUDE_RAD, noise_dph=NOISE, seed=4,
                   table_effects={"inner_wobble_harmonics": {"x_c1": 1800.0}})  # fmt: skip
    run = CalibrationRun(position_inputs(positions, LATITUDE_RAD), sim.outputs_dph,
                         np.full(len(positions), NOISE))  # fmt: skip
    result = design_run_separation(run, ("table:inner_wobble_harmonics", "instrument_tilt"),
                                   _candidates(), 4)  # fmt: skip
    assert list(result.implausible) == ["table:inner_wobble_harmonics"]
    assert not result.separable and result.positions_deg.shape == (0, 2)
    assert "axis wobbles by 30" in result.words and result.words.startswith("not planned")
    assert result.to_dict()["implausible"] == result.implausible
