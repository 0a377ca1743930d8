"""The figure gallery: every viz/ script runs (fast settings) and every image of the index loads
in a real browser, so the examples never rot."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys

import pytest

from conftest import VIZ_DIR, cli_env, needs_chromium
from turntable_pin.viewer.browser import check_page_images, chromium_available

SCRIPTS = sorted(VIZ_DIR.glob("fig_*.py"))


def _load_make_all():
    spec = importlib.util.spec_from_file_location("viz_make_all", VIZ_DIR / "make_all.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses look their module up there
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def gallery(tmp_path_factory):
    out = tmp_path_factory.mktemp("figures")
    proc = subprocess.run(
        [sys.executable, str(VIZ_DIR / "make_all.py"), "-o", str(out), "--fast"],
        capture_output=True,
        text=True,
        timeout=600,
        env=cli_env(),
    )
    assert proc.returncode == 0, proc.stderr
    return out, proc.stdout


@pytest.mark.slow
def test_every_figure_script_ran_and_is_on_the_index(gallery):
    out, stdout = gallery
    assert len(SCRIPTS) >= 3
    page = (out / "index.html").read_text()
    for script in SCRIPTS:
        assert f"{script.name}:" in stdout
        assert f'id="{script.stem}"' in page
    for src in re.findall(r'<img src="([^"]+)"', page):
        assert (out / src).is_file()
    if not chromium_available():
        # The 3-D figures are listed as skipped, saying that the browser is missing.
        assert re.search(r'class="skip">skipped: [^<]*chromium', page, re.IGNORECASE)


@pytest.mark.slow
@needs_chromium
def test_every_image_of_the_index_loads_in_the_browser(gallery):
    out, _ = gallery
    report = check_page_images(out / "index.html")
    n_tags = len(re.findall(r"<img ", (out / "index.html").read_text()))
    assert report.n_images == n_tags >= len(SCRIPTS)
    assert report.all_loaded, report.failed


def test_a_figure_script_that_writes_nothing_is_an_error(tmp_path, monkeypatch):
    make_all = _load_make_all()
    script = tmp_path / "fig_empty.py"
    script.write_text('"""Empty."""\n\ndef main(out_dir, fast=False):\n    return []\n')
    with pytest.raises(RuntimeError, match="wrote no figure"):
        make_all.run_script(script, tmp_path, fast=True)
    broken = tmp_path / "fig_broken.py"
    broken.write_text("def main(out_dir, fast=False):\n    raise ValueError('rotten')\n")
    with pytest.raises(ValueError, match="rotten"):
        make_all.run_script(broken, tmp_path, fast=True)


def test_adding_a_figure_is_adding_a_file(tmp_path, monkeypatch):
    make_all = _load_make_all()
    viz = tmp_path / "viz"
    viz.mkdir()
    (viz / "fig_square.py").write_text(
        '"""A square.\n\nIts caption."""\n'
        "import matplotlib\nmatplotlib.use('Agg')\nimport matplotlib.pyplot as plt\n"
        "from pathlib import Path\n\n"
        "def main(out_dir, fast=False):\n"
        "    out = Path(out_dir) / 'square.png'\n"
        "    plt.figure(figsize=(1, 1)); plt.plot([0, 1]); plt.savefig(out); plt.close()\n"
        "    return [out]\n"
    )
    monkeypatch.setattr(make_all, "VIZ_DIR", viz)
    runs = make_all.make_all(tmp_path / "out", fast=True)
    assert [(r.title, r.caption, r.images) for r in runs] == [
        ("A square.", "Its caption.", ["square.png"])
    ]
    assert '<img src="square.png"' in (tmp_path / "out" / "index.html").read_text()
