"""The CLI's shared helpers: bundled files by name, the one version."""

import re
from pathlib import Path

from conftest import EXAMPLES_DIR, cli
from turntable_pin.cli.common import input_path

ROOT = Path(__file__).resolve().parents[2]


def test_a_file_that_is_there_is_read_as_given(tmp_path):
    mine = tmp_path / "measurements_example.csv"
    mine.write_text("x")
    assert input_path(str(mine)) == mine


def test_bundled_files_are_found_by_name_from_any_folder(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    models = EXAMPLES_DIR.parent
    assert input_path("altaz_mount") == models / "altaz_mount.urdf"
    assert input_path("altaz_mount.urdf") == models / "altaz_mount.urdf"
    assert input_path("measurements_example.csv") == EXAMPLES_DIR / "measurements_example.csv"
    assert input_path("mmt_pointing/k_and_e.dat") == EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"
    assert input_path("models/examples/measurements_example.csv") == (
        EXAMPLES_DIR / "measurements_example.csv"
    )
    assert input_path("nothing_like_it.csv") == Path("nothing_like_it.csv")  # said missing later


def test_one_version_the_metadata_s_the_project_s_and_the_changelog_s():
    version = re.search(r'^version = "(.+)"', (ROOT / "pyproject.toml").read_text(), re.M)[1]
    proc = cli("--version")
    assert proc.returncode == 0 and proc.stdout.strip() == f"turntable-pin {version}"
    changelog = (ROOT / "docs" / "changelog.md").read_text().split("# Changelog", 1)[1]
    assert re.search(r"^- \*\*([0-9.]+),", changelog, re.M)[1] == version
