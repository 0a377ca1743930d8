"""``turntable-pin orientation`` and ``turntable-pin urdf``: the error model at one position."""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..calibration.positions import MAX_COMMANDED_ANGLE_DEG
from ..core.exceptions import InputError
from ..core.units import M_PER_MM, deg_to_rad, rad_to_arcsec
from ..model.angles import ANGLE_ENTRIES, ANGLE_NAMES
from ..model.small_angle import small_angle_orientation_error
from .common import (
    add_error_options,
    bounded_float,
    generic_errors_from_args,
    generic_table_from_args,
    model_from_args,
    one_line_errors,
    paper_table_requested,
    print_json,
)

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
    p.add_argument("--phi1-deg", type=angle, default=None, help="outer-axis angle, degrees")
    p.add_argument("--phi2-deg", type=angle, default=None, help="inner-axis angle, degrees")
    p.add_argument(
        "--angles-deg",
        metavar="A,B,C",
        help="the joint angles in chain order from the base, degrees (any table; a two-axis "
        "table also takes --phi1-deg/--phi2-deg)",
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


def _joint_angles_deg(args: argparse.Namespace, n_joints: int) -> list[float]:
    """The joint angles of ``--angles-deg`` or ``--phi1-deg/--phi2-deg`` (0 where not given)."""
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
    return [0.0 if v is None else v for v in two[:n_joints]] + [0.0] * max(0, n_joints - 2)


def generic_orientation_report(table, error_values, angles_deg: list[float]) -> dict:
    """The ``orientation`` dictionary of any table (generic error names; units in the keys)."""
    angles_rad = [deg_to_rad(a) for a in angles_deg]
    dR = table.rotation_error(error_values, angles_rad)
    first = table.regressor([np.array([a]) for a in angles_rad])[0] @ error_values
    report = {
        "urdf": str(table.urdf_path),
        "payload_frame": table.payload_frame,
        "angles_deg": dict(zip(table.joint_names, angles_deg, strict=True)),
        "dR": dR,
    }
    for k, (name, (i, j)) in enumerate(zip(ANGLE_NAMES, ANGLE_ENTRIES, strict=True)):
        report[f"{name}_arcsec"] = rad_to_arcsec(float(dR[i, j]))
        report[f"{name}_first_order_arcsec"] = rad_to_arcsec(float(first[k]))
    report["payload_origin_mm"] = table.payload_origin_m(error_values, angles_rad) / M_PER_MM
    report["errors"] = {k: v for k, v in table.to_user_units(error_values).items() if v != 0.0}
    return report


def _print_report(report: dict, position: str, approx_key: str, approx_label: str) -> None:
    """The text form of an ``orientation`` report: dR, the exact angles beside their
    approximation (``<angle>_<approx_key>_arcsec``), the payload origin."""
    print(f"position: {position}")
    print("dR = Rd^T Rt:")
    for row in report["dR"]:
        print("  [" + "  ".join(f"{v: .12f}" for v in row) + "]")
    label = f"{approx_label} (arcsec)"
    print(f"{'':8s}{'exact (arcsec)':>16s}{label:>{len(label) + 3}s}")
    for name in ANGLE_NAMES:
        exact, approx = report[f"{name}_arcsec"], report[f"{name}_{approx_key}_arcsec"]
        print(f"{name:8s}{exact:16.6f}{approx:{len(label) + 3}.6f}")
    x, y, z = report["payload_origin_mm"]
    print(f"payload origin (mm): x = {x:.6f}, y = {y:.6f}, z = {z:.6f}")


def run_orientation(args: argparse.Namespace) -> int:
    if not paper_table_requested(args):
        return _run_generic_orientation(args)
    phi1, phi2 = _joint_angles_deg(args, 2)
    report = orientation_report(model_from_args(args), phi1, phi2)
    if args.json:
        print_json(report)
    else:
        _print_report(report, f"phi1 = {phi1:g} deg, phi2 = {phi2:g} deg", "small_angle", "eq. 26")
    return 0


def _run_generic_orientation(args: argparse.Namespace) -> int:
    table = generic_table_from_args(args)
    angles = _joint_angles_deg(args, len(table.joint_names))
    report = generic_orientation_report(table, generic_errors_from_args(table, args), angles)
    if args.json:
        print_json(report)
        return 0
    where = ", ".join(f"{j} = {a:g} deg" for j, a in report["angles_deg"].items())
    position = f"{where} (payload frame {table.payload_frame})"
    _print_report(report, position, "first_order", "first order")
    return 0


def run_urdf(args: argparse.Namespace) -> int:
    if not paper_table_requested(args):
        table = generic_table_from_args(args)
        path = table.write_urdf(generic_errors_from_args(table, args), args.output)
        print(f"wrote {path}")
        return 0
    path = model_from_args(args).write_urdf(args.output)
    print(f"wrote {path}")
    return 0
