"""The headless snapshot: a real picture of the setup, reproducible, nothing left running."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.colors as mcolors
import matplotlib.image as mimage
import numpy as np
import pytest

from conftest import needs_chromium
from process_watch import ProcessWatch, alive
from turntable_pin import InputError, TurntableErrors
from turntable_pin.viewer.browser import CHROMIUM_ENV, BrowserError
from turntable_pin.viewer.scene import SetupScene
from turntable_pin.viewer.snapshot import decorate_static_page, render_snapshot

pytest.importorskip("meshcat")


EXAMPLE = TurntableErrors.from_arcsec(dalpha_x1=3.0, deps_x=4.0, deps_y=-3.0, deta_mm=0.2)
# The URDF's material gyrowheel_orange, rgba 1.0 0.55 0.0: its hue, in degrees.
PAYLOAD_HUE_DEG = mcolors.rgb_to_hsv((1.0, 0.55, 0.0))[0] * 360.0


def _pixels(path) -> np.ndarray:
    return mimage.imread(path)[..., :3]  # floats in [0, 1]


def _payload_pixels(rgb: np.ndarray) -> int:
    """Pixels of the payload's colour under any shading: its hue, strongly saturated."""
    hsv = mcolors.rgb_to_hsv(rgb)
    hue_deg = hsv[..., 0] * 360.0
    return int(np.sum((np.abs(hue_deg - PAYLOAD_HUE_DEG) < 8.0) & (hsv[..., 1] > 0.7)))


@pytest.fixture(scope="module")
def shots(tmp_path_factory):
    out = tmp_path_factory.mktemp("shots")
    scene = SetupScene(EXAMPLE)
    with ProcessWatch() as watch:
        first = render_snapshot(scene, np.radians([30, 45]), out / "a.png")
    again = render_snapshot(scene, np.radians([30, 45]), out / "b.png")
    other = render_snapshot(scene, np.radians([90, 0]), out / "c.png")
    return {"first": first, "again": again, "other": other, "watch": watch}


@pytest.mark.slow
@needs_chromium
def test_snapshot_is_a_real_picture_of_the_setup(shots):
    result = shots["first"]
    rgb = _pixels(result.path)
    assert rgb.shape == (600, 800, 3)
    colours = np.unique((rgb * 255).round().astype(np.uint8).reshape(-1, 3), axis=0)
    assert len(colours) > 500, "a blank or flat page, not a rendered scene"
    assert rgb.std() > 0.1
    assert _payload_pixels(rgb) > 500, "the orange GyroWheel is not in the picture"
    assert result.to_dict()["exaggeration"]["angle_factor"] == pytest.approx(2700.0)


@pytest.mark.slow
@needs_chromium
def test_same_angles_same_picture_other_angles_other_picture(shots):
    a = shots["first"].path.read_bytes()
    assert shots["again"].path.read_bytes() == a
    other = _pixels(shots["other"].path)
    changed = np.any(np.abs(other - _pixels(shots["first"].path)) > 0.05, axis=-1)
    assert changed.mean() > 0.02, "turning the table by 60 and 45 degrees changed nothing"
    assert _payload_pixels(other) > 200


@pytest.mark.slow
@needs_chromium
def test_no_server_or_browser_remains(shots):
    watch, result = shots["watch"], shots["first"]
    assert watch.server_pids == {result.server_pid}
    assert watch.browser_pids, "the watcher saw no browser process (the check would be empty)"
    assert watch.survivors() == []
    assert not alive(result.server_pid) and not alive(result.browser_pid)


@needs_chromium
def test_a_failing_browser_leaves_nothing_and_keeps_the_old_file(tmp_path, monkeypatch):
    out = tmp_path / "keep.png"
    out.write_bytes(b"old")
    monkeypatch.setenv(CHROMIUM_ENV, "false")  # a program that exits at once, writing nothing
    with ProcessWatch() as watch, pytest.raises(BrowserError, match="no screenshot"):
        render_snapshot(SetupScene(EXAMPLE), (0.0, 0.0), out, width=200, height=150)
    assert out.read_bytes() == b"old"
    assert len(watch.server_pids) == 1
    assert watch.survivors() == []


def test_snapshot_refuses_bad_sizes_and_names_before_starting_anything(tmp_path):
    scene = SetupScene(EXAMPLE)
    with pytest.raises(InputError, match="width"):
        render_snapshot(scene, (0.0, 0.0), tmp_path / "a.png", width=10)
    with pytest.raises(InputError, match=r"\.png"):
        render_snapshot(scene, (0.0, 0.0), tmp_path / "a.jpg")


def test_decorated_page_hides_the_controls_and_escapes_the_legend():
    page = decorate_static_page("<html><body><p>x</p></body></html>", ["a < b", "phi1 = 30 deg"])
    assert ".dg.main { display: none !important; }" in page
    assert "a &lt; b<br>phi1 = 30 deg" in page
    assert page.index("turntable-pin-legend") < page.index("</body>")
