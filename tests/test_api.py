"""The flat API (``turntable_pin.api``): each function on a bundled example with paths and objects
in, the same answer as the library calls the command line makes, the result objects' notebook
views (``_repr_html_``, ``plot()``, ``to_json()``), the user's loop in at most ten lines, and an
``import turntable_pin`` that stays light."""

from __future__ import annotations

import inspect
import json

import numpy as np
import pytest

import turntable_pin as tp
from conftest import REPO_DIR, cli, run_python
from turntable_pin.core.exceptions import InputError, TurntablePinError
from turntable_pin.core.notebook import jsonable
from turntable_pin.core.resources import BUNDLED_TABLES

EXAMPLES = REPO_DIR / "models" / "examples"

USER_LOOP = """\
import turntable_pin as tp
table = tp.load_table("turntable")
sim = tp.simulate(table, errors={"dphi_y1": 20}, effects={"inner_encoder_harmonics": {"c1": 3}})
before = tp.fit(sim, table=table)
diagnosis = tp.diagnose(sim, table=table)
after = tp.fit(sim, diagnosis.missing_effect, table=table)
print(f"rms {before.result.rms_user:.2f} -> {after.result.rms_user:.2f} arcsec")
"""
"""The user's loop: load, simulate, fit, diagnose, add the named effect, refit."""


@pytest.fixture(scope="module")
def paper():
    return tp.load_table("turntable")


@pytest.fixture(scope="module")
def simulated(paper):
    return tp.simulate(
        paper, errors={"dphi_y1": 20}, effects={"inner_encoder_harmonics": {"c1": 3}}, seed=3
    )


@pytest.fixture(scope="module")
def diagnosis(paper, simulated):
    return tp.diagnose(simulated, table=paper)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    from turntable_pin.report.figures import pyplot

    pyplot().close("all")


# ---- the import stays light; the flat names are the one names --------------------------------
def test_import_pays_for_no_heavy_library():
    code = (
        "import sys, turntable_pin as tp\n"
        "assert callable(tp.design)\n"
        "print(','.join(m for m in ('numpy', 'scipy', 'matplotlib', 'pinocchio') "
        "if m in sys.modules))"
    )
    out = run_python(code)
    assert out.strip() == ""


def test_flat_names_replace_the_old_exports():
    flat = {"load_table", "read_measurements", "simulate", "fit", "diagnose", "design",
            "allocate", "calibrate", "import_tpoint"}  # fmt: skip
    assert flat <= set(tp.__all__)
    for old in ("simulate_measurements", "fit_orientation", "diagnose_measurements",
                "allocate_tolerances", "calibrate_run"):  # fmt: skip
        assert old not in tp.__all__
        with pytest.raises(AttributeError):
            getattr(tp, old)
    from turntable_pin import api

    assert tp.read_measurements is api.read_measurements and tp.calibrate is api.calibrate


def test_design_is_callable_whether_or_not_the_subpackage_was_imported():
    code = (
        "import turntable_pin.design.space, turntable_pin as tp\n"
        "import turntable_pin.design.identify as identify\n"
        "print(tp.design('turntable', 8, candidates=200).n_positions, identify.__name__)"
    )
    out = run_python(code)
    assert out.split() == ["8", "turntable_pin.design.identify"]


def test_a_result_without_its_views_says_how_to_get_them():
    code = (
        "from turntable_pin.measurement.data import read_measurements\n"
        "from turntable_pin.measurement.fit import fit_orientation\n"
        "from turntable_pin.core.resources import examples_dir\n"
        "fit = fit_orientation(read_measurements(examples_dir() / 'measurements_example.csv'))\n"
        "print(len(fit.to_json()) > 0)\n"
        "try:\n    fit.plot()\nexcept Exception as exc:\n    print(type(exc).__name__, exc)\n"
    )
    out = run_python(code)
    lines = out.splitlines()
    assert lines[0] == "True"
    assert lines[1].startswith("TurntablePinError no view of a OrientationFit is registered")
    assert "import turntable_pin.report.notebook" in lines[1]


def test_simulate_takes_a_schedule(paper):
    schedule = tp.Schedule(90, 90, repeats=2, passes=1)
    sim = tp.simulate(paper, schedule=schedule, seed=2)
    assert sim.data.n_positions == schedule.count(2)
    assert sim.to_dict()["schedule"] == schedule.describe(2)


# ---- the user's loop --------------------------------------------------------------------------
def test_user_loop_reaches_the_error_fell_in_ten_lines(capsys):
    assert len(USER_LOOP.strip().splitlines()) <= 10
    assert "turntable_pin." not in USER_LOOP  # no deep import
    scope: dict = {}
    exec(compile(USER_LOOP, "<user loop>", "exec"), scope)
    before, after = scope["before"].result.rms_user, scope["after"].result.rms_user
    assert scope["diagnosis"].missing_effect == "inner_encoder_harmonics"
    assert after < 0.75 * before
    assert after == pytest.approx(1.0, rel=0.2)  # down to the 1-arcsec noise
    assert capsys.readouterr().out.startswith(f"rms {before:.2f} -> {after:.2f} arcsec")


# ---- load_table -----------------------------------------------------------------------------
@pytest.mark.parametrize("name", BUNDLED_TABLES)
def test_load_table_by_name_and_by_path(name):
    by_name = tp.load_table(name)
    by_path = tp.load_table(REPO_DIR / "models" / f"{name}.urdf")
    assert by_name.joint_names == by_path.joint_names
    assert by_name.parameter_names == by_path.parameter_names
    assert tp.load_table(by_name) is by_name
    model, data = by_name.nominal_pin_model, by_name.nominal_pin_data
    assert model.nv == len(by_name.joint_names)
    assert data is by_name.nominal_pin_data  # made once
    import pinocchio as pin

    pin.forwardKinematics(model, data, pin.neutral(model))


def test_load_table_default_mount_and_refusals():
    assert tp.load_table().joint_names == ("outer_axis", "inner_axis")
    assert tp.load_table("altaz_mount").telescope_mount == "altaz"
    assert tp.load_table("altaz_mount", mount="none").telescope_mount is None
    with pytest.raises(InputError, match="no such URDF file"):
        tp.load_table("no_such_table")


# ---- read_measurements ----------------------------------------------------------------------
class _Frame:
    """What read_measurements asks of a pandas DataFrame: ``to_csv(path, index=False)``."""

    def __init__(self, text: str) -> None:
        self.text = text

    def to_csv(self, path, index: bool = True) -> None:
        assert index is False
        with open(path, "w") as f:
            f.write(self.text)


def test_read_measurements_paths_frames_and_objects(simulated):
    from turntable_pin.measurement.data import read_measurements

    by_name = tp.read_measurements("measurements_example.csv")
    by_path = tp.read_measurements(EXAMPLES / "measurements_example.csv")
    direct = read_measurements(EXAMPLES / "measurements_example.csv")
    np.testing.assert_array_equal(by_name.angles_rad, direct.angles_rad)
    np.testing.assert_array_equal(by_path.joint_rad, direct.joint_rad)
    frame = _Frame((EXAMPLES / "measurements_example.csv").read_text())
    from_frame = tp.read_measurements(frame)
    np.testing.assert_allclose(from_frame.angles_rad, direct.angles_rad)
    assert from_frame.source == "a DataFrame"
    assert tp.read_measurements(simulated) is simulated.data
    assert tp.read_measurements(direct) is direct


def test_read_measurements_names_the_table_joints():
    data = tp.read_measurements("measurements_three_axis.csv", table="three_axis_imu_table")
    assert data.n_joints == 3


def test_read_measurements_frame_errors_are_the_file_errors():
    frame = _Frame("phi1_deg;phi2_deg;dpsi_arcsec;dtheta_arcsec;dgamma_arcsec\n0;0;1;2;3\n")
    with pytest.raises(InputError):
        tp.read_measurements(frame)


# ---- simulate -------------------------------------------------------------------------------
def test_simulate_errors_as_dict_vector_or_yaml_agree(paper, tmp_path):
    yaml_file = tmp_path / "errors.yaml"
    yaml_file.write_text("dphi_y1: 20\ndalpha_x2: -5\n")
    as_dict = tp.simulate(paper, errors={"dphi_y1": 20, "dalpha_x2": -5}, seed=4)
    vector = paper.errors_from_user_units({"dphi_y1": 20, "dalpha_x2": -5})
    as_vector = tp.simulate(paper, errors=vector, seed=4)
    as_yaml = tp.simulate(paper, errors=yaml_file, seed=4)
    for other in (as_vector, as_yaml):
        np.testing.assert_array_equal(other.data.angles_rad, as_dict.data.angles_rad)
    assert as_dict.seed == 4 and as_dict.errors["dphi_y1_arcsec"] == pytest.approx(20)


def test_simulate_is_the_command_lines_simulation(tmp_path):
    out = tmp_path / "sim.csv"
    result = cli("simulate", "--error", "dphi_y1=20", "--effect", "inner_encoder_harmonics:c1=3",
                 "--seed", "5", "--random-positions", "40", "-o", str(out))  # fmt: skip
    assert result.returncode == 0, result.stderr
    sim = tp.simulate(errors={"dphi_y1": 20}, effects={"inner_encoder_harmonics": {"c1": 3}},
                      seed=5, random_positions=40)  # fmt: skip
    written = tp.read_measurements(out)
    np.testing.assert_allclose(written.angles_rad, sim.data.angles_rad, atol=1e-15)


# ---- fit and diagnose -----------------------------------------------------------------------
def test_fit_paths_and_objects_agree_with_the_library(paper):
    from turntable_pin.measurement.catalogue import resolve_effect
    from turntable_pin.measurement.data import read_measurements
    from turntable_pin.measurement.fit import fit_orientation

    data = read_measurements(EXAMPLES / "measurements_example.csv")
    library = fit_orientation(data, [resolve_effect("inner_encoder_harmonics", paper)])
    for given in ("measurements_example.csv", data):
        for effects in ("inner_encoder_harmonics", ["inner_encoder_harmonics"]):
            fitted = tp.fit(given, effects, table=paper)
            np.testing.assert_allclose(fitted.result.params, library.result.params, atol=1e-15)
    assert tp.fit(data).effect_names == ()
    with pytest.raises(InputError, match="no_such_effect"):
        tp.fit(data, "no_such_effect")


def test_fit_ignore_sigma_estimates_the_noise():
    fitted = tp.fit("measurements_example.csv", ignore_sigma=True)
    assert (
        fitted.to_dict()["sigma_source"]
        != tp.fit("measurements_example.csv").to_dict()["sigma_source"]
    )


def test_diagnose_names_the_hidden_effects(diagnosis):
    assert diagnosis.missing_effect == "inner_encoder_harmonics"
    assert tp.diagnose("measurements_example.csv").missing_effect == "inner_encoder_harmonics"
    three = tp.diagnose("measurements_three_axis.csv", table="three_axis_imu_table")
    assert three.missing_effect == "wobble_harmonics@middle_gimbal"


def test_diagnose_takes_a_user_catalogue(simulated, paper):
    effect_file = EXAMPLES / "effects" / "inner_encoder_3rev.yaml"
    with_file = tp.diagnose(simulated, table=paper, catalogue=[effect_file])
    names = {c.effect for c in with_file.candidates}
    assert "inner_encoder_3rev" in names


# ---- design, allocate, calibrate, import_tpoint ---------------------------------------------
def test_design_modes(paper, simulated):
    identify = tp.design(paper, 10, effects="inner_encoder_harmonics", candidates=300, seed=2)
    assert type(identify).__name__ == "IdentifyDesign" and identify.n_positions == 10
    separate = tp.design(paper, 10, separate="inner_encoder_harmonics,inner_wobble_harmonics",
                         from_data=simulated, candidates=300)  # fmt: skip
    assert type(separate).__name__ == "SeparationDesign"
    calibration = tp.design(paper, 12, calibrate=True, candidates=300)
    assert type(calibration).__name__ == "CalibrationDesign"
    with pytest.raises(InputError, match="not both"):
        tp.design(paper, 10, separate="a,b", calibrate=True)
    with pytest.raises(InputError, match="two effects"):
        tp.design(paper, 10, separate="inner_encoder_harmonics")
    with pytest.raises(InputError, match="n_positions"):
        tp.design(paper, 10_000, candidates=100)


def test_design_is_the_command_lines_design(tmp_path):
    out = tmp_path / "plan.csv"
    result = cli("design", "-n", "9", "--effects", "inner_encoder_harmonics", "--candidates",
                 "300", "--seed", "1", "--json")  # fmt: skip
    assert result.returncode == 0, result.stderr
    ours = tp.design(None, 9, effects="inner_encoder_harmonics", candidates=300, seed=1)
    assert json.loads(result.stdout) == json.loads(ours.to_json())
    del out


def test_allocate_is_the_library_allocation():
    from turntable_pin.allocation.solver import OrientationLimits, allocate_tolerances

    limits = (0.6, 0.25, 0.45)
    ours = tp.allocate(limits_arcmin=limits)
    library = allocate_tolerances(OrientationLimits.from_arcmin(*limits))
    np.testing.assert_array_equal(ours.upper_bounds_rad, library.upper_bounds_rad)
    paper = tp.allocate(limits_arcmin=limits, weights="paper")
    assert paper.weights_scheme == "paper"


def test_calibrate_fits_or_diagnoses_a_run():
    from turntable_pin.calibration.drift_fit import calibrate_run
    from turntable_pin.calibration.site import DEFAULT_LATITUDE_DEG

    result = tp.calibrate("gyrowheel_run_example.csv")
    library = calibrate_run(
        EXAMPLES / "gyrowheel_run_example.csv", np.radians(DEFAULT_LATITUDE_DEG)
    )
    np.testing.assert_array_equal(result.x.coefficients_dph, library.x.coefficients_dph)
    diagnosis = tp.calibrate(EXAMPLES / "runs" / "run_inner_wobble.csv", diagnose=True)
    assert type(diagnosis).__name__ == "Diagnosis"
    assert diagnosis.missing_effect is not None


def test_import_tpoint_reads_back_as_the_commands_csv(tmp_path):
    run = tp.import_tpoint("mmt_pointing/k_and_e.dat")
    assert run.run.n_stars == 80 and run.urdf_name == "altaz_mount.urdf"
    out = tmp_path / "mmt.csv"
    result = cli("import-tpoint", str(EXAMPLES / "mmt_pointing" / "k_and_e.dat"), "-o", str(out))
    assert result.returncode == 0, result.stderr
    data = tp.read_measurements(run)
    np.testing.assert_array_equal(data.angles_rad, tp.read_measurements(out).angles_rad)
    table = tp.load_table(run)
    assert table.joint_names == ("azimuth", "elevation")
    assert tp.fit(data, "TF,TX", table=table).result.rms_user < 1.0
    fitted = tp.fit(run, "TF,TX")  # the run's mount, not the paper's table
    assert fitted.result.rms_user < 1.0
    assert "TPOINT terms (altaz mount;" in fitted._repr_html_()


# ---- the result objects in a notebook --------------------------------------------------------
def _results(paper, simulated, diagnosis):
    return {
        "measurements": simulated.data,
        "simulation": simulated,
        "fit": tp.fit(simulated, table=paper),
        "diagnosis": diagnosis,
        "identify": tp.design(paper, 8, candidates=200),
        "separate": tp.design(
            paper,
            8,
            separate="inner_encoder_harmonics,inner_wobble_harmonics",
            from_data=simulated,
            candidates=200,
        ),  # fmt: skip
        "calibration design": tp.design(paper, 12, calibrate=True, candidates=200),
        "allocation": tp.allocate(limits_arcmin=(0.6, 0.25, 0.45)),
        "calibration": tp.calibrate("gyrowheel_run_example.csv"),
        "tpoint": tp.import_tpoint("mmt_pointing/k_and_e.dat"),
    }


def test_results_show_plot_and_serialise_themselves(paper, simulated, diagnosis):
    from matplotlib.figure import Figure

    for name, result in _results(paper, simulated, diagnosis).items():
        page = result._repr_html_()
        assert page.startswith('<div class="turntable-pin">') and page.endswith("</div>"), name
        assert "<html" not in page and "body{" not in page, name
        assert page.count('<div class="turntable-pin">') == 1, name  # one style, not nested
        text = result.to_json()
        assert json.loads(text) == jsonable(result.to_dict()), name
        if name == "calibration":
            with pytest.raises(TurntablePinError, match="no figure"):
                result.plot()
            continue
        figures = result.plot()
        assert figures and all(isinstance(f, Figure) for f in figures), name
        assert all(f.axes for f in figures), name


def test_views_come_from_the_reports(paper, diagnosis):
    from turntable_pin.report.diagnosis_text import headline

    page = diagnosis._repr_html_()
    assert headline(diagnosis.to_dict()).split(":")[0] in page
    allocation = tp.allocate(limits_arcmin=(0.6, 0.25, 0.45))
    assert allocation.report().splitlines()[0].strip() in allocation._repr_html_().replace(
        "&#x27;", "'"
    ).replace("&quot;", '"')
    assert len(diagnosis.plot()) == 3  # residuals, harmonics, residual maps: what --plots writes


def test_plot_writes_nothing_outside_a_temporary_folder(tmp_path, monkeypatch, diagnosis):
    monkeypatch.chdir(tmp_path)
    diagnosis.plot()
    assert list(tmp_path.iterdir()) == []


def test_scoped_style_confines_every_rule():
    from turntable_pin.report.notebook import scoped_style

    css = scoped_style("body{a:b}\ntd,th{c:d}h1{e:f}")
    assert (
        css == ".turntable-pin{a:b}.turntable-pin td,.turntable-pin th{c:d}.turntable-pin h1{e:f}"
    )


def test_docstrings_are_numpy_style():
    from turntable_pin import api

    for name in api.__all__:
        doc = inspect.getdoc(getattr(api, name)) or ""
        for section in ("Parameters\n----------", "Returns\n-------", "Examples\n--------"):
            assert section in doc, f"{name}: no {section.splitlines()[0]} section"


def test_docstring_examples_run():
    import doctest

    from turntable_pin import api

    result = doctest.testmod(api, optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    assert result.attempted >= 20 and result.failed == 0
