"""``turntable-pin orientation`` and ``turntable-pin urdf``: the error model of a table (the paper's
or any URDF's, in its own error names) at one position."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..calibration.positions import MAX_COMMANDED_ANGLE_DEG
from ..core.exceptions import InputError
from ..core.units import M_PER_MM, deg_to_rad, rad_to_arcsec
from ..model.angles import ANGLE_NAMES
from .common import (
    add_error_options,
    bounded_float,
    error_values_from_args,
    one_line_errors,
    print_json,
    table_from_args,
)

__all__ = [
    "joint_angles_deg",
    "orientation_report",
    "position_fields",
    "position_text",
    "register",
]


ORIENTATION_ANGLE_DEG = 0.0
"""The angle of every joint ``orientation`` is not given, degrees."""


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``orientation`` and ``urdf`` subcommands to ``subparsers``."""
    p = subparsers.add_parser(
        "orientation",
        description="Orientation error dR = Rd^T Rt of the payload (Pinocchio forward kinematics "
        "of the URDF with the errors in its joint placements), the angles dpsi, dtheta, dgamma "
        "(eq. 24) beside their small-angle values (eq. 26), and the payload origin.",
    )
    one_line_errors(p)
    angle = bounded_float(-MAX_COMMANDED_ANGLE_DEG, MAX_COMMANDED_ANGLE_DEG, "deg", why="ten turns")
    for k, which in ((1, "outer"), (2, "inner")):
        p.add_argument(f"--phi{k}-deg", type=angle, default=None,
                       help=f"{which}-axis angle, degrees (default: "
                       f"{ORIENTATION_ANGLE_DEG:g})")  # fmt: skip
    p.add_argument(
        "--angles-deg",
        metavar="A,B,C",
        help="the joint angles in chain order from the base, degrees (any table; a two-axis "
        f"table also takes --phi1-deg/--phi2-deg; default: {ORIENTATION_ANGLE_DEG:g} for every "
        "joint)",
    )
    add_error_options(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.set_defaults(func=run_orientation)

    u = subparsers.add_parser(
        "urdf",
        description="Write the turntable URDF whose joint <origin>s carry the errors; plain "
        "pinocchio.buildModelFromUrdf(OUT) gives the same dR.",
    )
    one_line_errors(u)
    add_error_options(u)
    u.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.urdf",
                   help="the URDF to write")  # fmt: skip
    u.set_defaults(func=run_urdf)


def joint_angles_deg(
    args: argparse.Namespace, n_joints: int, defaults_deg=(ORIENTATION_ANGLE_DEG,) * 3
) -> list[float]:
    """The joint angles (chain order, degrees) of ``--angles-deg`` or ``--phi1-deg/--phi2-deg``
    (a two-joint table), ``defaults_deg`` where not given."""
    two = (args.phi1_deg, args.phi2_deg)
    if args.angles_deg is not None:
        if any(v is not None for v in two):
            raise InputError("give either --angles-deg or --phi1-deg/--phi2-deg, not both")
        check = bounded_float(
            -MAX_COMMANDED_ANGLE_DEG, MAX_COMMANDED_ANGLE_DEG, "deg", why="ten turns"
        )
        try:
            angles = [check(t) for t in args.angles_deg.split(",")]
        except argparse.ArgumentTypeError as exc:
            raise InputError(f"--angles-deg '{args.angles_deg}': {exc}") from None
        if len(angles) != n_joints:
            raise InputError(
                f"--angles-deg '{args.angles_deg}': this table has {n_joints} joint(s), "
                f"got {len(angles)} angle(s)"
            )
        return angles
    if n_joints != 2 and any(v is not None for v in two):
        raise InputError(f"this table has {n_joints} joint(s): give --angles-deg")
    given = [*two, None][:n_joints]
    return [d if v is None else v for v, d in zip(given, defaults_deg, strict=False)]


def position_fields(table, angles_deg) -> dict:
    """How a command's JSON names the table and its position: its URDF, payload frame and
    ``angles_deg``, ``{angle: degrees}`` under the table's angle names (the paper's phi1, phi2;
    the joint names on a table whose layout names no angles)."""
    angles = [float(a) for a in angles_deg]
    return {
        "urdf": str(table.urdf_path),
        "payload_frame": table.payload_frame,
        "angles_deg": dict(zip(table.angle_names, angles, strict=True)),
    }


def position_text(fields: dict, payload_frame: bool = True) -> str:
    """The position of :func:`position_fields` in words (``phi1 = 30 deg, ...``), with the
    payload frame (``payload_frame``: where the user named the table)."""
    text = ", ".join(f"{j} = {a:g} deg" for j, a in fields["angles_deg"].items())
    return f"{text} (payload frame {fields['payload_frame']})" if payload_frame else text


def orientation_report(table, error_values, angles_deg) -> dict:
    """The dictionary the ``orientation`` command prints (units in the key names): the exact
    angles (Pinocchio) beside the first-order ones (the table's closed form where its layout
    has one, eq. 26 on the paper's), the payload origin and the errors."""
    angles_rad = [deg_to_rad(a) for a in angles_deg]
    result = table.orientation_error(error_values, angles_rad)
    first = table.first_order_error_rad(error_values, angles_rad)
    report = {**position_fields(table, angles_deg), "dR": result.dR}
    for name, value in zip(ANGLE_NAMES, (result.dpsi_rad, result.dtheta_rad, result.dgamma_rad),
                           strict=True):  # fmt: skip
        report[f"{name}_arcsec"] = rad_to_arcsec(value)
    for name, value in zip(ANGLE_NAMES, first, strict=True):
        report[f"{name}_first_order_arcsec"] = rad_to_arcsec(float(value))
    report["payload_origin_mm"] = np.asarray(result.payload_origin_m) / M_PER_MM
    report["errors"] = table.to_user_units(error_values)
    return report


def run_orientation(args: argparse.Namespace) -> int:
    table = table_from_args(args)
    angles = joint_angles_deg(args, len(table.joint_names))
    values = error_values_from_args(table, args)
    report = orientation_report(table, values, angles)
    if args.json:
        print_json(report)
        return 0
    print(f"position: {position_text(report, payload_frame=args.urdf is not None)}")
    print("dR = Rd^T Rt:")
    for row in report["dR"]:
        print("  [" + "  ".join(f"{v: .12f}" for v in row) + "]")
    label = f"{table.first_order_label} (arcsec)"
    print(f"{'':8s}{'exact (arcsec)':>16s}{label:>{len(label) + 3}s}")
    for name in ANGLE_NAMES:
        exact, approx = report[f"{name}_arcsec"], report[f"{name}_first_order_arcsec"]
        print(f"{name:8s}{exact:16.6f}{approx:{len(label) + 3}.6f}")
    x, y, z = report["payload_origin_mm"]
    print(f"payload origin (mm): x = {x:.6f}, y = {y:.6f}, z = {z:.6f}")
    return 0


def run_urdf(args: argparse.Namespace) -> int:
    table = table_from_args(args)
    path = table.write_urdf(error_values_from_args(table, args), args.output)
    print(f"wrote {path}")
    return 0
