"""``turntable-pin allocate`` and ``turntable-pin montecarlo``: error allocation and its check."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
from pathlib import Path

from ..allocation.capability import ManufacturingCapability
from ..allocation.monte_carlo import run_monte_carlo
from ..allocation.solver import (
    DEFAULT_ACCURACY_DPH,
    DEFAULT_POSITIONS,
    REQUIREMENT_KINDS,
    WEIGHT_SCHEMES,
    Allocation,
    OrientationLimits,
    allocate_tolerances,
    default_orientation_limits,
)
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InfeasibleError, InputError
from ..core.sizes import MIN_GRID_STEP_DEG
from ..core.units import ARCMIN_PER_RAD, DEG_PER_RAD
from ..model.angles import ANGLE_SYMBOLS
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .common import (
    accuracy_dph,
    add_table_options,
    bounded_float,
    finite_float,
    input_path,
    latitude_deg,
    one_line_errors,
    position_scheme,
    positive_float,
    positive_int,
    print_json,
    seed,
    table_from_args,
)

__all__ = ["parse_limits", "register"]


def parse_limits(text: str, unit: str) -> OrientationLimits:
    """``psi=P,theta=T,gamma=G`` (or one number for all three) in ``arcmin`` or ``deg``."""
    option = f"--limits-{unit}"
    text = text.strip()
    values: dict[str, float] = {}
    if "=" not in text:
        values = dict.fromkeys(ANGLE_SYMBOLS, _number(text, option))
    else:
        for item in text.split(","):
            key, sep, raw = item.partition("=")
            key = key.strip()
            if not sep or key not in ANGLE_SYMBOLS:
                raise InputError(
                    f"{option} '{text}': expected psi=P,theta=T,gamma=G (or one number), "
                    f"got '{item.strip()}'"
                )
            if key in values:
                raise InputError(f"{option}: '{key}' is given twice")
            values[key] = _number(raw, option)
        missing = [n for n in ANGLE_SYMBOLS if n not in values]
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
    limits.add_argument(
        "--limits-deg",
        metavar="psi=P,theta=T,gamma=G",
        help="the same in degrees (default: as --limits-arcmin says)",
    )
    p.add_argument(
        "--accuracy-dph",
        type=accuracy_dph,
        default=DEFAULT_ACCURACY_DPH,
        help="calibration accuracy behind the default limits, deg/h",
    )
    p.add_argument(
        "--positions",
        type=position_scheme,
        default=DEFAULT_POSITIONS,
        help="position scheme behind the default limits",
    )
    p.add_argument(
        "--latitude-deg",
        type=latitude_deg,
        default=DEFAULT_LATITUDE_DEG,
        help="latitude behind the default limits, degrees",
    )
    p.add_argument(
        "--requirement",
        choices=REQUIREMENT_KINDS,
        default=REQUIREMENT_KINDS[0],
        help="which requirement the default limits are: the largest box whose every point "
        "meets the accuracy or the paper's planes (eqs. 15-16; all three at their "
        "limits at once exceed it)",
    )
    p.add_argument(
        "--weights",
        choices=WEIGHT_SCHEMES,
        default="model",
        help="W = 1/sensitivity from the exact model, from the paper's Figure 8 "
        "(0.6481 for sin/cos terms, 1 for constants), or equal weights (traditional method)",
    )
    p.add_argument(
        "--lower-bounds",
        type=input_path,
        metavar="FILE.yaml",
        help="manufacturing lower bounds in the table's error names (default: the table's "
        "bundled ones, the paper's models/manufacturing_lower_bounds.yaml; none bundled: 0)",
    )
    add_table_options(p)
    from ..allocation.sensitivity import DEFAULT_GRID_STEPS_DEG as STEPS

    steps = ", ".join(f"{STEPS[k]:g}" for k in sorted(STEPS))
    counts = ", ".join(str(k) for k in sorted(STEPS))
    p.add_argument(
        "--grid-step-deg",
        type=bounded_float(MIN_GRID_STEP_DEG, 90.0, "deg"),
        default=None,
        help="step of the grid over every joint on which the sensitivities are averaged, the "
        "maxima of the constraints start (they hold between the grid points too) and the Monte "
        f"Carlo runs (default {steps} deg when the first-order model depends on {counts} "
        f"joints: {STEPS[1]:g} deg on the paper's table)",
    )
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--quiet", action="store_true",
                   help="no progress report (by default long work reports its progress on "
                   "stderr, unless --json: the default limits' requirement, the Monte Carlo "
                   "runs)")  # fmt: skip


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``allocate`` and ``montecarlo`` subcommands to ``subparsers``."""
    a = subparsers.add_parser(
        "allocate",
        description="Error allocation of paper section 4.2 (eqs. 29-34) on the table's "
        "first-order model: three weighted problems whose constraints hold over every angle of "
        "their domain (the joint intervals the table's layout gives: the paper's phi2 intervals "
        "on its table; else whole turns) solved exactly, combined by eq. 34. Prints the upper "
        "bounds, J, the active constraints and the worst-case orientation error the bounds "
        "allow.",
    )
    _add_allocation_options(a)
    a.add_argument(
        "--plots",
        type=Path,
        metavar="DIR",
        help="write Figure 8 (sensitivities) here (default: no plots)",
    )
    a.set_defaults(func=run_allocate)

    m = subparsers.add_parser(
        "montecarlo",
        description="Allocate as `allocate` does, draw N turntables with error magnitudes uniform "
        "in [lower, upper] bound and random signs, evaluate the exact orientation error over a "
        "grid of every joint (--grid-step-deg; a joint no drawn table depends on at 0 only) and "
        "compare the largest |dpsi|, |dtheta|, |dgamma| with the limits (Figure 9). Exit status "
        "1 if a limit is exceeded.",
    )
    _add_allocation_options(m)
    m.add_argument("-n", type=positive_int, default=10000, help="number of turntables")
    m.add_argument("--seed", type=seed, default=0, help="random seed, recorded in the output")
    m.add_argument(
        "--scale-bounds",
        type=positive_float,
        default=1.0,
        metavar="K",
        help="sample inside K times the allocated upper bounds (K > 1 shows the bounds are tight)",
    )
    m.add_argument("--workers", type=positive_int, default=1, help="worker processes")
    m.add_argument(
        "--plots",
        type=Path,
        metavar="DIR",
        help="write Figure 9 (histograms) here (default: no plots)",
    )
    m.set_defaults(func=run_montecarlo)


def _limits_from_args(args: argparse.Namespace, table) -> tuple[OrientationLimits, str]:
    """The orientation limits of the options and how they were given; the default limits come
    from the calibration layer's requirement on ``table``'s positions."""
    if args.limits_arcmin is not None:
        return parse_limits(args.limits_arcmin, "arcmin"), f"--limits-arcmin {args.limits_arcmin}"
    if args.limits_deg is not None:
        return parse_limits(args.limits_deg, "deg"), f"--limits-deg {args.limits_deg}"
    given = f"the limits ({args.requirement}) of --accuracy-dph {args.accuracy_dph:g}"
    from ..core.exceptions import IdentifiabilityError

    try:
        limits = default_orientation_limits(
            args.accuracy_dph, args.positions, args.latitude_deg, table, args.requirement,
            progress=not (args.quiet or args.json),
        )  # fmt: skip
    except IdentifiabilityError as exc:
        raise IdentifiabilityError(
            f"no default limits for this table ({exc}); give --limits-arcmin or --limits-deg"
        ) from None
    return limits, given


def _allocation_from_args(args: argparse.Namespace, table) -> Allocation:
    """The allocation the options ask for, of ``table``."""
    limits, given = _limits_from_args(args, table)
    capability = None
    if args.lower_bounds:
        capability = ManufacturingCapability.from_yaml(args.lower_bounds, table)
    try:
        return allocate_tolerances(
            limits, args.weights, capability, table=table, grid_step_deg=args.grid_step_deg
        )
    except InfeasibleError as exc:  # name the two inputs that conflict
        source = (capability or ManufacturingCapability.of_table(table)).source
        raise InfeasibleError(f"{given} with the lower bounds of {source}: {exc}") from None


def run_allocate(args: argparse.Namespace) -> int:
    allocation = _allocation_from_args(args, table_from_args(args))
    figure = None
    if args.plots:
        from ..report.allocation_figures import plot_sensitivities

        figure = plot_sensitivities(
            allocation.sensitivities, args.plots / "figure8_sensitivities.png"
        )
    if args.json:
        report = allocation.to_dict()
        if figure:
            report["plot"] = str(figure)
        print_json(report)
    else:
        print(allocation.report())
        if figure:
            print(f"\nwrote {figure}")
    return 0


def _scaled_bounds(args: argparse.Namespace, upper, lower):
    """The box of ``--scale-bounds`` K: K times the upper bounds, the lower ones too if K < 1."""
    upper = upper * args.scale_bounds
    if float(upper.max()) > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:
        raise InputError(
            f"--scale-bounds {args.scale_bounds:g}: the scaled bounds reach "
            f"{float(upper.max()) * DEG_PER_RAD:g} deg, beyond the {MAX_ANGULAR_ERROR_DEG:g} deg "
            "of a small error"
        )
    if args.scale_bounds < 1.0:
        lower = lower * args.scale_bounds
    return upper, lower


def run_montecarlo(args: argparse.Namespace) -> int:
    if args.scale_bounds <= 0.0:
        raise InputError(f"--scale-bounds must be positive, got {args.scale_bounds}")
    table = table_from_args(args)
    allocation = _allocation_from_args(args, table)
    upper, lower = _scaled_bounds(args, allocation.upper_bounds_rad, allocation.lower_bounds_rad)
    result = run_monte_carlo(
        upper, allocation.limits, args.n, args.seed, table=table, lower_bounds_rad=lower,
        grid_step_deg=allocation.sensitivities.grid_step_deg, workers=args.workers,
        progress=not (args.quiet or args.json),
    )  # fmt: skip
    title = (
        f"Monte Carlo on {table.title}: {result.n} tables (seed {result.seed}), "
        f"grid {result.grid_steps_deg[0]:g} deg over {', '.join(table.joint_names)} "
        f"({result.n_grid_points} positions), exact chain, {result.elapsed_s:.1f} s"
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
        return 0 if result.all_within else 1
    limits = allocation.limits.to_dict()
    print(title)
    for k, name in enumerate(ANGLE_SYMBOLS):
        value = result.max_abs_rad[k] * ARCMIN_PER_RAD
        flag = "ok" if value <= limits[name] else "EXCEEDED"
        print(f"  max |d{name}| = {value:.4f}'  limit {limits[name]:.4f}'  {flag}")
    print("all within the limits" if result.all_within else "a limit is exceeded")
    if figure:
        print(f"wrote {figure}")
    return 0 if result.all_within else 1
