"""Positions that tell two effects apart (issue 19, item 2): the T-optimal design beats the
positions measured and the grid, its power claim agrees with the diagnosis run on simulated
data, pairs that no position separates are said to be so (with the independent measurement),
and bad input is one line.

The confounded campaign: the three-axis table's inner gimbal swept alone (24 positions, the
others at 0). There a sag about the inner axis (gravity_sag k_xy) is exactly the inner encoder's
1/rev term (s1): the campaign cannot tell them apart; turning the other axes can.
"""

import json

import numpy as np
import pytest

from conftest import REPO_DIR
from turntable_pin.cli import main
from turntable_pin.core.exceptions import InputError
from turntable_pin.design.separate import design_separate
from turntable_pin.design.space import design_space
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.simulation import Schedule, read_positions, simulate_measurements
from turntable_pin.measurement.user_effects import resolve_effects
from turntable_pin.model.paper_table import table_of

MODELS = REPO_DIR / "models"
ENCODER, SAG = "encoder_harmonics@inner_gimbal", "gravity_sag"
SWEEP = Schedule(30.0, 30.0, 15.0, sweep=("phi3",))


@pytest.fixture(scope="module")
def three_axis():
    return table_of(MODELS / "three_axis_imu_table.urdf")


@pytest.fixture(scope="module")
def campaign(three_axis):
    """The inner-axis sweep with a sag hidden (k_xy = -3 arcsec/g, 1 arcsec noise)."""
    return simulate_measurements(None, {SAG: {"k_xy": -3.0}}, schedule=SWEEP, seed=0,
                                 turntable=three_axis).data  # fmt: skip


def _space(table, pair, **options):
    return design_space(table, resolve_effects([pair], table), **options)


def _design(table, pair, n, **options):
    space_options = {k: options.pop(k) for k in ("limits_deg", "candidates") if k in options}
    return design_separate(_space(table, pair, seed=0, **space_options), n, **options)


@pytest.fixture(scope="module")
def separated(three_axis, campaign):
    return _design(three_axis, f"{ENCODER},{SAG}", 24, from_data=campaign, candidates=4000)


def test_the_design_separates_what_the_campaign_confounds(separated):
    design = separated
    assert design.inseparable is None and design.n_from == 24
    encoder, sag = design.hypotheses
    assert (encoder.effect, sag.effect) == (ENCODER, SAG)
    # fitted on the campaign: the encoder's s1 is the sag's k_xy (their shared shape)
    assert encoder.amplitude["s1"] == pytest.approx(-sag.amplitude["k_xy"], rel=0.02)
    for h in design.hypotheses:
        assert h.misfit_measured_chi2 < 2.0  # the campaign: each reproduces the other
        assert h.misfit_chi2 > 100.0 * h.misfit_measured_chi2
        assert h.misfit_chi2 > h.misfit_grid_chi2  # T-optimal beats the grid of the same size
        assert h.settled_by == "misfit"
    # a coin toss on the campaign (its chances sum to about one), a sure name after
    measured = [h.power_measured for h in design.hypotheses]
    assert 0.8 < sum(measured) < 1.4 and max(measured) < 0.8
    assert design.power > 0.99
    count = design.positions_for_power
    assert count is not None and count < 24 and design.power_at_positions_for_power >= 0.9
    assert design.positions_for_power_designed
    assert design.misfit_by_position.shape == (24, 2) and np.all(design.misfit_by_position >= 0)
    text = design.report()
    assert "chance that the diagnosis names gravity_sag" in text
    assert f"design separate {ENCODER},{SAG} n_positions {count}" in text
    json.dumps(design.to_dict())


def test_the_run_is_what_simulate_reads(separated, tmp_path):
    path = separated.plan.write_csv(tmp_path / "next.csv", comment=separated.comment())
    positions = read_positions(path, ("outer_gimbal", "middle_gimbal", "inner_gimbal"))
    np.testing.assert_allclose(np.array(positions["positions"]), separated.plan.rows.angles_deg())
    assert "T-optimal" in path.read_text().splitlines()[0]


@pytest.mark.slow
def test_the_power_claim_agrees_with_the_diagnosis_on_simulated_data(three_axis, campaign):
    # One new position: a chance in between for either truth; each simulated at the design's
    # amplitudes (its hypotheses) on the campaign's positions and the new one, 60 seeds each.
    design = _design(three_axis, f"{ENCODER},{SAG}", 1, from_data=campaign, candidates=4000)
    positions = np.concatenate([np.degrees(campaign.joint_rad), design.positions_deg])
    schedule = Schedule(positions=tuple(map(tuple, positions)))
    seeds = 60
    for h in design.hypotheses:
        named = 0
        for seed in range(seeds):
            sim = simulate_measurements(None, {h.effect: h.amplitude}, schedule=schedule,
                                        seed=1000 + seed, turntable=three_axis)  # fmt: skip
            named += (
                diagnose_measurements(sim.data, turntable=three_axis).missing_effect == h.effect
            )
        rate = named / seeds
        assert abs(rate - h.power) < 3 * np.sqrt(h.power * (1 - h.power) / seeds) + 0.08, (
            h.effect, rate, h.power,
        )  # fmt: skip
    assert 0.1 < min(h.power for h in design.hypotheses) < 0.9  # a claim worth testing


def test_the_elevation_encoders_one_per_rev_term_is_the_tube_flexure_everywhere():
    # TF (dE = -TF cos E) is the elevation encoder's c1: no position, at any limits, separates
    # them; the result says so in one line and names the independent measurements.
    table = table_of(MODELS / "altaz_mount.urdf")
    design = _design(table, "TF,encoder_harmonics@elevation", 24, limits_deg="elevation=15:90",
                     amplitudes={"TF": {"TF": 10.0}, "encoder_harmonics@elevation": {"c1": -10.0}},
                     candidates=2000)  # fmt: skip
    text = design.inseparable
    assert text and design.plan is None and "\n" not in text
    assert text.startswith("no positions within the joints' limits")
    assert "15 .. 90 deg" in text and "an independent measurement does" in text
    assert "tube's balance or mass" in text and "optical polygon" in text  # both confirm texts
    assert design.report() == text and design.to_dict()["inseparable"] == text


def test_an_encoder_one_per_rev_term_is_the_paper_tables_sag():
    table = table_of(None)
    amplitudes = {"gravity_sag": {"k": 3.0}, "outer_encoder_harmonics": {"s1": -3.0}}
    design = _design(table, "gravity_sag,outer_encoder_harmonics", 12, candidates=1000,
                     amplitudes=amplitudes)  # fmt: skip
    assert design.inseparable and "outer_encoder_harmonics" in design.inseparable


def test_a_nested_effect_is_named_by_parsimony_when_it_is_true():
    # TF is one of the sag's directions: a true TF is named for its one parameter, and the
    # design only has to show a sag that TF cannot follow.
    table = table_of(MODELS / "altaz_mount.urdf")
    design = _design(table, "TF,gravity_sag", 12, limits_deg="elevation=15:90", candidates=2000,
                     amplitudes={"TF": {"TF": 10.0}, "gravity_sag": {"k_xx": 5.0}})  # fmt: skip
    tf, sag = design.hypotheses
    assert tf.settled_by == "parsimony" and sag.settled_by == "misfit"
    assert tf.misfit_chi2 < 1e-12 and tf.added_rank < tf.rival_added_rank
    assert tf.power > 0.95  # chi2(3) below 3 ln m: the noise rarely pays for three parameters


def test_given_amplitudes_need_no_data_and_tf_is_told_from_tx():
    table = table_of(MODELS / "altaz_mount.urdf")
    design = _design(table, "TF,TX", 12, limits_deg="elevation=15:90", candidates=2000,
                     amplitudes={"TF": {"TF": 10.0}, "TX": {"TX": 3.0}})  # fmt: skip
    assert design.power > 0.99 and design.n_from == 0
    assert all(h.misfit_chi2 > h.misfit_grid_chi2 for h in design.hypotheses)
    assert np.all(design.positions_deg[:, 1] >= 15.0 - 1e-9)  # within the limits
    assert design.noise_source == "default"


def test_bad_input_is_one_line(three_axis, campaign):
    table = table_of(MODELS / "altaz_mount.urdf")
    cases = [
        (lambda: _design(table, "TF,TX", 4, candidates=200), "no amplitude for TF"),
        (lambda: _design(table, "TF,TX", 4, candidates=200,
                         amplitudes={"TF": {"TF": 0.0}, "TX": {"TX": 1.0}}), "nothing to separate"),
        (lambda: _design(table, "TF,TX", 4, candidates=200,
                         amplitudes={"TF": {"k": 1.0}, "TX": {"TX": 1.0}}), "no parameter 'k'"),
        (lambda: _design(table, "TF,TX", 4, candidates=200,
                         amplitudes={"TZ": {"k": 1.0}}), "not one of TF, TX"),
        (lambda: _design(table, "TF", 4, candidates=200), "two different effects"),
        (lambda: _design(table, "TF,TX", 500, candidates=100,
                         amplitudes={"TF": {"TF": 1.0}, "TX": {"TX": 1.0}}), "^n_positions is 500"),
    ]  # fmt: skip
    for call, words in cases:
        with pytest.raises(InputError, match=words) as caught:
            call()
        assert "\n" not in str(caught.value)


def test_the_command_line(tmp_path, capsys, campaign):
    data = tmp_path / "campaign.csv"
    simulate_measurements(None, {SAG: {"k_xy": -3.0}}, schedule=SWEEP, seed=0,
                          turntable=table_of(MODELS / "three_axis_imu_table.urdf")
                          ).write_csv(data)  # fmt: skip
    out = tmp_path / "next.csv"
    argv = ["design", "--urdf", "three_axis_imu_table", "--separate", f"{ENCODER},{SAG}",
            "--from", str(data), "-n", "6", "--candidates", "800", "-o", str(out),
            "--plots", str(tmp_path / "figs")]  # fmt: skip
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert "power (the smaller chance of the right name)" in text and f"wrote {out}" in text
    assert sorted(p.name for p in (tmp_path / "figs").iterdir()) == [
        "separate_positions.png", "separate_power.png",
    ]  # fmt: skip
    assert len(read_positions(out, ("a", "b", "c"))["positions"]) == 6
    assert main([*argv[:-4], "--json"]) == 0
    result = json.loads(capsys.readouterr().out)
    assert result["mode"] == "separate" and len(result["hypotheses"]) == 2
    # no positions separate them: one line, exit 0, nothing written
    inseparable = ["design", "--urdf", "altaz_mount",
                   "--separate", "TF,encoder_harmonics@elevation", "--amplitude", "TF:TF=10",
                   "--amplitude", "encoder_harmonics@elevation:c1=-10",
                   "--limits-deg", "elevation=15:90", "--candidates", "500",
                   "-o", str(tmp_path / "none.csv")]  # fmt: skip
    assert main(inseparable) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("no positions")
    assert not (tmp_path / "none.csv").exists()


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--separate", "TF"], "takes two effects"),
        (["--separate", "TF,TX", "--effects", "TX"], "--effects is for the identify mode"),
        (["--separate", "TF,TX", "--amplitude", "TZ:TZ=1"], "unknown effect 'TZ'"),
        (["--separate", "TF,TX", "--amplitude", "TF:TF=1", "--amplitude", "TF:TF=2"],
         "given twice"),
        (["--separate", "TF,TX", "--amplitude", "TF"], "without parameters|no parameters"),
    ],
)  # fmt: skip
def test_command_line_bad_input_exits_2(extra, words, capsys):
    argv = ["design", "--urdf", "altaz_mount", "--candidates", "100", *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert any(w in err for w in words.split("|")), err


def test_the_diagnosis_points_to_the_design_that_settles_it(tmp_path, capsys):
    import shlex

    data = tmp_path / "campaign.csv"
    simulate_measurements(None, {SAG: {"k_xy": -3.0}}, schedule=SWEEP, seed=0,
                          turntable=table_of(MODELS / "three_axis_imu_table.urdf")
                          ).write_csv(data)  # fmt: skip
    assert main(["diagnose", str(data), "--urdf", "three_axis_imu_table", "--json"]) == 0
    verdict = json.loads(capsys.readouterr().out)["verdict"]
    (other,) = verdict["separations"]
    command = verdict["separation_commands"][other]
    pair = ",".join([verdict["missing_effect"], other])
    assert command == (f"turntable-pin design --separate {pair} --from {shlex.quote(str(data))} "
                       "--urdf three_axis_imu_table")  # fmt: skip
    assert main(["diagnose", str(data), "--urdf", "three_axis_imu_table"]) == 0
    assert f"    to settle it, design the next positions: {command}" in capsys.readouterr().out
    # ... and the command runs (with fewer candidates, for the test's time)
    assert main([*shlex.split(command)[1:], "--candidates", "800", "-n", "4"]) == 0
    assert "chance that the diagnosis names" in capsys.readouterr().out


def test_a_diagnosis_without_confounded_candidates_has_no_command():
    sim = simulate_measurements(None, {"inner_encoder_harmonics": {"c1": 3.0}}, seed=2)
    verdict = diagnose_measurements(sim.data).to_dict()["verdict"]
    assert verdict["missing_effect"] == "inner_encoder_harmonics" and not verdict["separations"]
    assert "separation_commands" not in verdict


def test_the_paper_tables_commands_name_no_urdf_and_simulated_data_a_placeholder():
    sim = simulate_measurements(None, {"gravity_sag": {"k": 3.0}}, seed=7)
    verdict = diagnose_measurements(sim.data).to_dict()["verdict"]
    command = verdict["separation_commands"]["outer_encoder_harmonics"]
    assert command == (  # from Python, the Python call; the CLI prints the shell command
        "design(separate='gravity_sag,outer_encoder_harmonics', from_data='DATA.csv')"
    )


def test_a_hypothesis_fitted_at_an_implausible_amplitude_is_flagged_not_planned(tmp_path):
    """Issue 29: on the MMT run an elevation wobble fits only at about a degree and a half; the
    design says so instead of planning positions for it. Given as a hypothesis, it is planned."""
    from tpoint_runs import ALTAZ_URDF, mmt_csv
    from turntable_pin.measurement.data import read_measurements
    from turntable_pin.model.generic_table import GenericTable

    table = GenericTable(ALTAZ_URDF)
    data = read_measurements(mmt_csv(tmp_path / "mmt.csv"), table.joint_names)
    design = _design(table, "wobble_harmonics@elevation,TF", 8, from_data=data, candidates=500)
    assert list(design.implausible) == ["wobble_harmonics@elevation"]
    assert "axis wobbles by 1.4" in design.implausible["wobble_harmonics@elevation"]
    assert design.n_positions == 0 and design.to_dict()["implausible"] == design.implausible
    assert design.report().startswith("not planned: wobble_harmonics@elevation's amplitude")
    given = _design(table, "wobble_harmonics@elevation,TF", 8, from_data=data, candidates=500,
                    amplitudes={"wobble_harmonics@elevation": {"a_c1": 2000.0}})  # fmt: skip
    assert given.implausible == {} and given.n_positions == 8
