"""A PNG of the setup scene, rendered without a display: meshcat's static page in headless Chromium.

The scene is drawn into a short-lived meshcat server, which hands back a self-contained HTML page
(``static_html``, about 0.9 MB, works offline); the server is then stopped. The page gets the
controls panel hidden and a legend, and headless Chromium renders it to PNG
(:func:`turntable_pin.viewer.browser.screenshot_html`). Neither the server nor the browser nor a
temporary folder outlives the call, also on error or interruption. The same scene and angles give
a byte-identical PNG (virtual time).
"""

from __future__ import annotations

import html
import time
from dataclasses import dataclass
from pathlib import Path

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
    "RenderedSnapshot",
    "SnapshotResult",
    "TableSnapshotResult",
    "decorate_static_page",
    "render_snapshot",
    "render_table_snapshot",
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
class RenderedSnapshot:
    """What every written snapshot says: path, size (px), magnification, timings (s), pids;
    the position is the subclass's (:meth:`position_dict`)."""

    path: Path
    width: int
    height: int
    exaggeration: dict
    scene_seconds: float
    browser_seconds: float
    server_pid: int
    browser_pid: int

    def position_dict(self) -> dict:
        """Where the table stood, degrees, JSON-ready (none here)."""
        return {}

    def to_dict(self) -> dict:
        """The result as a JSON-ready dict (sizes in px, angles in deg, times in s; no pids)."""
        return {
            "path": str(self.path),
            "width_px": self.width,
            "height_px": self.height,
            **self.position_dict(),
            "exaggeration": self.exaggeration,
            "scene_seconds": self.scene_seconds,
            "browser_seconds": self.browser_seconds,
        }


@dataclass(frozen=True)
class SnapshotResult(RenderedSnapshot):
    """A written snapshot of the paper's table: :class:`RenderedSnapshot` at (phi1, phi2), deg."""

    phi1_deg: float
    phi2_deg: float

    def position_dict(self) -> dict:
        """``phi1_deg`` and ``phi2_deg``."""
        return {"phi1_deg": self.phi1_deg, "phi2_deg": self.phi2_deg}


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


def scene_page(
    scene: SetupScene, phi1_rad: float, *more_angles_rad: float, legend: bool = True
) -> tuple[str, int]:
    """The decorated static HTML page of ``scene`` at (phi1, phi2) (a
    :class:`~turntable_pin.viewer.table_scene.TableScene`: at its joint angles, one per joint),
    and the pid of the (now stopped) meshcat server that made it."""
    angles = (phi1_rad, *more_angles_rad)
    with MeshcatServer() as server:
        scene.draw(server.visualizer)
        scene.set_position(*angles)
        page = server.visualizer.static_html()
        pid = server.pid
    return decorate_static_page(page, scene.legend(*angles) if legend else None), pid


def _check_size(name: str, value: int) -> int:
    if not MIN_SIZE_PX <= int(value) <= MAX_SIZE_PX:
        raise InputError(
            f"{name} must be between {MIN_SIZE_PX} and {MAX_SIZE_PX} pixels, got {value}"
        )
    return int(value)


def _render(scene, angles_rad, output, width, height, legend, timeout_s) -> dict:
    """Render ``scene`` at ``angles_rad`` to the PNG ``output``: the fields of
    :class:`RenderedSnapshot`, by name."""
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
    page, server_pid = scene_page(scene, *angles_rad, legend=legend)
    scene_seconds = time.perf_counter() - start
    with temporary_folder("turntable-pin-scene-") as tmp:
        page_path = tmp / "scene.html"
        page_path.write_text(page, encoding="utf-8")
        data, run = screenshot_html(
            page_path, width=width, height=height, timeout_s=timeout_s, chromium=chromium
        )
    write_bytes_atomic(output, data)
    return {
        "path": output,
        "width": width,
        "height": height,
        "exaggeration": scene.exaggeration.to_dict(),
        "scene_seconds": scene_seconds,
        "browser_seconds": run.seconds,
        "server_pid": server_pid,
        "browser_pid": run.pid,
    }


def render_snapshot(
    scene: SetupScene,
    phi1_rad: float,
    phi2_rad: float,
    output: str | Path,
    *,
    width: int = 800,
    height: int = 600,
    legend: bool = True,
    timeout_s: float = 60.0,
) -> SnapshotResult:
    """Render ``scene`` at commanded angles (phi1, phi2), radians, to the PNG file ``output``.

    Raises:
        MeshcatMissingError: meshcat is not installed.
        BrowserNotFoundError: no Chromium (names the Debian package ``chromium``).
        BrowserError: Chromium failed or timed out.
    """
    rendered = _render(scene, (phi1_rad, phi2_rad), output, width, height, legend, timeout_s)
    return SnapshotResult(
        **rendered,
        phi1_deg=round(float(phi1_rad) * DEG_PER_RAD, 9),
        phi2_deg=round(float(phi2_rad) * DEG_PER_RAD, 9),
    )


@dataclass(frozen=True)
class TableSnapshotResult(RenderedSnapshot):
    """A written snapshot of any table: :class:`RenderedSnapshot` at its joint angles (deg)."""

    angles_deg: dict

    def position_dict(self) -> dict:
        """``angles_deg``: ``{joint: degrees}``."""
        return {"angles_deg": dict(self.angles_deg)}


def render_table_snapshot(
    scene,
    angles_rad,
    output: str | Path,
    *,
    width: int = 800,
    height: int = 600,
    legend: bool = True,
    timeout_s: float = 60.0,
) -> TableSnapshotResult:
    """Render a :class:`~turntable_pin.viewer.table_scene.TableScene` at its joint angles
    (radians, chain order) to the PNG file ``output``; raises as :func:`render_snapshot`."""
    angles = tuple(float(a) for a in angles_rad)
    rendered = _render(scene, angles, output, width, height, legend, timeout_s)
    return TableSnapshotResult(
        **rendered,
        angles_deg={
            j: round(a * DEG_PER_RAD, 9)
            for j, a in zip(scene.table.joint_names, angles, strict=True)
        },
    )
