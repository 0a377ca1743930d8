"""``rate-error``, ``requirement``, ``calibrate``: the GyroWheel calibration layer (section 2)."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
from pathlib import Path

from ..calibration.drift_fit import calibrate_read_run
from ..calibration.gyrowheel import GyroWheelModel
from ..calibration.positions import PositionSet, position_inputs
from ..calibration.rate_error import DEFINITIONS, rate_error
from ..calibration.requirement import orientation_requirement
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.exceptions import InputError
from ..core.units import deg_to_rad
from ..model.angles import ANGLE_NAMES, ANGLE_SYMBOLS
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from .common import (
    accuracy_dph,
    add_mount_option,
    add_table_options,
    bounded_float,
    input_path,
    latitude_deg,
    one_line_errors,
    position_scheme,
    print_json,
    table_from_args,
    warn_ignored_columns,
)

__all__ = ["register"]


def _add_setup_options(parser: argparse.ArgumentParser, *, positions: bool = True) -> None:
    if positions:
        parser.add_argument(
            "--positions", type=position_scheme, default="grid:30", metavar="SCHEME|FILE.csv",
            help="test positions: grid:STEP (every joint in 0, STEP, ... < 360 deg, every "
            "combination), grid:STEP1xSTEP2[xSTEP3] (one step per joint), or a CSV with one angle "
            "column per joint: phi1_deg .. phiN_deg (chain order) or <joint>_deg",
        )  # fmt: skip
    add_table_options(parser)
    parser.add_argument(
        "--latitude-deg", type=latitude_deg, default=DEFAULT_LATITUDE_DEG,
        help="latitude of the test site, degrees (the paper's: Harbin)",
    )  # fmt: skip


def _add_model_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--gyrowheel", type=input_path, metavar="FILE.yaml",
        help="drift coefficients {x: {DF, x, y, z, xx, zz, xy}, y: {...}} (default: Table 1)",
    )  # fmt: skip
    parser.add_argument(
        "--exact", action="store_true",
        help="exact rotation for dR instead of the small-angle matrix of eq. 7",
    )  # fmt: skip
    parser.add_argument(
        "--definition", choices=DEFINITIONS, default=DEFINITIONS[0],
        help="rate error: b1 - A beta2 - b2' (eq. 13 as printed) or b1 - A beta1 - b2'",
    )  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print one JSON object")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``rate-error``, ``requirement`` and ``calibrate`` subcommands to ``subparsers``."""
    r = subparsers.add_parser(
        "rate-error",
        description="Rate-sensing errors dwx, dwy (deg/h, eq. 14) of a multi-position calibration "
        "whose payload is off by (dpsi, dtheta, dgamma) at every position.",
    )
    one_line_errors(r)
    small = bounded_float(
        -MAX_ANGULAR_ERROR_DEG, MAX_ANGULAR_ERROR_DEG, "deg", why="a small orientation error"
    )
    for name in ANGLE_NAMES:
        r.add_argument(
            f"--{name}-deg", type=small, default=0.0, help=f"{name} at every position, degrees"
        )
    _add_setup_options(r)
    _add_model_options(r)
    r.set_defaults(func=run_rate_error)

    q = subparsers.add_parser(
        "requirement",
        description="Largest centred rectangles inside dwx <= w_m over (dpsi, dtheta) and "
        "dwy <= w_m over (dtheta, dgamma), sharing dtheta (the paper's planes, eqs. 15-16), and "
        "beside them the largest box whose every point meets w_m (all three angles at once: "
        "allocate's default limits); Figures 4 and 5 with --plots.",
    )
    one_line_errors(q)
    q.add_argument(
        "--accuracy-dph", type=accuracy_dph, default=0.01,
        help="required calibration accuracy w_m, deg/h",
    )  # fmt: skip
    _add_setup_options(q)
    _add_model_options(q)
    q.add_argument(
        "--plots",
        type=Path,
        metavar="DIR",
        help="write Figures 4 and 5 (PNG) here (default: no plots)",
    )
    from ..calibration.requirement import PROGRESS_DELAY_S

    q.add_argument("--quiet", action="store_true",
                   help=f"no progress report (by default a run longer than {PROGRESS_DELAY_S:g} "
                   "s reports its progress on stderr, unless --json)")  # fmt: skip
    q.set_defaults(func=run_requirement)
    _register_calibrate(subparsers)


def _register_calibrate(subparsers: argparse._SubParsersAction) -> None:
    c = subparsers.add_parser(
        "calibrate",
        description="Least-squares calibration of a run CSV (one angle column per joint: "
        "phi1_deg .. phiN_deg in chain order or <joint>_deg, phi1_deg, phi2_deg on the paper's "
        "table; out_x_dph, out_y_dph[, sigma_dph, time_s]): coefficients, standard errors, "
        "residuals per position.",
    )
    one_line_errors(c)
    from ..core.csv_table import ROW_RULE

    c.add_argument("data", type=input_path, metavar="RUN.csv",
                   help=f"the calibration run (a CSV; {ROW_RULE})")  # fmt: skip
    _add_setup_options(c, positions=False)
    add_mount_option(c)
    c.add_argument("--json", action="store_true", help="print one JSON object")
    c.add_argument(
        "--diagnose", action="store_true",
        help="is it the table or the instrument? test every candidate effect of the run (the "
        "table's errors and effects through eqs. 8-13; the instrument's tilt, heading, bias "
        "drift, temperature coefficient, earth-rate scale, g-squared terms) and name what is "
        "missing, verdict first",
    )  # fmt: skip
    c.add_argument(
        "--effects", action="append", default=[], metavar="A,B",
        help="fit the coefficients with these effects added and show the residuals before and "
        "after: run catalogue names (instrument_tilt, bias_drift, table:deps_x, ...) and inline "
        "terms (out_x~h2(phi1), out_y~poly2(time_s), dpsi~h1(phi2)); comma-separated, "
        "repeatable (default: none)",
    )  # fmt: skip
    c.add_argument(
        "--effects-module", action="append", default=[], type=input_path, metavar="FILE.py",
        help="a Python file defining run effects (subclasses of turntable_pin.instrument."
        "effects.RunEffect): they join the candidates of --diagnose and the names of --effects. "
        "The file is code that runs: it is imported and its methods called (give only files you "
        "trust); each effect is checked against its contract first "
        "(TURNTABLE_PIN_TRACEBACK=1 shows the traceback of an error inside it); repeatable "
        "(default: none)",
    )  # fmt: skip
    c.add_argument(
        "--until-explained",
        action="store_true",
        help="with --diagnose: name every effect the stepwise search accepts",
    )
    c.add_argument(
        "--keep-outliers",
        action="store_true",
        help="with --diagnose: keep every output (no outlier rule)",
    )
    c.add_argument(
        "--plots",
        type=Path,
        metavar="DIR",
        help="with --diagnose or --effects: residual plots (PNG) before and after (default: no "
        "plots)",
    )
    c.add_argument(
        "--report",
        type=Path,
        metavar="OUT.html",
        help="with --diagnose: one self-contained HTML page with the whole story (default: no "
        "report)",
    )
    c.set_defaults(func=run_calibrate)


def _table_keys(table) -> dict:
    """The table a report is of: its URDF, payload frame and joints (every table alike)."""
    return {
        "urdf": str(table.urdf_path),
        "payload_frame": table.payload_frame,
        "joints": list(table.joint_names),
    }


def _print_table(args: argparse.Namespace, table) -> None:
    """The line naming the table in a text report, when the user named one (``--urdf``)."""
    if args.urdf is not None:
        print(f"table {table.urdf_path.name}: joints {', '.join(table.joint_names)}")


def _gyrowheel(args: argparse.Namespace) -> GyroWheelModel:
    return GyroWheelModel.from_yaml(args.gyrowheel) if args.gyrowheel else GyroWheelModel.nominal()


def run_rate_error(args: argparse.Namespace) -> int:
    table = table_from_args(args)
    positions = PositionSet.parse(args.positions, table)
    inputs = position_inputs(positions, deg_to_rad(args.latitude_deg))
    result = rate_error(
        _gyrowheel(args), inputs,
        deg_to_rad(args.dpsi_deg), deg_to_rad(args.dtheta_deg), deg_to_rad(args.dgamma_deg),
        exact=args.exact, definition=args.definition,
    )  # fmt: skip
    report = {**result.to_dict(), **_table_keys(table)}
    if args.json:
        print_json(report)
        return 0
    _print_table(args, table)
    print(
        f"positions {report['positions']} ({report['n_positions']}), latitude "
        f"{report['latitude_deg']:g} deg, {'exact rotation' if args.exact else 'eq. 7 dR'}, "
        f"{args.definition.replace('_', ' ')}"
    )
    print(f"dwx = {report['dwx_dph']:.6g} deg/h")
    print(f"dwy = {report['dwy_dph']:.6g} deg/h")
    return 0


def run_requirement(args: argparse.Namespace) -> int:
    table = table_from_args(args)
    result = orientation_requirement(
        args.accuracy_dph, PositionSet.parse(args.positions, table), deg_to_rad(args.latitude_deg),
        gyrowheel=_gyrowheel(args), exact=args.exact, definition=args.definition,
        progress=not (args.quiet or args.json),
    )  # fmt: skip
    report = {**result.to_dict(), **_table_keys(table)}
    if args.plots:
        from ..report.requirement_figures import write_requirement_figures

        report["plots"] = [str(p) for p in write_requirement_figures(result, args.plots)]
    if args.json:
        print_json(report)
        return 0
    _print_table(args, table)
    print(
        f"accuracy {args.accuracy_dph:g} deg/h, positions {report['positions']} "
        f"({report['n_positions']}), latitude {report['latitude_deg']:g} deg, "
        f"{args.definition.replace('_', ' ')}"
    )
    for name in ANGLE_SYMBOLS:
        print(
            f"|d{name}| <= I_{name} = {report[f'I_{name}_deg']:.5f} deg "
            f"({report[f'I_{name}_arcsec']:.2f} arcsec)"
        )
    print(f"I_theta set by the {report['binding_plane']} plane")
    if any(r["capped"] for r in report["rectangles"]):
        print(
            "note: dw stays below w_m up to the 10-degree search limit along some angle; that "
            "limit is a cap (the small-angle model), not a requirement"
        )
    print(
        f"all three angles at their limits at once: dwx <= {report['box_dwx_dph']:.4g}, "
        f"dwy <= {report['box_dwy_dph']:.4g} deg/h"
    )
    box = report["box"]
    print(
        "the largest box that holds (largest volume; every orientation error in it meets "
        "w_m; allocate's default limits):"
    )
    for name in ANGLE_SYMBOLS:
        print(f"|d{name}| <= {box[f'I_{name}_deg']:.5f} deg ({box[f'I_{name}_arcsec']:.2f} arcsec)")
    print(
        f"its corners: dwx <= {box['dwx_dph']:.4g}, dwy <= {box['dwy_dph']:.4g} deg/h"
        + ("; a limit stopped at the 10-degree search cap" if any(box["capped"]) else "")
    )
    for path in report.get("plots", []):
        print(f"wrote {path}")
    return 0


def run_calibrate(args: argparse.Namespace) -> int:
    table = table_from_args(args)
    only = [(f"--{k.replace('_', '-')}", getattr(args, k)) for k in
            ("until_explained", "keep_outliers", "report")]  # fmt: skip
    if args.effects_module and not (args.diagnose or args.effects):
        raise InputError("--effects-module goes with --diagnose or --effects")
    if not args.diagnose:
        for option, value in only:
            if value:
                raise InputError(f"{option} goes with --diagnose")
        if args.plots and not args.effects:
            raise InputError("--plots goes with --diagnose or --effects")
    elif args.effects:
        raise InputError(
            "--diagnose names what is missing from the base model; --effects fits a model you "
            "choose: give one of them"
        )
    if args.diagnose:
        return _diagnose_run(args, table)
    if args.effects:
        return _fit_run_effects(args, table)
    from ..calibration.run import read_run

    run = read_run(args.data, deg_to_rad(args.latitude_deg), table)
    warn_ignored_columns(args, run, args.data)
    result = calibrate_read_run(run)
    if args.json:
        print_json({**result.to_dict(), **_table_keys(table)})
    else:
        print(result.report())
    return 0


def _user_run_effects(args: argparse.Namespace, run) -> tuple:
    """The run effects of ``--effects-module`` files, in the order given, checked on ``run``
    (names, and their contract on a probe and on the run) before any fit."""
    from ..instrument.user_effects import load_run_effects_modules

    return load_run_effects_modules(args.effects_module, run)


def _read_run(args: argparse.Namespace, table):
    from ..calibration.run import read_run, refuse_copied_rows

    run = read_run(args.data, deg_to_rad(args.latitude_deg), table)
    refuse_copied_rows(run)
    warn_ignored_columns(args, run, args.data)
    return run


def _diagnose_run(args: argparse.Namespace, table) -> int:
    from ..instrument.diagnosis import diagnose_run
    from ..instrument.effects import run_catalogue
    from ..report.diagnosis_text import diagnosis_lines
    from ..report.html_report import write_report
    from ..report.measurement_figures import write_diagnosis_plots

    run = _read_run(args, table)
    catalogue = (*run_catalogue(table), *_user_run_effects(args, run))
    diagnosis = diagnose_run(
        run, until_explained=args.until_explained, outliers=not args.keep_outliers,
        catalogue=catalogue,
    )  # fmt: skip
    out = {**diagnosis.to_dict(), **_table_keys(table)}
    if args.plots:
        out["plots"] = [str(p) for p in write_diagnosis_plots(diagnosis, args.plots)]
    if args.report:
        title = f"Calibration run {Path(args.data).name}: the table or the GyroWheel?"
        out["report"] = str(write_report(diagnosis, args.report, title=title))
    if args.json:
        print_json(out)
        return 0
    _print_table(args, table)
    print("\n".join(diagnosis_lines(out)))
    for path in [*out.get("plots", []), *([out["report"]] if "report" in out else [])]:
        print(f"wrote {path}")
    return 0


def _fit_run_effects(args: argparse.Namespace, table) -> int:
    from ..instrument.effects import resolve_run_effects
    from ..instrument.model import fit_run
    from ..instrument.residuals import run_residuals
    from ..measurement.residuals import analyse_residuals
    from ..report.measurement_figures import write_residual_plots

    run = _read_run(args, table)
    names = [n for group in args.effects for n in group.split(",") if n.strip()]
    effects = resolve_run_effects(names, table, _user_run_effects(args, run))
    for effect in effects:
        missing = effect.missing_columns(run)
        if missing:
            raise InputError(
                f"effect '{effect.name}' needs the column(s) {run.missing_columns_words(missing)}",
                path=args.data,
            )
    after = fit_run(run, effects)
    before = fit_run(run, (), context=after.model.context)
    before = before.with_noise_variance(after.result.noise_variance)
    out = {"run": str(args.data), **after.to_dict(), **_table_keys(table)}
    out["before"] = {k: before.result.to_dict()[k] for k in
                     ("rms_dph", "chi2_reduced", "p_value", "rank", "n_params")}  # fmt: skip
    analysis = analyse_residuals(run_residuals(after))
    out["where_it_fails"] = analysis.to_dict()
    if args.plots:
        sets = [run_residuals(before), run_residuals(after)]
        out["plots"] = [str(p) for p in write_residual_plots(sets, args.plots)]
    if args.json:
        print_json(out)
        return 0
    _print_table(args, table)
    sigma = "from the sigma_dph column" if out["sigma_source"] == "column" else "estimated"
    print(f"{args.data}: {run.n_positions} positions, noise {sigma}")
    for label, summary in (("before: base", out["before"]),
                           ("after: base + " + " + ".join(after.effect_names), out)):  # fmt: skip
        p = summary["p_value"]
        print(f"  {label:44s} rms {summary['rms_dph']:.4g} deg/h   chi2_reduced "
              f"{summary['chi2_reduced']:.3f}   rank {summary['rank']}/{summary['n_params']}"
              + (f"   p {p:.3g}" if p is not None else ""))  # fmt: skip
    print("effect parameters (value +- std):")
    for name, entry in out["params"].items():
        if "." in name:
            std = "not determined alone" if entry["std"] is None else f"+- {entry['std']:.3g}"
            print(f"  {name:40s} {entry['value']:12.5g} {std} {entry['unit']}")
    for axis, terms in out["coefficients_dph"].items():
        print(f"axis {axis}: " + ", ".join(f"D{axis}{k} = {v['value']:.6g}"
                                           for k, v in terms.items()))  # fmt: skip
    undetermined = after.result.undetermined_combinations()
    if undetermined:
        print("not determined by this run: " + "; ".join(undetermined[:6]))
    print(f"outputs beyond 3 sigma after: {len(analysis.failing)}")
    for path in out.get("plots", []):
        print(f"wrote {path}")
    return 0
