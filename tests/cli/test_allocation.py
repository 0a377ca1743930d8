"""``turntable-pin allocate`` and ``montecarlo``: JSON keys, Table 4, units, clear errors."""

import json

import numpy as np
import pytest

from conftest import cli
from turntable_pin import ANGULAR_ERROR_NAMES
from turntable_pin.cli import main
from turntable_pin.cli.allocation import parse_limits
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.units import ARCMIN_PER_RAD

PAPER = ["--limits-arcmin", "psi=1.4801,theta=1.56,gamma=1.4801", "--weights", "paper"]


def json_of(capsys, argv):
    status = main(argv)
    return status, json.loads(capsys.readouterr().out)


def test_allocate_json_reproduces_table4(capsys):
    status, out = json_of(capsys, ["allocate", *PAPER, "--json"])
    assert status == 0
    ub = out["upper_bounds_arcmin"]
    assert set(ub) == set(ANGULAR_ERROR_NAMES)
    assert round(ub["dphi_z2"], 4) == 0.78 and round(ub["dalpha_x2"], 4) == 0.2825
    assert round(ub["deps_x"], 4) == 0.4234
    assert set(out["J"]) == {"psi", "theta", "gamma", "total"}
    for name, value in out["worst_case_arcmin"].items():
        assert value <= out["limits_arcmin"][name] + 1e-12


def test_limits_in_degrees_equal_limits_in_arcmin(capsys):
    _, arcmin = json_of(capsys, ["allocate", "--limits-arcmin", "1.62", "--weights", "equal",
                                 "--json"])  # fmt: skip
    _, deg = json_of(capsys, ["allocate", "--limits-deg", "psi=0.027,theta=0.027,gamma=0.027",
                              "--weights", "equal", "--json"])  # fmt: skip
    for name in ANGULAR_ERROR_NAMES:
        assert deg["upper_bounds_arcmin"][name] == pytest.approx(
            arcmin["upper_bounds_arcmin"][name], rel=1e-12
        )


@pytest.mark.slow
def test_default_limits_are_the_orientation_requirement(capsys):
    from turntable_pin import PositionSet, orientation_requirement

    _, out = json_of(capsys, ["allocate", "--json"])
    req = orientation_requirement(0.01, PositionSet.parse("grid:30"), np.radians(45.75))
    expected = {"psi": req.box.psi_rad, "theta": req.box.theta_rad, "gamma": req.box.gamma_rad}
    assert out["limits_arcmin"] == pytest.approx(
        {k: v * ARCMIN_PER_RAD for k, v in expected.items()}
    )
    _, planes = json_of(capsys, ["allocate", "--json", "--requirement", "planes"])
    assert planes["limits_arcmin"] == pytest.approx(
        {"psi": req.psi_rad * ARCMIN_PER_RAD, "theta": req.theta_rad * ARCMIN_PER_RAD,
         "gamma": req.gamma_rad * ARCMIN_PER_RAD}
    )  # fmt: skip
    assert out["weights"] == "model"
    _, looser = json_of(capsys, ["allocate", "--json", "--accuracy-dph", "0.02"])
    assert all(looser["limits_arcmin"][k] > out["limits_arcmin"][k] for k in expected)


def test_allocate_text_and_figure8(tmp_path, capsys):
    assert main(["allocate", *PAPER, "--plots", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "dalpha_y2" in text and "worst case" in text
    assert (tmp_path / "figure8_sensitivities.png").read_bytes()[:4] == b"\x89PNG"


def test_montecarlo_json(tmp_path, capsys):
    status, out = json_of(
        capsys,
        ["montecarlo", *PAPER, "-n", "3000", "--seed", "4", "--plots", str(tmp_path), "--json"],
    )
    assert status == 0
    assert out["all_within"] is True and out["seed"] == 4 and out["n"] == 3000
    assert set(out["max_abs_arcmin"]) == set(out["limits_arcmin"]) == {"psi", "theta", "gamma"}
    assert (tmp_path / "figure9_montecarlo.png").is_file()


def test_montecarlo_beyond_the_bounds_fails_with_status_1(capsys):
    status, out = json_of(
        capsys, ["montecarlo", *PAPER, "-n", "3000", "--scale-bounds", "1.2", "--json"]
    )
    assert status == 1
    assert out["all_within"] is False


def test_infeasible_lower_bounds_exit_2_with_one_line(tmp_path):
    lb = tmp_path / "lb.yaml"
    lb.write_text("lower_bounds:\n  dalpha_x2_arcmin: 2.0\n")
    proc = cli("allocate", *PAPER, "--lower-bounds", str(lb))
    assert proc.returncode == 2
    assert proc.stderr.count("\n") == 1 and "Traceback" not in proc.stderr
    assert "dgamma" in proc.stderr and "above the limit" in proc.stderr


@pytest.mark.parametrize(
    "args, fragment",
    [
        (["--limits-arcmin", "psi=1,theta=2"], "no limit for gamma"),
        (["--limits-arcmin", "psi=1,theta=2,gamma=-1"], "positive"),
        (["--limits-arcmin", "psi=1,theta=x,gamma=1"], "expected a number"),
        (["--limits-arcmin", "psi=1,tau=2,gamma=1"], "expected psi=P"),
        (["--lower-bounds", "/nonexistent/lb.yaml"], "cannot read"),
    ],
)
def test_bad_input_exit_2(args, fragment, capsys):
    assert main(["allocate", *args]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1


def test_parse_limits_one_number_for_all():
    limits = parse_limits("1.5", "arcmin").to_dict()
    assert limits == pytest.approx({"psi": 1.5, "theta": 1.5, "gamma": 1.5})
    with pytest.raises(InputError, match="twice"):
        parse_limits("psi=1,psi=2,theta=1,gamma=1", "deg")


@pytest.mark.parametrize("table", [[], ["--urdf", "two_axis_vertical_outer"]])
def test_the_text_says_what_holds_for_the_final_bounds(table):
    # Issue 18: "dpsi limit 0.6'  worst case 0.3031' ... active: first-order max |dpsi| = limit"
    # showed a line of the psi sub-problem as if it held for the result.
    args = [*table, "--limits-arcmin", "psi=0.6,theta=0.25,gamma=0.45"]
    text = cli("allocate", *args).stdout
    out = json.loads(cli("allocate", *args, "--json").stdout)
    for name in ("psi", "theta", "gamma"):
        limit = {"psi": 0.6, "theta": 0.25, "gamma": 0.45}[name]
        worst = out["worst_case_arcmin"][name]
        line = next(x for x in text.splitlines() if x.startswith(f"d{name} ") and "limit" in x)
        state = "(at the limit)" if worst >= limit * (1 - 1e-6) else f"({worst / limit:.0%} of"
        assert state in line, line
    assert "active in it:" in text and "active: " not in text


def test_allocate_reports_the_default_limits_progress_unless_quiet(monkeypatch):
    """The default limits are a requirement (seconds on a three-axis grid): its progress goes to
    stderr, never to stdout; --quiet and --json silence it (issue 30)."""
    import turntable_pin.calibration.requirement as requirement

    monkeypatch.setattr(requirement, "PROGRESS_DELAY_S", 0.0)
    args = ["allocate", "--positions", "grid:90"]
    loud = cli(*args)
    assert loud.returncode == 0 and "requirement (16 positions): 100%" in loud.stderr
    assert "requirement (" not in loud.stdout
    for extra in ("--quiet", "--json"):
        quiet = cli(*args, extra)
        assert quiet.returncode == 0 and "requirement (" not in quiet.stderr
