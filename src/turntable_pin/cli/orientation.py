"""``turntable-pin orientation`` and ``turntable-pin urdf``: the error model at one position."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..calibration.positions import MAX_COMMANDED_ANGLE_DEG
from ..core.units import M_PER_MM, deg_to_rad, rad_to_arcsec
from ..model.angles import ANGLE_NAMES
from ..model.small_angle import small_angle_orientation_error
from .common import add_error_options, bounded_float, model_from_args, one_line_errors, print_json

__all__ = ["register"]


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
    p.add_argument("--phi1-deg", type=angle, default=0.0, help="outer-axis angle, degrees")
    p.add_argument("--phi2-deg", type=angle, default=0.0, help="inner-axis angle, degrees")
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
    u.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.urdf")
    u.set_defaults(func=run_urdf)


def orientation_report(model, phi1_deg: float, phi2_deg: float) -> dict:
    """The dictionary the ``orientation`` command prints (units in the key names)."""
    phi1_rad, phi2_rad = deg_to_rad(phi1_deg), deg_to_rad(phi2_deg)
    result = model.orientation_error(phi1_rad, phi2_rad)
    small = small_angle_orientation_error(model.errors, phi2_rad)
    return {
        "phi1_deg": phi1_deg,
        "phi2_deg": phi2_deg,
        "dR": result.dR,
        "dpsi_arcsec": rad_to_arcsec(result.dpsi_rad),
        "dtheta_arcsec": rad_to_arcsec(result.dtheta_rad),
        "dgamma_arcsec": rad_to_arcsec(result.dgamma_rad),
        "dpsi_small_angle_arcsec": rad_to_arcsec(float(small[0])),
        "dtheta_small_angle_arcsec": rad_to_arcsec(float(small[1])),
        "dgamma_small_angle_arcsec": rad_to_arcsec(float(small[2])),
        "payload_origin_mm": np.asarray(result.payload_origin_m) / M_PER_MM,
        "errors": model.errors.to_user_units(),
    }


def run_orientation(args: argparse.Namespace) -> int:
    report = orientation_report(model_from_args(args), args.phi1_deg, args.phi2_deg)
    if args.json:
        print_json(report)
        return 0
    print(f"position: phi1 = {args.phi1_deg:g} deg, phi2 = {args.phi2_deg:g} deg")
    print("dR = Rd^T Rt:")
    for row in report["dR"]:
        print("  [" + "  ".join(f"{v: .12f}" for v in row) + "]")
    print(f"{'':8s}{'exact (arcsec)':>16s}{'eq. 26 (arcsec)':>18s}")
    for name in ANGLE_NAMES:
        exact = report[f"{name}_arcsec"]
        small = report[f"{name}_small_angle_arcsec"]
        print(f"{name:8s}{exact:16.6f}{small:18.6f}")
    x, y, z = report["payload_origin_mm"]
    print(f"payload origin (mm): x = {x:.6f}, y = {y:.6f}, z = {z:.6f}")
    return 0


def run_urdf(args: argparse.Namespace) -> int:
    path = model_from_args(args).write_urdf(args.output)
    print(f"wrote {path}")
    return 0
