"""Every bundled example gets its whole report: ``report`` writes the page, ``fit --plots`` and
``diagnose --plots`` write every figure, for each simulated example file (with the URDF its truth
names) and for the real telescope runs imported with ``import-tpoint``, whose roll (``dgamma``)
is not measured."""

from __future__ import annotations

import json

import pytest

from conftest import EXAMPLES_DIR, REPO_DIR, cli
from turntable_pin.core.files import read_yaml
from turntable_pin.measurement.data import read_measurements
from turntable_pin.model.generic_table import GenericTable

RESIDUAL_PLOTS = ("residuals.png", "harmonics.png")
"""What ``write_residual_plots`` writes for every residual set."""

MAP_PLOT = "residual_maps.png"
"""Written besides when the data have two or more joints (a map over the first two)."""


def _orientation_files() -> list[str]:
    """The example CSVs that are orientation-measurement files (a ``dpsi_arcsec`` column)."""
    out = []
    for path in sorted(EXAMPLES_DIR.glob("*.csv")):
        header = next(ln for ln in path.read_text().splitlines() if ln and ln[0] != "#")
        if "dpsi_arcsec" in header.split(","):
            out.append(path.name)
    return out


def _simulated_cases() -> list[tuple[str, str | None]]:
    """(example file, its URDF or None for the paper's table), from the examples' truths."""
    urdf = {}
    for truth in (EXAMPLES_DIR / "truth").glob("*.yaml"):
        entry = read_yaml(truth)
        urdf[entry["data"]] = entry["urdf"] and str(REPO_DIR / "models" / entry["urdf"])
    return [(name, urdf.get(name, "no truth names its URDF")) for name in _orientation_files()]


@pytest.fixture(scope="module")
def real_runs(tmp_path_factory) -> dict[str, tuple]:
    """The bundled TPOINT runs as measurement files: ``{name: (csv, urdf)}``."""
    folder = tmp_path_factory.mktemp("runs")
    mmt, gem, gem_urdf = folder / "mmt_run.csv", folder / "gem_run.csv", folder / "gem.urdf"
    result = cli("import-tpoint", str(EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"),
                 "-o", str(mmt))  # fmt: skip
    assert result.returncode == 0, result.stderr
    result = cli("import-tpoint", str(EXAMPLES_DIR / "gem_pointing" / "gem-28.dat"),
                 "-o", str(gem), "--write-urdf", str(gem_urdf))  # fmt: skip
    assert result.returncode == 0, result.stderr
    return {"mmt": (mmt, str(REPO_DIR / "models" / "altaz_mount.urdf")), "gem": (gem, gem_urdf)}


def _n_joints(data, urdf) -> int:
    joints = None if urdf is None else GenericTable(urdf).joint_names
    return read_measurements(data, joints).n_joints


def _check_report_and_plots(data, urdf, folder) -> None:
    table = [] if urdf is None else ["--urdf", str(urdf)]
    page = folder / "report.html"
    result = cli("report", str(data), *table, "-o", str(page))
    assert result.returncode == 0, result.stderr
    assert page.is_file() and "<img" in page.read_text()

    expected = [*RESIDUAL_PLOTS, *([MAP_PLOT] if _n_joints(data, urdf) >= 2 else [])]
    result = cli("fit", str(data), *table, "--plots", str(folder / "fit"))
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in (folder / "fit").iterdir()) == sorted(expected)

    result = cli("diagnose", str(data), *table, "--plots", str(folder / "diagnose"), "--json")
    assert result.returncode == 0, result.stderr
    terms = json.loads(result.stdout)["verdict"]["remaining_structure"]
    expected += [f"structure_{i}.png" for i in range(1, len(terms) + 1)]
    assert sorted(p.name for p in (folder / "diagnose").iterdir()) == sorted(expected)
    for png in [*(folder / "fit").iterdir(), *(folder / "diagnose").iterdir()]:
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n", png


def test_every_orientation_example_has_a_truth_naming_its_urdf():
    cases = _simulated_cases()
    assert len(cases) >= 5
    assert [c for c in cases if c[1] == "no truth names its URDF"] == []


@pytest.mark.slow
@pytest.mark.parametrize(
    ("name", "urdf"), _simulated_cases(), ids=[c[0] for c in _simulated_cases()]
)
def test_each_simulated_example_gets_its_page_and_every_figure(name, urdf, tmp_path):
    _check_report_and_plots(EXAMPLES_DIR / name, urdf, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("run", ["mmt", "gem"])
def test_each_real_run_gets_its_page_and_every_figure_without_its_roll(run, real_runs, tmp_path):
    """Pointing runs leave ``dgamma`` empty in every row (the roll is not measured). Only that
    the page and every figure are written is checked here, not the numbers."""
    data, urdf = real_runs[run]
    assert not read_measurements(data, GenericTable(urdf).joint_names).measured[:, 2].any()
    _check_report_and_plots(data, urdf, tmp_path)
