"""Tests of the headless-Chromium helpers: image check, screenshot, cleanup, missing browser."""

from __future__ import annotations

import base64

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pytest

from conftest import needs_chromium
from process_watch import ProcessWatch
from turntable_pin.viewer.browser import (
    CHROMIUM_ENV,
    BrowserError,
    BrowserNotFoundError,
    check_page_images,
    chromium_available,
    find_chromium,
    png_size,
    run_chromium,
    screenshot_html,
)


def _png(path, size_in=(2.0, 1.5), dpi=50):
    fig = plt.figure(figsize=size_in)
    fig.gca().plot([0, 1], [1, 0])
    fig.savefig(path, dpi=dpi)
    plt.close(fig)
    return path


def test_png_size_reads_the_header(tmp_path):
    data = _png(tmp_path / "a.png").read_bytes()
    assert png_size(data) == (100, 75)
    with pytest.raises(BrowserError, match="not a PNG"):
        png_size(b"GIF89a" + bytes(30))


def test_missing_browser_names_the_debian_package(monkeypatch, tmp_path):
    monkeypatch.delenv(CHROMIUM_ENV, raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    assert not chromium_available()
    with pytest.raises(BrowserNotFoundError, match="Debian package 'chromium'"):
        find_chromium()


def test_browser_override_must_be_a_program(monkeypatch):
    monkeypatch.setenv(CHROMIUM_ENV, "/nonexistent/chromium")
    with pytest.raises(BrowserNotFoundError, match=CHROMIUM_ENV):
        find_chromium()


@needs_chromium
def test_image_check_tells_loaded_from_broken_images(tmp_path):
    (tmp_path / "img").mkdir()
    _png(tmp_path / "img" / "plot.png")
    inline = base64.b64encode(_png(tmp_path / "inline.png").read_bytes()).decode()
    page = tmp_path / "page.html"
    source = (
        "<!DOCTYPE html><html><head><title>t</title></head><body>"
        '<img src="img/plot.png"><img src="img/missing.png">'
        f'<img src="data:image/png;base64,{inline}"><img src="img/">'
        "</body></html>"
    )
    page.write_text(source)
    report = check_page_images(page)
    assert report.n_images == 4
    assert set(report.failed) == {"img/missing.png", "img/"}
    assert not report.all_loaded
    loaded = [im for im in report.images if im.loaded]
    assert {(im.natural_width, im.natural_height) for im in loaded} == {(100, 75)}
    assert page.read_text() == source  # the checked page is only read
    assert report.to_dict()["n_loaded"] == 2


@needs_chromium
def test_image_check_of_a_page_without_head_or_images(tmp_path):
    page = tmp_path / "bare.html"
    page.write_text("<p>no images here</p>")
    report = check_page_images(page)
    assert report.n_images == 0 and report.all_loaded


@pytest.mark.slow
@needs_chromium
def test_screenshot_has_the_asked_size_and_is_reproducible(tmp_path):
    page = tmp_path / "red.html"
    page.write_text('<body style="margin:0;background:#ff0000"><div>x</div></body>')
    first, run = screenshot_html(page, width=320, height=200)
    second, _ = screenshot_html(page, width=320, height=200)
    assert png_size(first) == (320, 200)
    assert first == second
    assert run.seconds > 0


@pytest.mark.slow
@needs_chromium
def test_no_browser_process_survives_a_timeout(tmp_path):
    page = tmp_path / "slow.html"
    page.write_text("<script>while (true) {}</script>")
    with ProcessWatch() as watch, pytest.raises(BrowserError, match="did not finish"):
        run_chromium(["--virtual-time-budget=60000", "--dump-dom", page.as_uri()], timeout_s=2.0)
    assert watch.browser_pids, "the watcher saw no browser process (the check would be empty)"
    assert watch.survivors() == []


@needs_chromium
def test_no_browser_process_survives_a_normal_run(tmp_path):
    page = tmp_path / "p.html"
    page.write_text("<p>hello</p>")
    with ProcessWatch() as watch:
        run = run_chromium(["--dump-dom", page.as_uri()])
    assert "hello" in run.stdout
    assert len(watch.browser_pids) >= 2
    assert watch.survivors() == []


CRASHING_BROWSER = """#!/usr/bin/env python3
import os, signal, sys, pathlib
count = pathlib.Path({count!r})
n = int(count.read_text()) if count.exists() else 0
count.write_text(str(n + 1))
if n < {crashes}:
    os.kill(os.getpid(), signal.SIGABRT)  # a start-up abort, as Chromium's zygote does under load
shot = next(a.split("=", 1)[1] for a in sys.argv if a.startswith("--screenshot="))
pathlib.Path(shot).write_bytes(pathlib.Path({png!r}).read_bytes())
"""


@pytest.mark.parametrize("crashes, ok", [(2, True), (3, False)])
def test_a_browser_that_aborts_at_start_is_started_again(tmp_path, crashes, ok):
    """Chromium killed by a signal of its own before the picture: started again in a fresh
    profile, up to CRASH_ATTEMPTS times in all; then the error names the exit."""
    from turntable_pin.viewer.browser import CRASH_ATTEMPTS

    png = _png(tmp_path / "ok.png", size_in=(8.0, 6.0), dpi=100)
    fake = tmp_path / "chromium"
    fake.write_text(CRASHING_BROWSER.format(count=str(tmp_path / "n"), crashes=crashes,
                                            png=str(png)))  # fmt: skip
    fake.chmod(0o755)
    page = tmp_path / "page.html"
    page.write_text("<html></html>")
    assert crashes < CRASH_ATTEMPTS or not ok
    if ok:
        data, run = screenshot_html(page, chromium=str(fake))
        assert png_size(data) == (800, 600) and run.returncode == 0
    else:
        with pytest.raises(BrowserError, match=r"wrote no screenshot \(exit -6\)"):
            screenshot_html(page, chromium=str(fake))
    assert int((tmp_path / "n").read_text()) == min(crashes + 1, CRASH_ATTEMPTS)
