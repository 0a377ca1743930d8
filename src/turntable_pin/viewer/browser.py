"""Headless Chromium as a tool: render a local HTML page to PNG, or check that its images load.

Every run gets a throw-away profile and XDG/TMPDIR folders in a temporary folder (nothing goes
into the home folder); its processes are killed and waited for, and the folder removed, before a
function returns, also on error, timeout or interruption. Chromium (Debian package ``chromium``)
is an external program; without it these functions raise :class:`BrowserNotFoundError`.
"""

from __future__ import annotations

import html
import json
import os
import re
import shutil
import signal
import subprocess
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..core.exceptions import TurntablePinError
from ..core.interrupts import deferred, register_cleanup, temporary_folder

__all__ = [
    "CHROMIUM_ENV",
    "CRASH_ATTEMPTS",
    "CHROMIUM_NAMES",
    "DEBIAN_PACKAGE",
    "BrowserError",
    "BrowserNotFoundError",
    "BrowserRun",
    "ImageLoadReport",
    "ImageStatus",
    "ProcessInfo",
    "check_page_images",
    "chromium_available",
    "descendant_processes",
    "find_chromium",
    "kill_descendant_processes",
    "kill_related_processes",
    "png_size",
    "process_table",
    "related_processes",
    "run_chromium",
    "screenshot_html",
]

CHROMIUM_ENV = "TURNTABLE_PIN_CHROMIUM"
"""Environment variable naming the Chromium executable to use (overrides the search)."""

CHROMIUM_NAMES: tuple[str, ...] = ("chromium", "chromium-browser", "google-chrome", "chrome")
"""Executable names searched on ``PATH``, in order."""
DEBIAN_PACKAGE = "chromium"
"""The Debian package that provides Chromium (named in the not-found message)."""

# Software WebGL: `--use-gl=swiftshader` renders a blank page with Debian chromium 156, ANGLE's
# SwiftShader backend works. `--no-sandbox` is needed as root (CI containers); we only ever load
# local pages that we wrote or were asked to check.
_BASE_FLAGS: tuple[str, ...] = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--hide-scrollbars",
    "--no-first-run",
    "--no-default-browser-check",
    "--disable-extensions",
    "--disable-background-networking",
    "--disable-sync",
    "--mute-audio",
)
_CHECK_ELEMENT_ID = "__turntable_pin_image_check__"


class BrowserNotFoundError(TurntablePinError):
    """No headless Chromium on this machine."""


class BrowserError(TurntablePinError):
    """Chromium ran but did not produce what was asked (crash, timeout, no output)."""


def find_chromium() -> str:
    """Path of the Chromium executable: ``$TURNTABLE_PIN_CHROMIUM`` or the first on ``PATH``.

    Raises:
        BrowserNotFoundError: naming the Debian package to install.
    """
    override = os.environ.get(CHROMIUM_ENV)
    if override:
        found = shutil.which(override)
        if found is None:
            raise BrowserNotFoundError(
                f"${CHROMIUM_ENV} is '{override}', which is not an executable program"
            )
        return found
    for name in CHROMIUM_NAMES:
        found = shutil.which(name)
        if found:
            return found
    raise BrowserNotFoundError(
        "headless Chromium is needed but was not found on PATH; install the Debian package "
        f"'{DEBIAN_PACKAGE}' (apt-get install -y {DEBIAN_PACKAGE}) or set ${CHROMIUM_ENV}"
    )


def chromium_available() -> bool:
    """Whether :func:`find_chromium` finds a browser."""
    try:
        find_chromium()
    except BrowserNotFoundError:
        return False
    return True


@dataclass(frozen=True)
class BrowserRun:
    """One finished Chromium run: its leader's pid (already gone), output and wall time (s)."""

    pid: int
    returncode: int
    stdout: str
    stderr: str
    seconds: float
    command: tuple[str, ...] = field(repr=False)


@dataclass(frozen=True)
class ProcessInfo:
    """One process of :func:`process_table`: ids, whether it is alive, its command line."""

    pid: int
    ppid: int
    pgid: int
    sid: int
    alive: bool  # not a zombie
    cmdline: str


def process_table() -> list[ProcessInfo]:
    """Every process of the machine, read from /proc (empty where /proc does not exist)."""
    table = []
    proc = Path("/proc")
    if not proc.is_dir():
        return table
    for entry in proc.iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
            cmdline = (
                (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode("utf-8", "replace")
            )
        except OSError:
            continue
        # Fields after the parenthesised command name: state ppid pgrp session ...
        fields = stat[stat.rfind(")") + 2 :].split()
        table.append(
            ProcessInfo(
                pid=int(entry.name),
                ppid=int(fields[1]),
                pgid=int(fields[2]),
                sid=int(fields[3]),
                alive=fields[0] not in ("Z", "X"),
                cmdline=cmdline,
            )
        )
    return table


def _grown(table: list[ProcessInfo], members: set[int]) -> set[int]:
    """``members`` plus every process of ``table`` descending from one of them or in a session or
    process group that one of them leads."""
    members = set(members)
    grew = True
    while grew:
        before = len(members)
        for p in table:
            if p.ppid in members or p.sid in members or p.pgid in members:
                members.add(p.pid)
        grew = len(members) > before
    return members


def related_processes(marker: str) -> list[int]:
    """Live processes of one browser run: those naming its folder (``marker``) on their command
    line, and their descendants, sessions and groups (Chromium calls ``setsid``). Starting from the
    marker, not a pid, never mistakes a reused pid for ours."""
    table = [p for p in process_table() if p.alive]
    members = _grown(table, {p.pid for p in table if marker in p.cmdline})
    alive = {p.pid for p in table}
    return sorted(members & alive)


def descendant_processes(pid: int | None = None) -> list[int]:
    """Live processes started by ``pid`` (default: this process), directly or not, and those in a
    session or process group one of them leads (children that called ``setsid``); not ``pid``."""
    pid = os.getpid() if pid is None else pid
    table = [p for p in process_table() if p.alive]
    members = _grown(table, {pid}) - {pid}
    alive = {p.pid for p in table}
    return sorted(members & alive)


def _kill_until_gone(find, timeout_s: float) -> None:
    """SIGKILL every pid ``find()`` returns until it returns none (or ``timeout_s`` passed)."""
    deadline = time.monotonic() + timeout_s
    while True:
        pids = find()
        if not pids or time.monotonic() > deadline:
            return
        for pid in pids:
            try:
                os.kill(pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass
        time.sleep(0.02)


def kill_related_processes(marker: str, timeout_s: float = 5.0) -> None:
    """SIGKILL every process of :func:`related_processes` and wait until none is alive."""
    _kill_until_gone(lambda: related_processes(marker), timeout_s)


def kill_descendant_processes(pid: int | None = None, timeout_s: float = 5.0) -> None:
    """SIGKILL every process of :func:`descendant_processes` and wait until none is alive.

    The last resort of an interrupted command line: no helper it started may outlive it.
    """
    _kill_until_gone(lambda: descendant_processes(pid), timeout_s)


def run_chromium(
    arguments: list[str],
    *,
    width: int = 800,
    height: int = 600,
    timeout_s: float = 60.0,
    chromium: str | None = None,
) -> BrowserRun:
    """Run headless Chromium with ``arguments`` in a throw-away profile; always clean up.

    Raises:
        BrowserNotFoundError: no Chromium.
        BrowserError: the run did not end within ``timeout_s`` seconds.
    """
    executable = chromium or find_chromium()
    with temporary_folder("turntable-pin-chromium-") as tmp_path:
        env = dict(os.environ)
        env["XDG_CONFIG_HOME"] = str(tmp_path / "config")
        env["XDG_CACHE_HOME"] = str(tmp_path / "cache")
        env["TMPDIR"] = str(tmp_path)  # Chromium's own scratch folders go with the run's folder
        command = (
            executable,
            *_BASE_FLAGS,
            f"--user-data-dir={tmp_path / 'profile'}",
            f"--window-size={int(width)},{int(height)}",
            *arguments,
        )
        started: list[subprocess.Popen] = []

        def stop() -> None:
            """Kill every process of the run (found by its folder) and reap the launcher."""
            with deferred():
                kill_related_processes(str(tmp_path))
                for proc in started:
                    if proc.poll() is None:
                        proc.kill()
                    proc.wait()

        # Registered before the launch: an interruption at any moment still finds the browser.
        unregister = register_cleanup(stop)
        try:
            start = time.perf_counter()
            with deferred():
                started.append(
                    subprocess.Popen(
                        command,
                        stdin=subprocess.DEVNULL,
                        stdout=subprocess.PIPE,
                        stderr=subprocess.PIPE,
                        env=env,
                        start_new_session=True,
                    )
                )
            proc = started[0]
            # Chromium runs in a session of its own: Ctrl-C never reaches it, so an interrupted
            # communicate() need not wait the 0.25 s it grants a child to end on that signal.
            proc._sigint_wait_secs = 0.0
            try:
                stdout, stderr = proc.communicate(timeout=timeout_s)
            except subprocess.TimeoutExpired:
                raise BrowserError(
                    f"headless Chromium did not finish within {timeout_s:g} s and was stopped"
                ) from None
        finally:
            stop()
            unregister()
        seconds = time.perf_counter() - start
    return BrowserRun(
        pid=proc.pid,
        returncode=proc.returncode,
        stdout=stdout.decode("utf-8", "replace"),
        stderr=stderr.decode("utf-8", "replace"),
        seconds=seconds,
        command=command,
    )


def _last_error_line(run: BrowserRun) -> str:
    lines = [line for line in run.stderr.splitlines() if line.strip()]
    errors = [line for line in lines if "ERROR" in line or "error" in line]
    return (errors or lines or ["no message"])[-1].strip()


def png_size(data: bytes) -> tuple[int, int]:
    """(width, height) of PNG bytes, read from the IHDR chunk."""
    if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
        raise BrowserError("the browser's output is not a PNG image")
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


CRASH_ATTEMPTS = 3
"""How many times :func:`screenshot_html` starts Chromium when it dies by a signal of its own
before writing the picture (SIGABRT in its zygote under load), each in a fresh profile."""


def screenshot_html(
    page: str | Path,
    *,
    width: int = 800,
    height: int = 600,
    virtual_time_ms: int = 5000,
    timeout_s: float = 60.0,
    chromium: str | None = None,
) -> tuple[bytes, BrowserRun]:
    """Render a local HTML file to PNG bytes of ``width`` x ``height`` pixels.

    ``virtual_time_ms`` is the page's own time budget (scripts, data-URL fetches, animation
    frames) before the picture is taken; virtual time makes the picture reproducible.
    """
    page = Path(page).resolve()
    if not page.is_file():
        raise BrowserError(f"{page}: no such page to render")
    with temporary_folder("turntable-pin-shot-") as tmp:
        out = tmp / "shot.png"
        for _ in range(CRASH_ATTEMPTS):
            run = run_chromium(
                [
                    f"--virtual-time-budget={int(virtual_time_ms)}",
                    f"--screenshot={out}",
                    page.as_uri(),
                ],
                width=width,
                height=height,
                timeout_s=timeout_s,
                chromium=chromium,
            )
            # Killed by a signal of its own (it runs in its own session: an interruption of
            # ours never reaches it): a start-up abort seen on busy machines; a fresh profile
            # usually starts.
            if run.returncode >= 0 or (out.is_file() and out.stat().st_size > 0):
                break
        if not out.is_file() or out.stat().st_size == 0:
            raise BrowserError(
                f"headless Chromium wrote no screenshot (exit {run.returncode}): "
                f"{_last_error_line(run)}"
            )
        data = out.read_bytes()
    size = png_size(data)
    if size != (width, height):
        raise BrowserError(f"screenshot is {size[0]}x{size[1]} pixels, asked for {width}x{height}")
    return data, run


@dataclass(frozen=True)
class ImageStatus:
    """One ``<img>`` of a page as the browser saw it after loading (sizes in pixels)."""

    src: str
    complete: bool
    natural_width: int
    natural_height: int

    @property
    def loaded(self) -> bool:
        """Whether the image finished loading with a non-empty size."""
        return self.complete and self.natural_width > 0 and self.natural_height > 0


@dataclass(frozen=True)
class ImageLoadReport:
    """Which images of a page loaded in headless Chromium."""

    page: Path
    images: tuple[ImageStatus, ...]
    seconds: float

    @property
    def n_images(self) -> int:
        """Number of ``<img>`` elements on the page."""
        return len(self.images)

    @property
    def failed(self) -> tuple[str, ...]:
        """``src`` of every image that did not load."""
        return tuple(image.src for image in self.images if not image.loaded)

    @property
    def all_loaded(self) -> bool:
        """Whether every image loaded."""
        return not self.failed

    def to_dict(self) -> dict:
        """Page, image counts, failed sources and time (s) as a JSON-ready dict."""
        return {
            "page": str(self.page),
            "n_images": self.n_images,
            "n_loaded": self.n_images - len(self.failed),
            "failed": list(self.failed),
            "seconds": self.seconds,
        }


_CHECK_SCRIPT = (
    """
<script>
window.addEventListener("load", function () {
  var images = Array.prototype.slice.call(document.images).map(function (im) {
    var src = im.getAttribute("src") || "";
    return {src: src.length > 120 ? src.slice(0, 120) + "..." : src,
            complete: im.complete, w: im.naturalWidth, h: im.naturalHeight};
  });
  var out = document.createElement("pre");
  out.id = "ID";
  out.textContent = JSON.stringify(images);
  document.body.appendChild(out);
});
</script>
"""
).replace("ID", _CHECK_ELEMENT_ID)


def _instrumented_page(source: str, base_url: str) -> str:
    """``source`` with a ``<base>`` (relative URLs still resolve) and the image-check script."""
    base = "" if re.search(r"<base\s", source, re.I) else f'<base href="{html.escape(base_url)}">'
    head = re.search(r"<head[^>]*>", source, re.I)
    if head:
        source = source[: head.end()] + base + source[head.end() :]
    else:
        source = base + source
    closing = source.lower().rfind("</body>")
    if closing < 0:
        return source + _CHECK_SCRIPT
    return source[:closing] + _CHECK_SCRIPT + source[closing:]


def check_page_images(
    page: str | Path,
    *,
    width: int = 1280,
    height: int = 2000,
    virtual_time_ms: int = 10000,
    timeout_s: float = 60.0,
    chromium: str | None = None,
) -> ImageLoadReport:
    """Load a local HTML page in headless Chromium and report whether every ``<img>`` loaded: a
    copy (with a ``<base>`` at the page's folder) records each image's state at ``load`` into the
    DOM, which Chromium dumps. :class:`BrowserError` when the page is missing or never loads."""
    page = Path(page).resolve()
    try:
        source = page.read_text(encoding="utf-8")
    except OSError as exc:
        raise BrowserError(f"{page}: cannot read the page: {exc.strerror or exc}") from None
    base_url = page.parent.as_uri() + "/"
    with temporary_folder("turntable-pin-check-") as tmp:
        copy = tmp / page.name
        copy.write_text(_instrumented_page(source, base_url), encoding="utf-8")
        run = run_chromium(
            [
                "--allow-file-access-from-files",
                f"--virtual-time-budget={int(virtual_time_ms)}",
                "--dump-dom",
                copy.as_uri(),
            ],
            width=width,
            height=height,
            timeout_s=timeout_s,
            chromium=chromium,
        )
    match = re.search(rf'<pre id="{_CHECK_ELEMENT_ID}">(.*?)</pre>', run.stdout, re.S)
    if match is None:
        raise BrowserError(
            f"{page}: the page did not finish loading in headless Chromium "
            f"(exit {run.returncode}): {_last_error_line(run)}"
        )
    entries = json.loads(html.unescape(match.group(1)))
    images = tuple(
        ImageStatus(
            src=str(e["src"]),
            complete=bool(e["complete"]),
            natural_width=int(e["w"]),
            natural_height=int(e["h"]),
        )
        for e in entries
    )
    return ImageLoadReport(page=page, images=images, seconds=run.seconds)
