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
from .common import (
    add_error_options,
    errors_from_args,
    finite_float,
    generic_errors_from_args,
    generic_table_from_args,
    input_path,
    paper_table_requested,
    positive_int,
    print_json,
)

__all__ = ["register"]


def _add_scene_options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--phi1-deg", type=finite_float, default=None, help="outer-axis angle, degrees (30)"
    )
    p.add_argument(
        "--phi2-deg", type=finite_float, default=None, help="inner-axis angle, degrees (45)"
    )
    p.add_argument(
        "--angles-deg",
        metavar="A,B,C",
        help="the joint angles in chain order from the base, degrees (any table; default 30, 45, "
        "60 for the first, second, third joint; a two-axis table also takes --phi1/2-deg)",
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
    s.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.png")
    s.add_argument("--width", type=positive_int, default=800, help="pixels (64 to 4096)")
    s.add_argument("--height", type=positive_int, default=600, help="pixels (64 to 4096)")
    s.add_argument("--no-legend", action="store_true", help="leave the legend out of the picture")
    s.add_argument("--json", action="store_true", help="print one JSON object")
    s.set_defaults(func=run_snapshot)


_DEFAULT_ANGLES_DEG = (30.0, 45.0, 60.0)


def _table(args: argparse.Namespace):
    """The :class:`GenericTable` of ``--urdf``, or None for the paper's table."""
    if paper_table_requested(args):
        return None
    return generic_table_from_args(args)


def _angles_deg(args: argparse.Namespace, table) -> list[float]:
    """The joint angles of the options (chain order, degrees)."""
    from .orientation import _joint_angles_deg

    n = len(table.joint_names)
    if args.angles_deg is None and args.phi1_deg is None and args.phi2_deg is None:
        return list(_DEFAULT_ANGLES_DEG[:n])
    return _joint_angles_deg(args, n)


def table_scene_from_args(args: argparse.Namespace, table):
    """The :class:`~turntable_pin.viewer.table_scene.TableScene` of the options for ``table``."""
    from ..viewer.table_scene import TableScene, table_exaggeration

    values = generic_errors_from_args(table, args)
    exaggeration = table_exaggeration(table, values, args.exaggerate, args.exaggerate_deta)
    scene = TableScene(table, values, exaggeration=exaggeration)
    for line in scene.warnings:
        print(f"turntable-pin {args.command}: warning: {line}", file=sys.stderr)
    return scene


def _table_schedule_rad(args: argparse.Namespace, table) -> np.ndarray:
    """Animation frames (F, J) of any table: through ``--positions`` or a 90-degree grid."""
    from ..calibration.table_positions import JointPositions

    if args.positions is not None:
        positions = np.degrees(JointPositions.from_csv(table, args.positions).angles_rad)
    else:
        positions = np.degrees(JointPositions.grid(table, 90.0).angles_rad)
    return animation_frames_rad(positions, args.frames_per_move)


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

    table = _table(args)
    if table is None:
        scene = scene_from_args(args)
        angles_rad = [deg_to_rad(v) for v in _paper_angles_deg(args)]
        frames = _schedule_rad(args) if args.animate else None
    else:
        scene = table_scene_from_args(args, table)
        angles_rad = [deg_to_rad(v) for v in _angles_deg(args, table)]
        frames = _table_schedule_rad(args, table) if args.animate else None
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


def _paper_angles_deg(args: argparse.Namespace) -> tuple[float, float]:
    """(phi1, phi2) of the paper's table, degrees (default 30, 45; or ``--angles-deg``)."""
    if args.angles_deg is not None:
        from .orientation import _joint_angles_deg

        phi1, phi2 = _joint_angles_deg(args, 2)
        return phi1, phi2
    phi1 = _DEFAULT_ANGLES_DEG[0] if args.phi1_deg is None else args.phi1_deg
    phi2 = _DEFAULT_ANGLES_DEG[1] if args.phi2_deg is None else args.phi2_deg
    return phi1, phi2


def _print_snapshot(args: argparse.Namespace, scene, result, where: str, lengths: str) -> int:
    """Say what ``snapshot`` wrote: one JSON object (``--json``) or one line; ``where`` is the
    position's text ("" or ending "; "), ``lengths`` the name of the magnified lengths."""
    if args.json:
        print_json({**result.to_dict(), **scene.to_dict()})
    else:
        k = scene.exaggeration
        print(
            f"wrote {result.path} ({result.width}x{result.height} px; {where}errors magnified "
            f"x{k.angle_factor:.4g}, {lengths} x{k.length_factor:.4g}; "
            f"{result.scene_seconds + result.browser_seconds:.1f} s)"
        )
    return 0


def _run_table_snapshot(args: argparse.Namespace, table) -> int:
    """``snapshot`` of a table given by ``--urdf`` (or ``--angles-deg``)."""
    from ..viewer.snapshot import render_table_snapshot

    angles_deg = _angles_deg(args, table)
    scene = table_scene_from_args(args, table)
    result = render_table_snapshot(
        scene,
        [deg_to_rad(a) for a in angles_deg],
        args.output,
        width=args.width,
        height=args.height,
        legend=not args.no_legend,
    )
    where = ", ".join(f"{j} = {a:g} deg" for j, a in result.angles_deg.items())
    return _print_snapshot(args, scene, result, f"{where}; ", "offsets")


def run_snapshot(args: argparse.Namespace) -> int:
    from ..viewer.snapshot import render_snapshot

    table = _table(args)
    if table is not None:
        return _run_table_snapshot(args, table)
    phi1_deg, phi2_deg = _paper_angles_deg(args)
    scene = scene_from_args(args)
    result = render_snapshot(
        scene,
        deg_to_rad(phi1_deg),
        deg_to_rad(phi2_deg),
        args.output,
        width=args.width,
        height=args.height,
        legend=not args.no_legend,
    )
    return _print_snapshot(args, scene, result, "", "deta")
