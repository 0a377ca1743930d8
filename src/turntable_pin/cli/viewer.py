"""``turntable-pin view`` and ``turntable-pin snapshot``: a table in 3-D, live or as a PNG."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
import sys
import time
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.units import deg_to_rad
from ..viewer.scene import Exaggeration, SetupScene, animation_frames_rad, default_positions_deg
from .common import (
    add_error_options,
    error_values_from_args,
    finite_float,
    input_path,
    positive_int,
    print_json,
    table_from_args,
)
from .orientation import joint_angles_deg, position_fields, position_text

__all__ = ["register"]


def _add_scene_options(p: argparse.ArgumentParser) -> None:
    first, second, third = (f"{a:g}" for a in _DEFAULT_ANGLES_DEG)
    p.add_argument("--phi1-deg", type=finite_float, default=None,
                   help=f"outer-axis angle, degrees (default: {first})")  # fmt: skip
    p.add_argument("--phi2-deg", type=finite_float, default=None,
                   help=f"inner-axis angle, degrees (default: {second})")  # fmt: skip
    p.add_argument(
        "--angles-deg",
        metavar="A,B,C",
        help="the joint angles in chain order from the base, degrees (any table; default "
        f"{first}, {second}, {third} for the first, second, third joint; a two-axis table also "
        "takes --phi1/2-deg)",
    )
    add_error_options(p)
    p.add_argument(
        "--exaggerate",
        type=finite_float,
        metavar="K",
        help="magnify the angular errors K times (default: the largest becomes 3 deg)",
    )
    p.add_argument(
        "--exaggerate-deta",
        type=finite_float,
        metavar="K",
        help="magnify the intersection error (any table: the offsets) K times (default: the "
        "angular factor, but at most what shows deta as 30 mm)",
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``view`` and ``snapshot`` subcommands to ``subparsers``."""
    v = subparsers.add_parser(
        "view",
        description="Serve a meshcat 3-D view of the turntable URDF with its errors magnified, "
        "the ideal and the actual payload frames as triads and the ideal and actual axis of the "
        "last joint (the paper's inner axis). "
        "Prints the URL and serves until Ctrl-C (or --duration). Needs the extra 'viz' (meshcat).",
    )
    _add_scene_options(v)
    v.add_argument(
        "--animate",
        action="store_true",
        help="step through a position schedule (default: a 16-position 90-degree tumble)",
    )
    v.add_argument(
        "--positions",
        type=input_path,
        metavar="FILE.csv",
        help="schedule for --animate: a CSV with columns phi1_deg, phi2_deg (any table: "
        "phi1_deg .. phiN_deg or <joint>_deg; default every joint through 0, 90, 180, 270 deg)",
    )
    v.add_argument(
        "--frames-per-move", type=positive_int, default=12, help="animation frames per move"
    )
    v.add_argument(
        "--frame-seconds", type=finite_float, default=0.08, help="seconds per animation frame"
    )
    v.add_argument(
        "--duration",
        type=finite_float,
        metavar="S",
        help="stop serving after S seconds (default: until Ctrl-C)",
    )
    v.set_defaults(func=run_view)

    s = subparsers.add_parser(
        "snapshot",
        description="Render the same scene as 'view' to a PNG with headless Chromium (Debian "
        "package 'chromium'); no server or browser is left running afterwards.",
    )
    _add_scene_options(s)
    s.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.png",
                   help="the PNG to write")  # fmt: skip
    s.add_argument("--width", type=positive_int, default=800, help="pixels (64 to 4096)")
    s.add_argument("--height", type=positive_int, default=600, help="pixels (64 to 4096)")
    s.add_argument("--no-legend", action="store_true", help="leave the legend out of the picture")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=run_snapshot)


_DEFAULT_ANGLES_DEG = (30.0, 45.0, 60.0)


def scene_from_args(args: argparse.Namespace) -> tuple[SetupScene, list[float]]:
    """The :class:`SetupScene` of the table, error and magnification options (warnings on
    stderr), and the joint angles of the options (chain order, degrees)."""
    table = table_from_args(args)
    angles_deg = joint_angles_deg(args, len(table.joint_names), _DEFAULT_ANGLES_DEG)
    values = error_values_from_args(table, args)
    exaggeration = Exaggeration.for_errors(
        values, args.exaggerate, args.exaggerate_deta, table=table
    )
    scene = SetupScene(values, table=table, exaggeration=exaggeration)
    for line in scene.warnings:
        print(f"turntable-pin {args.command}: warning: {line}", file=sys.stderr)
    return scene, angles_deg


def _schedule_rad(args: argparse.Namespace, table) -> np.ndarray:
    """Animation frames (F, J): through ``--positions`` or every joint through 0, 90, 180,
    270 deg."""
    if args.positions is not None:
        from ..calibration.positions import PositionSet

        positions = np.degrees(PositionSet.from_csv(args.positions, table).angles_rad)
    else:
        positions = default_positions_deg(len(table.joint_names))
    return animation_frames_rad(positions, args.frames_per_move)


def run_view(args: argparse.Namespace) -> int:
    from ..viewer.meshcat_server import MeshcatServer

    scene, angles_deg = scene_from_args(args)
    angles_rad = [deg_to_rad(v) for v in angles_deg]
    frames = _schedule_rad(args, scene.table) if args.animate else None
    if args.frame_seconds <= 0:
        raise InputError(f"--frame-seconds must be > 0, got {args.frame_seconds:g}")
    if args.duration is not None and args.duration < 0:
        raise InputError(f"--duration must be >= 0, got {args.duration:g}")
    # Ctrl-C and a plain `kill` raise out of the loop (cli.main turns them into 130 / 143); the
    # `with` block stops the server on the way out.
    with MeshcatServer() as server:
        scene.draw(server.visualizer)
        scene.set_position(*angles_rad)
        print(f"meshcat viewer: {server.url}")
        for line in scene.legend(*angles_rad)[1:]:
            print(f"  {line}")
        until = f"for {args.duration:g} s" if args.duration is not None else "until Ctrl-C"
        print(f"serving {until}", flush=True)
        deadline = None if args.duration is None else time.monotonic() + args.duration
        i = 0
        while deadline is None or time.monotonic() < deadline:
            if frames is not None:
                scene.set_position(*frames[i % len(frames)])
                i += 1
                time.sleep(args.frame_seconds)
            else:
                time.sleep(0.1)
    print("meshcat server stopped", file=sys.stderr)
    return 0


def run_snapshot(args: argparse.Namespace) -> int:
    from ..viewer.snapshot import render_snapshot

    scene, angles_deg = scene_from_args(args)
    result = render_snapshot(
        scene,
        [deg_to_rad(a) for a in angles_deg],
        args.output,
        width=args.width,
        height=args.height,
        legend=not args.no_legend,
    )
    position = position_fields(scene.table, angles_deg)
    if args.json:
        print_json({**result.to_dict(position), **scene.to_dict()})
        return 0
    k = scene.exaggeration
    where = position_text(position, payload_frame=args.urdf is not None)
    print(
        f"wrote {result.path} ({result.width}x{result.height} px; {where}; "
        f"errors magnified x{k.angle_factor:.4g}, {scene.length_label} x{k.length_factor:.4g}; "
        f"{result.scene_seconds + result.browser_seconds:.1f} s)"
    )
    return 0
