"""A PNG of the setup scene of any table, rendered headless: meshcat's static page in Chromium.

A short-lived meshcat server hands back a self-contained HTML page (``static_html``, about
0.9 MB); with the controls hidden and a legend, headless Chromium renders it to PNG
(:func:`~turntable_pin.viewer.browser.screenshot_html`). Nothing outlives the call, also on error
or interruption; the same scene and angles give a byte-identical PNG (virtual time).
"""

from __future__ import annotations

import html
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.files import write_bytes_atomic
from ..core.interrupts import temporary_folder
from ..core.units import DEG_PER_RAD
from .browser import find_chromium, screenshot_html
from .meshcat_server import MeshcatServer, import_meshcat
from .scene import SetupScene

__all__ = [
    "MAX_SIZE_PX",
    "MIN_SIZE_PX",
    "SnapshotResult",
    "decorate_static_page",
    "render_snapshot",
    "scene_page",
]

MIN_SIZE_PX = 64
"""Smallest snapshot width or height, pixels."""
MAX_SIZE_PX = 4096
"""Largest snapshot width or height, pixels."""

_PAGE_STYLE = """
<style>
  .dg.main { display: none !important; }
  #turntable-pin-legend {
    position: fixed; left: 10px; top: 10px; padding: 6px 9px; max-width: 70%;
    font: 12px/1.35 sans-serif; color: #111; background: rgba(255, 255, 255, 0.82);
    border-radius: 4px; pointer-events: none;
  }
</style>
"""


@dataclass(frozen=True)
class SnapshotResult:
    """A written snapshot: path, size (px), the joint angles (deg), magnification, timings (s)
    and the pids of the (stopped) server and browser."""

    path: Path
    width: int
    height: int
    angles_deg: dict
    exaggeration: dict
    scene_seconds: float
    browser_seconds: float
    server_pid: int
    browser_pid: int

    def to_dict(self, position: dict | None = None) -> dict:
        """The result as a JSON-ready dict (sizes in px, angles in deg, times in s; no pids);
        ``position`` names the position in the caller's words (default ``angles_deg``:
        ``{joint: degrees}``)."""
        return {
            "path": str(self.path),
            "width_px": self.width,
            "height_px": self.height,
            **(position if position is not None else {"angles_deg": dict(self.angles_deg)}),
            "exaggeration": self.exaggeration,
            "scene_seconds": self.scene_seconds,
            "browser_seconds": self.browser_seconds,
        }


def decorate_static_page(page: str, legend: list[str] | None = None) -> str:
    """meshcat's static page with the controls panel hidden and ``legend`` lines overlaid."""
    extra = _PAGE_STYLE
    if legend:
        lines = "<br>".join(html.escape(line) for line in legend)
        extra += f'<div id="turntable-pin-legend">{lines}</div>'
    closing = page.lower().rfind("</body>")
    if closing < 0:
        return page + extra
    return page[:closing] + extra + page[closing:]


def scene_page(scene: SetupScene, *angles_rad: float, legend: bool = True) -> tuple[str, int]:
    """The decorated static HTML page of ``scene`` at its joint angles (radians, one per joint),
    and the pid of the (now stopped) meshcat server that made it."""
    with MeshcatServer() as server:
        scene.draw(server.visualizer)
        scene.set_position(*angles_rad)
        page = server.visualizer.static_html()
        pid = server.pid
    return decorate_static_page(page, scene.legend(*angles_rad) if legend else None), pid


def _check_size(name: str, value: int) -> int:
    if not MIN_SIZE_PX <= int(value) <= MAX_SIZE_PX:
        raise InputError(
            f"{name} must be between {MIN_SIZE_PX} and {MAX_SIZE_PX} pixels, got {value}"
        )
    return int(value)


def render_snapshot(
    scene: SetupScene,
    angles_rad,
    output: str | Path,
    *,
    width: int = 800,
    height: int = 600,
    legend: bool = True,
    timeout_s: float = 60.0,
) -> SnapshotResult:
    """Render ``scene`` at the joint angles ``angles_rad`` (chain order, radians) to the PNG file
    ``output``. Raises :class:`MeshcatMissingError`, :class:`BrowserNotFoundError` (naming the
    Debian package ``chromium``) or :class:`BrowserError` (Chromium failed or timed out)."""
    angles = tuple(float(a) for a in np.ravel(angles_rad))
    joints = scene.table.joint_names
    if len(angles) != len(joints):
        raise InputError(
            f"expected {len(joints)} joint angle(s) ({', '.join(joints)}), got {len(angles)}"
        )
    width, height = _check_size("width", width), _check_size("height", height)
    output = Path(output)
    if output.suffix.lower() != ".png":
        raise InputError(
            "the snapshot is a PNG image: give an output name ending in .png", path=output
        )
    # Fail on a missing browser or meshcat before starting anything.
    chromium = find_chromium()
    import_meshcat()
    start = time.perf_counter()
    page, server_pid = scene_page(scene, *angles, legend=legend)
    scene_seconds = time.perf_counter() - start
    with temporary_folder("turntable-pin-scene-") as tmp:
        page_path = tmp / "scene.html"
        page_path.write_text(page, encoding="utf-8")
        data, run = screenshot_html(
            page_path, width=width, height=height, timeout_s=timeout_s, chromium=chromium
        )
    write_bytes_atomic(output, data)
    return SnapshotResult(
        path=output,
        width=width,
        height=height,
        angles_deg={j: round(a * DEG_PER_RAD, 9) for j, a in zip(joints, angles, strict=True)},
        exaggeration=scene.exaggeration.to_dict(),
        scene_seconds=scene_seconds,
        browser_seconds=run.seconds,
        server_pid=server_pid,
        browser_pid=run.pid,
    )
