"""``design``: which positions to measure next, to identify, to separate two effects, to calibrate.

Each mode is one function (``_run_identify``, ``_run_separate``, ``_run_calibrate``,
``_run_separate_run``) that calls :mod:`turntable_pin.design` and renders its one result as text,
JSON, a CSV of the positions (``-o``, what ``simulate --positions`` reads) and figures.
"""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
from pathlib import Path

from ..core.exceptions import InputError
from .common import (
    accuracy_dph,
    add_mount_option,
    add_table_options,
    bounded_float,
    effect_list,
    effect_options,
    effect_spec,
    input_path,
    latitude_deg,
    one_line_errors,
    positive_int,
    print_json,
    seed,
    table_from_args,
    warn_ignored_columns,
)

__all__ = ["register"]


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``design`` to ``subparsers``."""
    from ..design.space import GRID_STEP_DEG

    p = subparsers.add_parser(
        "design",
        description="Which positions to measure next. Default (identify): the N positions within "
        "the joints' limits that determine the identifiable combinations of the base errors and "
        "the chosen effects best (D-optimal: the largest log det of their Fisher information), "
        "with each combination's expected standard error and the D-efficiency against the "
        f"{GRID_STEP_DEG:g}-degree grid. --separate A,B: the positions that tell effect A from "
        "effect B (T-optimal). --calibrate: GyroWheel calibration positions least sensitive to "
        "the table's orientation errors. Effects that need time_s (thermal drift) make the run "
        "repeat positions early and late in a seeded random order; backlash makes it approach "
        "each position from both sides (dirK = +1 and -1).",
    )
    one_line_errors(p)
    add_table_options(p)
    add_mount_option(p)
    _add_mode_options(p)
    _add_design_options(p)
    _add_output_options(p)
    p.set_defaults(func=run_design)


def _add_mode_options(p: argparse.ArgumentParser) -> None:
    """``--separate``, ``--calibrate`` and their own options."""
    from ..design.calibrate import DEFAULT_MIN_EFFICIENCY, MAX_MIN_EFFICIENCY

    mode = p.add_mutually_exclusive_group()
    mode.add_argument(
        "--separate",
        type=effect_list,
        metavar="A,B",
        help="positions that tell effect A from effect B (T-optimal; default: without "
        "--separate or --calibrate, positions that identify the parameters)",
    )
    p.add_argument(
        "--amplitude",
        action="append",
        default=[],
        type=effect_spec,
        metavar="A:P=V[,P=V...]",
        help="with --separate: an effect's parameters in its user units (arcsec, arcsec/g), e.g. "
        "TF:TF=10 (default: fitted with the base errors on --from data); repeatable",
    )
    mode.add_argument(
        "--calibrate",
        action="store_true",
        help="GyroWheel calibration positions least sensitive to the table's orientation errors",
    )
    p.add_argument(
        "--accuracy-dph", type=accuracy_dph, default=0.01,
        help="--calibrate: the required calibration accuracy w_m, deg/h",
    )  # fmt: skip
    p.add_argument(
        "--min-efficiency", type=bounded_float(0.0, MAX_MIN_EFFICIENCY, low_open=True),
        default=DEFAULT_MIN_EFFICIENCY, metavar="E",
        help="--calibrate: the precision floor, D-efficiency of the 14 drift coefficients "
        "against the grid of the same N (1: at least as precise as the grid)",
    )  # fmt: skip


def _add_design_options(p: argparse.ArgumentParser) -> None:
    """How many positions, from which candidates, after which data, with which effects."""
    from ..design.space import DEFAULT_CANDIDATES, DEFAULT_POSITIONS, GRID_STEP_DEG

    p.add_argument(
        "-n",
        "--positions-count",
        type=positive_int,
        default=DEFAULT_POSITIONS,
        metavar="N",
        help="positions to choose",
    )
    p.add_argument(
        "--effects",
        action="append",
        default=[],
        type=effect_list,
        metavar="A,B",
        help="effects to identify besides the base errors, as fit --effects takes "
        "them: catalogue names, effect files (.yaml), inline terms; repeatable (default: none, "
        "the base errors alone)",
    )
    p.add_argument(
        "--effects-module",
        action="append",
        default=[],
        type=input_path,
        metavar="FILE.py",
        help="a Python file defining Effect subclasses (with --separate --run: RunEffect "
        "subclasses); their names join --effects. The file is code that runs: it is imported "
        "and its methods called (give only files you trust); repeatable (default: none)",
    )
    p.add_argument(
        "--from",
        "--from-data",
        dest="from_data",
        type=input_path,
        metavar="DATA.csv",
        help="positions already measured: their information is where the design "
        "starts, and their fitted noise the design's noise (default: none, the design starts "
        "from nothing)",
    )
    p.add_argument(
        "--limits-deg",
        metavar="J=LO:HI,...",
        help="narrow the joints' ranges (J: a joint's name or phiK; default: the "
        "URDF <limit>s, a full turn for continuous joints)",
    )
    p.add_argument(
        "--candidates",
        type=positive_int,
        default=DEFAULT_CANDIDATES,
        metavar="N",
        help=f"random candidate positions within the limits (seeded); the {GRID_STEP_DEG:g}-degree "
        "grid joins them",
    )
    p.add_argument(
        "--seed",
        type=seed,
        default=0,
        help="seed of the candidates and of the order (recorded in every output)",
    )
    p.add_argument(
        "--noise-arcsec",
        type=_noise_arcsec,
        default=None,
        help="1-sigma noise of a measured angle (default: fitted on --from data, else 1)",
    )
    p.add_argument(
        "--dwell-s",
        type=_dwell_s,
        default=60.0,
        help="time per measurement, seconds, for the time_s column",
    )


def _add_output_options(p: argparse.ArgumentParser) -> None:
    """``-o``, ``--run`` (with its latitude), ``--json`` and ``--plots``."""
    from ..calibration.site import DEFAULT_LATITUDE_DEG

    p.add_argument(
        "-o",
        "--output",
        type=Path,
        metavar="OUT.csv",
        help="write the positions as a CSV (phiK_deg, with time_s and dirK when "
        "the design needs them): simulate --positions reads it (default: printed only)",
    )
    p.add_argument(
        "--run", type=input_path, metavar="RUN.csv",
        help="with --separate: A and B are effects of this GyroWheel calibration run (its "
        "catalogue: table:<error>, instrument_tilt, g_squared_terms, ...; as calibrate "
        "--diagnose names them), each at the amplitude the run fits; the design adds "
        "calibration positions to the run (default: none, orientation measurements)",
    )  # fmt: skip
    p.add_argument(
        "--latitude-deg", type=latitude_deg, default=DEFAULT_LATITUDE_DEG,
        help="with --run: the latitude of the run's site, degrees",
    )  # fmt: skip
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument(
        "--plots",
        type=Path,
        metavar="DIR",
        help="write the design's figures here (default: no plots)",
    )


def _noise_arcsec(text: str) -> float:
    """argparse type of ``--noise-arcsec``: the noise range of a measurement file."""
    from ..measurement.data import MAX_SIGMA_ARCSEC, MIN_SIGMA_ARCSEC

    return bounded_float(MIN_SIGMA_ARCSEC, MAX_SIGMA_ARCSEC, "arcsec")(text)


def _dwell_s(text: str) -> float:
    """argparse type of ``--dwell-s``: a time in (0, a year]."""
    from ..measurement.data import MAX_TIME_S

    return bounded_float(0.0, MAX_TIME_S, "s", low_open=True)(text)


def run_design(args: argparse.Namespace) -> int:
    """Run the mode the options name (identify by default)."""
    if args.run is not None:
        if args.separate is None:
            raise InputError("--run goes with --separate A,B (the run's two explanations)")
        return _run_separate_run(args)
    if args.separate is not None:
        return _run_separate(args)
    if args.calibrate:
        return _run_calibrate(args)
    return _run_identify(args)


def _effects(args: argparse.Namespace, table) -> tuple:
    """The effects of ``--effects`` (and ``--effects-module``) on ``table``."""
    from ..measurement.user_effects import load_effects_modules, resolve_effects

    return resolve_effects(args.effects, table, load_effects_modules(args.effects_module, table))


def _space(args: argparse.Namespace, effects=None):
    """The :class:`~turntable_pin.design.space.DesignSpace` of the common options (the effects
    of ``--effects`` unless ``effects`` are given)."""
    from ..design.space import design_space

    table = table_from_args(args)
    chosen = _effects(args, table) if effects is None else tuple(effects)
    return design_space(
        table, chosen, limits_deg=args.limits_deg, candidates=args.candidates, seed=args.seed
    )


def _positions_count(args: argparse.Namespace, space) -> int:
    """``-n``, checked against the candidates of ``space`` before any of the design's work (the
    library checks its argument too, by its own name)."""
    from ..core.sizes import check_positions_count

    count = args.positions_count
    return check_positions_count(count, space.candidates_deg.shape[0], "-n", "more --candidates")


def _from_data(args: argparse.Namespace, table):
    """The measurements of ``--from`` (None when not given)."""
    if args.from_data is None:
        return None
    from ..measurement.data import read_measurements
    from ..measurement.table import measured_table

    measured = measured_table(table)
    data = read_measurements(args.from_data, measured.joint_names)
    warn_ignored_columns(args, data, args.from_data)
    return data


def _finish(result, args: argparse.Namespace, write_plots=None) -> int:
    """Write the positions (``-o``: ``result.plan``'s CSV, with ``result.comment()`` above it when
    the result has one) and the figures (``--plots``: ``write_plots(result, folder)``, else
    ``result.write_plots(folder)``) of ``result``, then print it (text or JSON)."""
    out = result.to_dict()
    written = []
    if args.output is not None:
        comment = result.comment() if hasattr(result, "comment") else ""
        out["output"] = str(result.plan.write_csv(args.output, comment=comment))
        written.append(out["output"])
    if args.plots is not None:
        plots = write_plots(result, args.plots) if write_plots else result.write_plots(args.plots)
        out["plots"] = [str(p) for p in plots]
        written += out["plots"]
    if args.json:
        print_json(out)
        return 0
    print(result.report())
    for path in written:
        print(f"wrote {path}")
    return 0


def _run_identify(args: argparse.Namespace) -> int:
    """D-optimal positions for the identifiable combinations (the default mode)."""
    from ..design.identify import design_identify

    space = _space(args)
    result = design_identify(
        space,
        _positions_count(args, space),
        from_data=_from_data(args, space.table),
        noise_arcsec=args.noise_arcsec,
        dwell_s=args.dwell_s,
    )
    from ..report.design_figures import write_identify_plots

    return _finish(result, args, write_identify_plots)


def _run_separate(args: argparse.Namespace) -> int:
    """T-optimal positions that tell two effects apart (``--separate A,B``): each at its
    amplitude (``--amplitude``, else fitted on ``--from``), with the chance of the right name;
    one line (exit 0) when no positions within the limits separate them."""
    from ..design.separate import design_separate
    from ..measurement.user_effects import load_effects_modules, resolve_effects
    from ..report.separation_figures import write_separate_plots

    if args.effects:
        raise InputError(
            "--separate A,B names the two effects to tell apart; --effects is for the identify mode"
        )
    table = table_from_args(args)
    modules = load_effects_modules(args.effects_module, table)
    pair = resolve_effects(_pair(args), table, modules)
    amplitudes = effect_options(args.amplitude, "--amplitude", table, modules)
    space = _space(args, pair)
    result = design_separate(
        space,
        _positions_count(args, space),
        from_data=_from_data(args, space.table),
        amplitudes=amplitudes,
        noise_arcsec=args.noise_arcsec,
        dwell_s=args.dwell_s,
    )
    if result.plan is None:  # no positions separate them: the answer, not an error
        if args.json:
            print_json(result.to_dict())
        else:
            print(result.report())
        return 0
    return _finish(result, args, write_separate_plots)


def _pair(args: argparse.Namespace) -> list[str]:
    """The two effects of ``--separate A,B``."""
    names = [n.strip() for n in args.separate.split(",") if n.strip()]
    if len(names) != 2:
        raise InputError(f"--separate takes two effects, A,B; got '{args.separate}'")
    return names


def _run_calibrate(args: argparse.Namespace) -> int:
    """GyroWheel calibration positions least sensitive to the table's errors (``--calibrate``):
    the loosest orientation requirement (the largest box that holds) at the reference grid's
    precision (:func:`~turntable_pin.design.calibrate.design_calibration`)."""
    from ..design.calibrate import design_calibration
    from ..report.requirement_figures import write_calibration_design_figures

    for option, given in (
        ("--effects", args.effects or args.effects_module),
        ("--from", args.from_data),
        ("--noise-arcsec", args.noise_arcsec is not None),
    ):
        if given:
            raise InputError(
                f"design --calibrate: {option} is for identify and --separate; a GyroWheel "
                "calibration design needs the table, its limits and -n only"
            )
    space = _space(args, effects=())
    result = design_calibration(
        space,
        _positions_count(args, space),
        accuracy_dph=args.accuracy_dph,
        min_efficiency=args.min_efficiency,
    )
    return _finish(result, args, write_calibration_design_figures)


def _run_separate_run(args: argparse.Namespace) -> int:
    """Calibration positions that tell two explanations of a run apart (``--separate A,B
    --run RUN.csv``: :func:`~turntable_pin.instrument.separate.design_run_separation`)."""
    from ..calibration.run import read_run
    from ..core.csv_table import write_csv_table
    from ..core.units import deg_to_rad
    from ..instrument.effects import run_catalogue
    from ..instrument.separate import design_run_separation
    from ..instrument.user_effects import load_run_effects_modules

    for option, given in (
        ("--effects", args.effects),
        ("--from", args.from_data),
        ("--amplitude", args.amplitude),
        ("--noise-arcsec", args.noise_arcsec is not None),
        ("--plots", args.plots),
    ):
        if given:
            raise InputError(
                f"design --separate --run: {option} is for orientation measurements; the run "
                "gives the amplitudes and the noise"
            )
    names = _pair(args)
    space = _space(args, effects=())
    count = _positions_count(args, space)
    run = read_run(args.run, deg_to_rad(args.latitude_deg), space.table)
    warn_ignored_columns(args, run, args.run)
    user = load_run_effects_modules(args.effects_module, run)
    result = design_run_separation(
        run, tuple(names), deg_to_rad(space.candidates_deg), count,
        seed=args.seed, catalogue=(*run_catalogue(space.table), *user),
    )  # fmt: skip
    out = {**result.to_dict(), "run": str(args.run)}
    if args.output is not None and result.separable:
        comment = (
            f"calibration positions separating {result.effects[0]} from {result.effects[1]} "
            f"(turntable-pin design --separate --run {args.run}; seed {result.seed})"
        )
        out["output"] = str(write_csv_table(args.output, result.columns(), comment=comment))
    if args.json:
        print_json(out)
        return 0
    print(result.report())
    if "output" in out:
        print(f"wrote {out['output']}")
    return 0
