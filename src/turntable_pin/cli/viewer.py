"""``turntable-pin view`` and ``turntable-pin snapshot``: the setup in 3-D, live or as a PNG."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from ..core.csv_table import read_csv_table
from ..core.exceptions import InputError
from ..core.units import deg_to_rad
from ..viewer.scene import Exaggeration, SetupScene, animation_frames_rad, default_positions_deg
from .common import add_error_options, errors_from_args, finite_float, positive_int, print_json

__all__ = ["register"]


def _add_scene_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--phi1-deg", type=finite_float, default=30.0, help="outer-axis angle, degrees")
    p.add_argument("--phi2-deg", type=finite_float, default=45.0, help="inner-axis angle, degrees")
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
        help="magnify the intersection error K times (default: the angular factor, but at "
        "most what shows deta as 30 mm)",
    )


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``view`` and ``snapshot`` subcommands to ``subparsers``."""
    v = subparsers.add_parser(
        "view",
        description="Serve a meshcat 3-D view of the turntable URDF with its errors magnified, "
        "the ideal and the actual payload frames as triads and the ideal and actual inner axis. "
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
        type=Path,
        metavar="FILE.csv",
        help="schedule for --animate: a CSV with columns phi1_deg, phi2_deg",
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
    s.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.png")
    s.add_argument("--width", type=positive_int, default=800, help="pixels (64 to 4096)")
    s.add_argument("--height", type=positive_int, default=600, help="pixels (64 to 4096)")
    s.add_argument("--no-legend", action="store_true", help="leave the legend out of the picture")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=run_snapshot)


def scene_from_args(args: argparse.Namespace) -> SetupScene:
    """The :class:`SetupScene` of the error and magnification options."""
    errors = errors_from_args(args)
    exaggeration = Exaggeration.for_errors(errors, args.exaggerate, args.exaggerate_deta)
    return SetupScene(errors, urdf_path=args.urdf, exaggeration=exaggeration)


def _schedule_rad(args: argparse.Namespace) -> np.ndarray:
    if args.positions is not None:
        table = read_csv_table(args.positions, required=("phi1_deg", "phi2_deg"))
        positions = np.column_stack([table["phi1_deg"], table["phi2_deg"]])
    else:
        positions = default_positions_deg()
    return animation_frames_rad(positions, args.frames_per_move)


def run_view(args: argparse.Namespace) -> int:
    from ..viewer.meshcat_server import MeshcatServer

    scene = scene_from_args(args)
    phi1_rad, phi2_rad = deg_to_rad(args.phi1_deg), deg_to_rad(args.phi2_deg)
    frames = _schedule_rad(args) if args.animate else None
    if args.frame_seconds <= 0:
        raise InputError(f"--frame-seconds must be > 0, got {args.frame_seconds:g}")
    if args.duration is not None and args.duration < 0:
        raise InputError(f"--duration must be >= 0, got {args.duration:g}")
    # Ctrl-C and a plain `kill` raise out of the loop (cli.main turns them into 130 / 143); the
    # `with` block stops the server on the way out.
    with MeshcatServer() as server:
        scene.draw(server.visualizer)
        scene.set_position(phi1_rad, phi2_rad)
        print(f"meshcat viewer: {server.url}")
        for line in scene.legend(phi1_rad, phi2_rad)[1:]:
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

    scene = scene_from_args(args)
    result = render_snapshot(
        scene,
        deg_to_rad(args.phi1_deg),
        deg_to_rad(args.phi2_deg),
        args.output,
        width=args.width,
        height=args.height,
        legend=not args.no_legend,
    )
    if args.json:
        print_json({**result.to_dict(), **scene.to_dict()})
    else:
        k = scene.exaggeration
        print(
            f"wrote {result.path} ({result.width}x{result.height} px; errors magnified "
            f"x{k.angle_factor:.4g}, deta x{k.length_factor:.4g}; "
            f"{result.scene_seconds + result.browser_seconds:.1f} s)"
        )
    return 0
