"""``turntable-pin allocate`` and ``turntable-pin montecarlo``: error allocation and its check."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..allocation.capability import ManufacturingCapability
from ..allocation.monte_carlo import run_monte_carlo
from ..allocation.sensitivity import AverageSensitivities, average_sensitivities
from ..allocation.solver import (
    DEFAULT_ACCURACY_DPH,
    DEFAULT_POSITIONS,
    ORIENTATION_ANGLES,
    WEIGHT_SCHEMES,
    Allocation,
    OrientationLimits,
    allocate_tolerances,
    default_orientation_limits,
)
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InfeasibleError, InputError
from ..core.units import ARCMIN_PER_RAD, DEG_PER_RAD
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .common import (
    accuracy_dph,
    bounded_float,
    finite_float,
    latitude_deg,
    one_line_errors,
    positive_float,
    positive_int,
    print_json,
    seed,
)

__all__ = ["parse_limits", "register"]


def parse_limits(text: str, unit: str) -> OrientationLimits:
    """``psi=P,theta=T,gamma=G`` (or one number for all three) in ``arcmin`` or ``deg``."""
    option = f"--limits-{unit}"
    text = text.strip()
    values: dict[str, float] = {}
    if "=" not in text:
        values = dict.fromkeys(ORIENTATION_ANGLES, _number(text, option))
    else:
        for item in text.split(","):
            key, sep, raw = item.partition("=")
            key = key.strip()
            if not sep or key not in ORIENTATION_ANGLES:
                raise InputError(
                    f"{option} '{text}': expected psi=P,theta=T,gamma=G (or one number), "
                    f"got '{item.strip()}'"
                )
            if key in values:
                raise InputError(f"{option}: '{key}' is given twice")
            values[key] = _number(raw, option)
        missing = [n for n in ORIENTATION_ANGLES if n not in values]
        if missing:
            raise InputError(f"{option}: no limit for {', '.join(missing)}")
    make = OrientationLimits.from_arcmin if unit == "arcmin" else OrientationLimits.from_deg
    try:
        return make(**values)
    except InputError as exc:
        raise InputError(f"{option}: {exc}") from None


def _number(text: str, option: str) -> float:
    try:
        return finite_float(text.strip())
    except argparse.ArgumentTypeError as exc:
        raise InputError(f"{option}: {exc}") from None


def _add_allocation_options(p: argparse.ArgumentParser) -> None:
    one_line_errors(p)
    limits = p.add_mutually_exclusive_group()
    limits.add_argument(
        "--limits-arcmin",
        metavar="psi=P,theta=T,gamma=G",
        help="orientation limits in arc minutes (one number: the same for all three); "
        "default: the calibration layer's orientation requirement for --accuracy-dph on "
        "--positions at --latitude-deg",
    )
    limits.add_argument("--limits-deg", metavar="psi=P,theta=T,gamma=G", help="... in degrees")
    p.add_argument(
        "--accuracy-dph",
        type=accuracy_dph,
        default=DEFAULT_ACCURACY_DPH,
        help=f"calibration accuracy behind the default limits, deg/h ({DEFAULT_ACCURACY_DPH})",
    )
    p.add_argument(
        "--positions",
        default=DEFAULT_POSITIONS,
        help=f"position scheme behind the default limits ({DEFAULT_POSITIONS})",
    )
    p.add_argument(
        "--latitude-deg",
        type=latitude_deg,
        default=DEFAULT_LATITUDE_DEG,
        help=f"latitude behind the default limits, degrees ({DEFAULT_LATITUDE_DEG})",
    )
    p.add_argument(
        "--weights",
        choices=WEIGHT_SCHEMES,
        default="model",
        help="W = 1/sensitivity from the exact model (default), from the paper's Figure 8 "
        "(0.6481 for sin/cos terms, 1 for constants), or equal weights (traditional method)",
    )
    p.add_argument(
        "--lower-bounds",
        type=Path,
        metavar="FILE.yaml",
        help="manufacturing lower bounds (default: the bundled "
        "models/manufacturing_lower_bounds.yaml)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``allocate`` and ``montecarlo`` subcommands to ``subparsers``."""
    a = subparsers.add_parser(
        "allocate",
        description="Error allocation of paper section 4.2 (eqs. 29-34): three weighted problems "
        "with their constraints over phi2 solved exactly, combined by eq. 34. Prints the upper "
        "bounds, J, the active constraints and the worst-case orientation error the bounds allow.",
    )
    _add_allocation_options(a)
    a.add_argument("--plots", type=Path, metavar="DIR", help="write Figure 8 (sensitivities) here")
    a.set_defaults(func=run_allocate)

    m = subparsers.add_parser(
        "montecarlo",
        description="Allocate as `allocate` does, draw N turntables with error magnitudes uniform "
        "in [lower, upper] bound and random signs, evaluate the exact orientation error over a "
        "phi2 grid and compare the largest |dpsi|, |dtheta|, |dgamma| with the limits (Figure 9). "
        "Exit status 1 if a limit is exceeded.",
    )
    _add_allocation_options(m)
    m.add_argument("-n", type=positive_int, default=10000, help="number of turntables (10000)")
    m.add_argument("--seed", type=seed, default=0, help="random seed, recorded in the output (0)")
    m.add_argument(
        "--phi2-step-deg",
        type=bounded_float(0.0, 90.0, "deg", low_open=True),
        default=1.0,
        help="phi2 grid step, degrees (1)",
    )
    m.add_argument(
        "--scale-bounds",
        type=positive_float,
        default=1.0,
        metavar="K",
        help="sample inside K times the allocated upper bounds (K > 1 shows the bounds are tight)",
    )
    m.add_argument("--workers", type=positive_int, default=1, help="worker processes (1)")
    m.add_argument("--plots", type=Path, metavar="DIR", help="write Figure 9 (histograms) here")
    m.add_argument("--quiet", action="store_true", help="no progress report")
    m.set_defaults(func=run_montecarlo)


def _allocation_from_args(args: argparse.Namespace) -> tuple[Allocation, AverageSensitivities]:
    """The allocation the options ask for and the sensitivities behind Figure 8."""
    if args.limits_arcmin is not None:
        limits = parse_limits(args.limits_arcmin, "arcmin")
        given = f"--limits-arcmin {args.limits_arcmin}"
    elif args.limits_deg is not None:
        limits = parse_limits(args.limits_deg, "deg")
        given = f"--limits-deg {args.limits_deg}"
    else:
        limits = default_orientation_limits(args.accuracy_dph, args.positions, args.latitude_deg)
        given = f"the limits of --accuracy-dph {args.accuracy_dph:g}"
    capability = (
        ManufacturingCapability.from_yaml(args.lower_bounds)
        if args.lower_bounds
        else ManufacturingCapability.default()
    )
    # phi1 drops out of dR (tested), so one phi1 value is enough for the averages.
    sensitivities = average_sensitivities(phi1_grid_deg=[0.0])
    try:
        allocation = allocate_tolerances(limits, args.weights, capability, sensitivities)
    except InfeasibleError as exc:  # name the two inputs that conflict
        source = capability.source
        raise InfeasibleError(f"{given} with the lower bounds of {source}: {exc}") from None
    return allocation, sensitivities


def run_allocate(args: argparse.Namespace) -> int:
    allocation, sensitivities = _allocation_from_args(args)
    figure = None
    if args.plots:
        from ..report.allocation_figures import plot_sensitivities

        figure = plot_sensitivities(sensitivities, args.plots / "figure8_sensitivities.png")
    if args.json:
        report = allocation.to_dict()
        report["sensitivities"] = sensitivities.to_dict()["sensitivities"]
        if figure:
            report["plot"] = str(figure)
        print_json(report)
    else:
        print(allocation.report())
        if figure:
            print(f"\nwrote {figure}")
    return 0


def run_montecarlo(args: argparse.Namespace) -> int:
    if args.scale_bounds <= 0.0:
        raise InputError(f"--scale-bounds must be positive, got {args.scale_bounds}")
    allocation, _ = _allocation_from_args(args)
    upper = allocation.upper_bounds_rad * args.scale_bounds
    if float(upper.max()) > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:
        raise InputError(
            f"--scale-bounds {args.scale_bounds:g}: the scaled bounds reach "
            f"{float(upper.max()) * DEG_PER_RAD:g} deg, beyond the {MAX_ANGULAR_ERROR_DEG:g} deg "
            "of a small error"
        )
    lower = allocation.capability.lower_bounds_rad
    if args.scale_bounds < 1.0:
        lower = lower * args.scale_bounds
    result = run_monte_carlo(
        upper,
        allocation.limits,
        args.n,
        args.seed,
        lower_bounds_rad=lower,
        phi2_step_deg=args.phi2_step_deg,
        workers=args.workers,
        progress=not (args.quiet or args.json),
    )
    report = result.to_dict()
    report["weights"] = args.weights
    report["scale_bounds"] = args.scale_bounds
    figure = None
    if args.plots:
        from ..report.allocation_figures import plot_monte_carlo

        figure = plot_monte_carlo(result, args.plots / "figure9_montecarlo.png")
        report["plot"] = str(figure)
    if args.json:
        print_json(report)
    else:
        limits = allocation.limits.to_dict()
        print(
            f"Monte Carlo: {result.n} turntables (seed {result.seed}), phi2 step "
            f"{result.phi2_step_deg:g} deg, exact chain, {result.elapsed_s:.1f} s"
        )
        for k, name in enumerate(ORIENTATION_ANGLES):
            value = result.max_abs_rad[k] * ARCMIN_PER_RAD
            flag = "ok" if value <= limits[name] else "EXCEEDED"
            print(f"  max |d{name}| = {value:.4f}'  limit {limits[name]:.4f}'  {flag}")
        print("all within the limits" if result.all_within else "a limit is exceeded")
        if figure:
            print(f"wrote {figure}")
    return 0 if result.all_within else 1
