"""The ``view`` and ``snapshot`` commands: serving, clean shutdown by pid, and clear errors.

``view`` serving runs in a child process (signals, and no server may outlive it); the error paths
and the snapshot run in-process."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import pytest

from conftest import cli, cli_env, needs_chromium
from process_watch import ProcessWatch, alive

pytest.importorskip("meshcat")


def _start_view(*args: str) -> tuple[subprocess.Popen, list[str]]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "turntable_pin", "view", *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=cli_env(),
    )
    lines = []
    while not lines or not lines[-1].startswith("serving"):
        line = proc.stdout.readline()
        if not line:
            raise AssertionError(f"view ended early: {proc.stderr.read()}")
        lines.append(line.strip())
    return proc, lines


@pytest.mark.slow
@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM])
def test_view_serves_until_interrupted_then_stops_its_server(stop):
    proc, lines = _start_view("--error", "deps_x=4", "--error", "deta=0.2")
    with ProcessWatch(parent_pid=proc.pid) as watch:
        time.sleep(0.3)
    try:
        assert lines[0].startswith("meshcat viewer: http://127.0.0.1:")
        assert any("magnified x2700" in line for line in lines)
        (server_pid,) = watch.server_pids
        assert alive(server_pid)
        os.kill(proc.pid, stop)
        proc.wait(timeout=30)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 128 + stop  # 130 on Ctrl-C, 143 on SIGTERM
    assert (
        proc.stderr.read()
        .strip()
        .splitlines()[-1]
        .endswith(f"interrupted ({signal.Signals(stop).name})")
    )
    assert not alive(server_pid)


@pytest.mark.slow
def test_view_animates_a_positions_file_for_a_while(tmp_path):
    positions = tmp_path / "positions.csv"
    positions.write_text("phi1_deg,phi2_deg\n0,0\n90,0\n90,180\n")
    proc = subprocess.Popen(
        [sys.executable, "-m", "turntable_pin", "view", "--animate", "--positions",
         str(positions), "--frames-per-move", "3", "--frame-seconds", "0.01", "--duration", "1"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=cli_env(),
    )  # fmt: skip
    with ProcessWatch(parent_pid=proc.pid) as watch:
        out, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert "serving for 1 s" in out
    assert len(watch.server_pids) == 1 and watch.survivors() == []


def test_view_of_the_paper_table_takes_joint_named_positions(tmp_path):
    positions = tmp_path / "positions.csv"
    positions.write_text("outer_axis_deg,inner_axis_deg\n0,0\n90,0\n")
    proc = cli("view", "--animate", "--positions", str(positions), "--angles-deg", "10,20",
               "--error", "deps_x=4", "--duration", "0")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "magenta rod: actual inner_axis" in proc.stdout


def test_view_names_the_bad_cell_of_a_positions_file(tmp_path):
    positions = tmp_path / "positions.csv"
    positions.write_text("phi1_deg,phi2_deg\n0,0\n90,abc\n")
    proc = cli("view", "--animate", "--positions", str(positions), "--duration", "0")
    assert proc.returncode == 2
    assert str(positions) in proc.stderr and "row 3" in proc.stderr and "phi2_deg" in proc.stderr
    assert "Traceback" not in proc.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["--exaggerate", "0"], "angle_factor"),
        (["--exaggerate-deta", "-1"], "length_factor"),
        (["--error", "nonsense=1"], "unknown error name"),
    ],
)
def test_snapshot_bad_options_exit_2(tmp_path, args, message):
    proc = cli("snapshot", "-o", str(tmp_path / "x.png"), *args)
    assert proc.returncode == 2
    assert message in proc.stderr and "Traceback" not in proc.stderr
    assert not (tmp_path / "x.png").exists()


def test_snapshot_without_chromium_names_the_package(tmp_path, monkeypatch):
    monkeypatch.setenv("PATH", os.path.dirname(sys.executable))  # python only, no browser
    monkeypatch.delenv("TURNTABLE_PIN_CHROMIUM", raising=False)
    proc = cli("snapshot", "-o", str(tmp_path / "x.png"))
    assert proc.returncode == 2
    assert "Debian package 'chromium'" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


@pytest.mark.slow
@needs_chromium
def test_snapshot_command_writes_the_png_and_reports_json(tmp_path):
    out = tmp_path / "setup.png"
    proc = cli(
        "snapshot", "--error", "dalpha_x2=2", "--phi1-deg", "60", "--phi2-deg", "10",
        "--width", "320", "--height", "240", "--exaggerate", "5000", "-o", str(out), "--json",
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    report = json.loads(proc.stdout)
    assert report["width_px"] == 320 and report["height_px"] == 240
    assert report["exaggeration"] == {"angle_factor": 5000.0, "length_factor": 5000.0}
    assert report["angles_deg"] == {"phi1": 60.0, "phi2": 10.0}
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
