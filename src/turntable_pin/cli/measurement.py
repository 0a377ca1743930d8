"""``simulate``, ``fit``, ``diagnose`` and ``report``: measurements against the error model."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
import shlex
from pathlib import Path

from ..core.exceptions import InputError
from ..core.sizes import MIN_GRID_STEP_DEG
from ..measurement.data import MAX_TIME_S, MIN_SIGMA_ARCSEC, read_measurements
from ..measurement.effects import EFFECT_NAMES, parse_effect_spec
from ..model.angles import ANGLE_NAMES
from ..model.errors import MAX_ORIENTATION_ERROR_DEG
from .common import (
    add_error_options,
    add_mount_option,
    add_table_options,
    bounded_float,
    effect_list,
    effect_options,
    effect_spec,
    error_values_from_args,
    input_path,
    non_negative_int,
    one_line_errors,
    one_or_each,
    own_effects_words,
    positive_float,
    positive_int,
    print_json,
    seed,
    table_from_args,
    warn_ignored_columns,
)

__all__ = ["register"]

# The fitting, plotting and report modules (scipy, matplotlib) are imported inside the commands
# that need them, so that every other subcommand starts fast.
ORDERS = ("grid", "random")
APPROACHES = ("random", "motion", "positive")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``simulate``, ``fit``, ``diagnose`` and ``report`` to ``subparsers``."""
    _register_simulate(subparsers)
    _register_fit(subparsers)
    _register_diagnose_and_report(subparsers)


def _register_simulate(subparsers: argparse._SubParsersAction) -> None:
    s = subparsers.add_parser(
        "simulate",
        description="Simulate a measurement run (the CSV described in docs/measurements.md): "
        "turntable errors, catalogued effects with their parameters, a position schedule, noise, "
        "time stamps and approach directions; the seed and the truth go into comment lines. "
        f"The paper's table's effects: {', '.join(EFFECT_NAMES)}; {own_effects_words()}.",
    )
    one_line_errors(s)
    add_error_options(s)
    add_mount_option(s)
    s.add_argument(
        "--effect",
        action="append",
        default=[],
        type=effect_spec,
        metavar="NAME:P=V[,P=V...]",
        help="a hidden effect and its parameters in user units (arcsec, arcsec/g, arcsec/h), "
        "e.g. inner_encoder_harmonics:c1=3,s2=-2 on the paper's table; "
        f"{own_effects_words()}; repeatable (default: none)",
    )
    _add_catalogue_option(s)
    _add_schedule_options(s)
    s.add_argument("--no-sigma", action="store_true", help="leave out the sigma_arcsec column")
    s.add_argument(
        "--hide-truth",
        action="store_true",
        help="record only seed, noise and schedule, not the errors and effects (blind rehearsal)",
    )
    s.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.csv",
                   help="the measurement CSV to write")  # fmt: skip
    _add_run_options(s)
    s.set_defaults(
        func=run_simulate,
        orientation_defaults={d: s.get_default(d) for d in ORIENTATION_ONLY_OPTIONS},
    )


def _add_schedule_options(s: argparse.ArgumentParser) -> None:
    """The noise and position schedule options of ``simulate``."""
    step = bounded_float(
        MIN_GRID_STEP_DEG, 360.0, "deg", why="a finer grid exceeds every size limit"
    )
    start = bounded_float(-3240.0, 3240.0, "deg")
    s.add_argument(
        "--noise-arcsec",
        type=_noise_arcsec,
        default=1.0,
        help="1-sigma noise, arcsec; three comma-separated values give dpsi,dtheta,dgamma their "
        "own",
    )
    s.add_argument(
        "--noise-spread",
        type=bounded_float(1.0, 100.0),
        default=1.0,
        metavar="F",
        help="uneven noise: each row's sigma drawn log-uniform in [sigma/F, sigma*F] (seeded)",
    )
    s.add_argument("--seed", type=seed, default=0, help="random seed, recorded in the file")
    s.add_argument(
        "--not-measured",
        type=_angle_list,
        default=(),
        metavar="A,B",
        help="angles left empty at every position (dpsi, dtheta, dgamma; default: none, all "
        "measured): "
        "'dgamma' makes a pointing run, whose dpsi is then the boresight's own component",
    )
    for k, which in ((1, "first axis"), (2, "second axis"), (3, "third axis (3-axis tables)")):
        s.add_argument(f"--phi{k}-step-deg", type=step, default=30.0,
                       help=f"grid step of phi{k}, the {which}, degrees")  # fmt: skip
    for k in (1, 2, 3):
        s.add_argument(f"--phi{k}-start-deg", type=start, default=0.0,
                       help=f"first grid angle of phi{k}, degrees; a sweep holds phi{k} "
                       "here")  # fmt: skip
    design = s.add_mutually_exclusive_group()
    design.add_argument("--positions", type=input_path, metavar="FILE.csv",
                        help="measure these positions in the file's order (columns phi1_deg.. "
                        "or <joint>_deg, optional dir1.. and time_s; default: the grid of "
                        "--phiK-step-deg)")  # fmt: skip
    design.add_argument("--sweep", metavar="AXES",
                        help="single-axis sweeps, one after the other: phi1,phi2 sweeps phi1 "
                        "over its grid with phi2 held, then phi2 with phi1 held (default: "
                        "no sweep, the whole grid)")  # fmt: skip
    design.add_argument("--random-positions", type=positive_int, metavar="N",
                        help="N positions uniform over every joint's turn (seeded; default: "
                        "the grid)")  # fmt: skip
    s.add_argument("--order", choices=ORDERS, default=ORDERS[0],
                   help="the order the grid is measured in: grid (phi1 the outer loop, the last "
                   "joint the inner) or random (the grid shuffled, seeded)")  # fmt: skip
    s.add_argument("--repeats", type=positive_int, default=1, metavar="R",
                   help="measure the whole schedule R times over, one after the other (each "
                   "measurement at its own time_s)")  # fmt: skip
    s.add_argument("--passes", type=positive_int, default=0, metavar="K",
                   help="forward then backward over the positions, K times; approach "
                   "directions follow the pass (+1 forward, -1 backward); 0: one pass")  # fmt: skip
    s.add_argument(
        "--dwell-s",
        type=bounded_float(0.0, MAX_TIME_S, "s", low_open=True),
        default=60.0,
        help="time per position, seconds (the time_s column)",
    )
    s.add_argument("--approach", choices=APPROACHES, default=None,
                   help="the approach direction of each position (dir1..): random, motion (the "
                   "direction the joint moved in) or positive (default: random; motion with "
                   "--passes)")  # fmt: skip


def _register_fit(subparsers: argparse._SubParsersAction) -> None:
    f = subparsers.add_parser(
        "fit",
        description="Weighted least squares of the base error model plus the chosen effects; "
        "rank, determined combinations with standard errors, rms, chi2_reduced, p-value; "
        "before (base) and after (with the effects), and where the fit fails.",
    )
    one_line_errors(f)
    _add_data_options(f)
    f.add_argument("--effects", action="append", default=[], type=effect_list, metavar="A,B",
                   help="effects to add to the base: catalogue names ('turntable-pin effects "
                   "--urdf FILE.urdf' lists a table's), effect files (.yaml) and "
                   "inline terms (dphi_z2~h3(phi2), dpsi~poly1(temperature_c), "
                   "dphi_y1~sign(dir1)); comma-separated, repeatable (default: none, the base "
                   "model alone)")  # fmt: skip
    f.add_argument(
        "--effects-module",
        action="append",
        default=[],
        type=Path,
        metavar="FILE.py",
        help="a Python file defining Effect subclasses; their names join --effects. The file is "
        "code that runs: it is imported and its methods called (give only files you trust); "
        "repeatable (default: none)",
    )
    f.add_argument(
        "--write-urdf",
        type=Path,
        metavar="OUT.urdf",
        help="write the URDF with the fitted errors in its joint placements (combinations the "
        "data cannot separate are split by the minimum-norm rule, stated in the output; "
        "default: no URDF)",
    )
    f.add_argument("--plots", type=Path, metavar="DIR",
                   help="write residual plots (PNG) here (default: no plots)")  # fmt: skip
    f.add_argument("--k-sigma", type=positive_float, default=3.0, metavar="K",
                   help="a position fails where a residual exceeds K sigma (K > 0)")  # fmt: skip
    f.set_defaults(func=run_fit)


def _register_diagnose_and_report(subparsers: argparse._SubParsersAction) -> None:
    from ..report.diagnosis_text import decision_rule_words

    d = subparsers.add_parser(
        "diagnose",
        description="Test every catalogued effect against the base fit by BIC "
        f"({decision_rule_words()}), rank them, name the missing effect, its equivalent "
        "alternatives, and whether structure remains that nothing in the catalogue explains.",
    )
    one_line_errors(d)
    _add_data_options(d)
    _add_until_explained_option(d)
    _add_outlier_option(d)
    d.add_argument("--plots", type=Path, metavar="DIR",
                   help="write residual plots (PNG) here (default: no plots)")  # fmt: skip
    _add_catalogue_option(d)
    d.set_defaults(func=run_diagnose)

    r = subparsers.add_parser(
        "report",
        description="Data, base fit, where it fails, diagnosis, fit with the missing effect, "
        "parameters; plots embedded.",
    )
    one_line_errors(r)
    _add_data_argument(r)
    add_table_options(r)
    add_mount_option(r)
    _add_ignore_sigma_option(r)
    _add_until_explained_option(r)
    _add_outlier_option(r)
    r.add_argument("-o", "--output", type=Path, required=True, metavar="report.html",
                   help="the HTML page to write")  # fmt: skip
    _add_catalogue_option(r)
    r.set_defaults(func=run_report)


RUN_ONLY_OPTIONS: tuple[str, ...] = (
    "noise_dph", "latitude_deg", "gyrowheel", "temperature", "outliers", "outlier_dph", "truth",
)  # fmt: skip
"""The ``simulate`` options of a calibration run (``--run``) alone."""
ORIENTATION_ONLY_OPTIONS: tuple[str, ...] = (
    "noise_arcsec", "noise_spread", "phi1_step_deg", "phi2_step_deg", "phi3_step_deg",
    "phi1_start_deg", "phi2_start_deg", "phi3_start_deg", "sweep", "order", "repeats", "passes",
    "approach",
)  # fmt: skip
"""The ``simulate`` options of orientation measurements alone (refused with ``--run``)."""
RUN_POSITIONS = "grid:30"
"""The positions of ``simulate --run`` without ``--positions``."""
RUN_NOISE_DPH = 0.002
"""The output noise of ``simulate --run`` without ``--noise-dph``, deg/h."""


def _add_run_options(s: argparse.ArgumentParser) -> None:
    """The options of ``simulate --run``: a GyroWheel calibration run (``docs/measurements.md``,
    "GyroWheel calibration runs") instead of orientation measurements."""
    from ..calibration.site import DEFAULT_LATITUDE_DEG
    from .common import latitude_deg

    g = s.add_argument_group(
        "calibration run (--run)",
        "with --run, simulate a GyroWheel calibration run: the outputs out_x_dph, out_y_dph at "
        "each position through the exact chain of the table's errors and effects, with the "
        "instrument effects of --effect (instrument_tilt:mx,my and instrument_heading:mz "
        "arcsec; bias_drift:x,y deg/h/h; temperature_coefficient:x,y deg/h/degC; "
        "earth_rate_scale:x,y ppm; "
        "g_squared_terms:x_xz,x_yz,y_xz,y_yz deg/h/g^2); --positions takes a scheme "
        f"(grid:STEP, grid:S1xS2; default {RUN_POSITIONS}) or a CSV of angles",
    )
    g.add_argument("--run", action="store_true",
                   help="simulate a GyroWheel calibration run (what calibrate reads)")  # fmt: skip
    g.add_argument("--truth", type=Path, metavar="OUT.yaml",
                   help="also write the truth (and this command) as YAML: the key to a blind run "
                   "made with --hide-truth (default: no truth file)")  # fmt: skip
    g.add_argument("--noise-dph", type=_noise_dph, metavar="S|SX,SY",
                   help="1-sigma output noise, deg/h: one value for both channels or x,y "
                   f"(default: {RUN_NOISE_DPH:g})")  # fmt: skip
    g.add_argument("--latitude-deg", type=latitude_deg,
                   help=f"site latitude, degrees (default {DEFAULT_LATITUDE_DEG})")  # fmt: skip
    g.add_argument("--gyrowheel", type=input_path, metavar="FILE.yaml",
                   help="the true drift coefficients (default: paper Table 1)")  # fmt: skip
    g.add_argument("--temperature", type=_temperature, metavar="START,RAMP_PER_H,SWING,PERIOD_H",
                   help="a temperature_c column: START degC + RAMP_PER_H degC/h * t + SWING degC "
                   "* sin(2 pi t / PERIOD_H h) (default: no temperature column)")  # fmt: skip
    g.add_argument("--outliers", type=non_negative_int, metavar="N",
                   help="N rows (seeded) get a gross error on one channel (default: "
                   "none)")  # fmt: skip
    g.add_argument("--outlier-dph", type=positive_float, metavar="D",
                   help="size of an outlier, deg/h (default 30 sigma of its channel)")  # fmt: skip


def _noise_dph(text: str) -> float | tuple[float, float]:
    """argparse type of ``--noise-dph``: one number >= 0 or two (x, y), deg/h."""
    from ..calibration.run import MAX_RUN_OUTPUT_DPH

    return one_or_each(text, bounded_float(0.0, MAX_RUN_OUTPUT_DPH / 100.0, "deg/h"), ("x", "y"))


def _temperature(text: str) -> tuple[float, float, float, float]:
    """argparse type of ``--temperature``: four numbers START,RAMP_PER_H,SWING,PERIOD_H."""
    parts = text.split(",")
    if len(parts) != 4:
        raise argparse.ArgumentTypeError(
            f"expected START,RAMP_PER_H,SWING,PERIOD_H (degC, degC/h, degC, h), got '{text}'"
        )
    start = bounded_float(-100.0, 200.0, "degC")(parts[0].strip())
    ramp = bounded_float(-100.0, 100.0, "degC/h")(parts[1].strip())
    swing = bounded_float(-100.0, 100.0, "degC")(parts[2].strip())
    period = bounded_float(0.0, 1e4, "h", low_open=True)(parts[3].strip())
    return start, ramp, swing, period


def _noise_arcsec(text: str) -> float | tuple[float, float, float]:
    """argparse type of ``--noise-arcsec``: the simulator's noise range (imported when used); one
    value, or three comma-separated ones (dpsi, dtheta, dgamma)."""
    from ..measurement.simulation import MAX_NOISE_ARCSEC

    parse = bounded_float(MIN_SIGMA_ARCSEC, MAX_NOISE_ARCSEC, "arcsec")
    return one_or_each(text, parse, ANGLE_NAMES)


def _sweep_axes(text: str, table) -> tuple[str, ...]:
    """``--sweep``: comma-separated axes (``phiK`` or the table's joint names) as ``phiK``."""
    names = _generic_joints(table) or ()
    n_joints = len(names) if names else 2
    known = {f"phi{k}": f"phi{k}" for k in range(1, n_joints + 1)}
    known.update({name: f"phi{k}" for k, name in enumerate(names, start=1)})
    out = []
    for part in text.split(","):
        axis = part.strip()
        if axis not in known:
            raise InputError(
                f"--sweep '{text}': unknown axis '{axis}'; the table's axes are {', '.join(known)}"
            )
        if known[axis] in out:
            raise InputError(f"--sweep '{text}': axis '{axis}' is swept twice")
        out.append(known[axis])
    return tuple(out)


def _add_until_explained_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--until-explained",
        action="store_true",
        help="name every effect the stepwise search accepts, each significant on top of those "
        "before it (by default the verdict names the first one and lists the others as also "
        "significant)",
    )


def _add_outlier_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--keep-outliers",
        action="store_true",
        help="turn the outlier rule off: every measured angle enters the fits (by default gross "
        "outliers are found by a stated robust rule, left out and listed)",
    )


def _add_catalogue_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--catalogue", action="append", default=[], type=input_path, metavar="FILE",
                   help="your effects (a .yaml effect file or a .py module) join the candidates; "
                   "repeatable. A .py module is code that runs: it is imported and its methods "
                   "called (give only files you trust; default: the catalogue alone)")  # fmt: skip


def _user_catalogue(args: argparse.Namespace, table=None):
    """The table's catalogue plus the effects of ``--catalogue`` (and installed ones), or
    ``None`` when there are none besides the catalogue."""
    from ..measurement.catalogue import catalogue
    from ..measurement.user_effects import load_catalogue

    user = load_catalogue(args.catalogue, table)
    return (*catalogue(table), *user) if user else None


def _add_data_options(p: argparse.ArgumentParser) -> None:
    _add_data_argument(p)
    add_table_options(p)
    add_mount_option(p)
    p.add_argument("--json", action="store_true", help="print one JSON object")
    _add_ignore_sigma_option(p)


def _add_data_argument(p: argparse.ArgumentParser) -> None:
    from ..core.csv_table import ROW_RULE

    p.add_argument("data", type=input_path, metavar="DATA.csv",
                   help=f"the measurements (a CSV, docs/measurements.md; {ROW_RULE})")  # fmt: skip


def _add_ignore_sigma_option(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--ignore-sigma",
        action="store_true",
        help="estimate the noise from the fit even if the file has sigma_arcsec (by default a "
        "sigma column is used)",
    )


def _generic_joints(table) -> tuple[str, ...] | None:
    """The joints the table's data files name (angle columns ``phiK_deg`` or ``<joint>_deg``),
    or ``None`` when its layout names the angles (the paper's ``phi1_deg, phi2_deg``)."""
    from ..measurement.table import measured_table

    measured = measured_table(table)
    return measured.data_joint_names or None


def _read(args: argparse.Namespace, table=None):
    """The measurements of ``args.data`` for ``table`` (angle columns ``phiK_deg`` or
    ``<joint>_deg`` of its joints; the paper's ``phi1_deg, phi2_deg`` when ``None``)."""
    data = read_measurements(args.data, _generic_joints(table))
    warn_ignored_columns(args, data, args.data)
    return data.without_sigma() if args.ignore_sigma else data


def _option(dest: str) -> str:
    return "--" + dest.replace("_", "-")


def run_simulate(args: argparse.Namespace) -> int:
    if args.run:
        return run_simulate_run(args)
    given = [d for d in RUN_ONLY_OPTIONS if getattr(args, d) is not None]
    if given:
        raise InputError(
            f"{_option(given[0])} is an option of a calibration run; add --run, or leave it out"
        )
    return _run_simulate_orientation(args)


def run_simulate_run(args: argparse.Namespace) -> int:
    """``simulate --run``: a GyroWheel calibration run CSV (``calibrate`` reads it)."""
    from ..calibration.gyrowheel import GyroWheelModel
    from ..calibration.positions import PositionSet
    from ..calibration.site import DEFAULT_LATITUDE_DEG
    from ..core.units import deg_to_rad
    from ..instrument.simulate import TemperatureProfile, simulate_calibration_run
    from ..measurement.user_effects import inline_effect, load_catalogue

    # A default given explicitly changes nothing and passes.
    defaults = args.orientation_defaults
    refused = [d for d in ORIENTATION_ONLY_OPTIONS if getattr(args, d) != defaults[d]]
    if refused:
        raise InputError(
            f"{_option(refused[0])} is an option of orientation measurements, not of a "
            "calibration run (--run); leave it out"
        )
    table = table_from_args(args)
    user = load_catalogue(args.catalogue, table)
    table_effects, instrument = _run_effects(args.effect, table, user)
    user = (*user, *(inline_effect(name, table) for name in table_effects if "~" in name))
    if args.random_positions:
        positions = PositionSet.random(args.random_positions, table, args.seed)
    else:
        positions = PositionSet.parse(
            RUN_POSITIONS if args.positions is None else str(args.positions), table
        )
    noise = RUN_NOISE_DPH if args.noise_dph is None else args.noise_dph
    latitude = DEFAULT_LATITUDE_DEG if args.latitude_deg is None else args.latitude_deg
    gyrowheel = GyroWheelModel.from_yaml(args.gyrowheel) if args.gyrowheel else None
    temperature = TemperatureProfile(*args.temperature) if args.temperature else None
    errors = error_values_from_args(table, args)
    sim = simulate_calibration_run(
        positions,
        deg_to_rad(latitude),
        gyrowheel=gyrowheel,
        table_errors_rad=dict(zip(table.parameter_names, errors, strict=True)),
        table_effects=table_effects,
        instrument=instrument,
        noise_dph=noise,
        dwell_s=args.dwell_s,
        temperature_c=temperature,
        outliers=args.outliers or 0,
        outlier_dph=args.outlier_dph,
        seed=args.seed,
        catalogue=user,
    )
    path = sim.write_csv(args.output, hide_truth=args.hide_truth, with_sigma=not args.no_sigma)
    print(f"wrote {path}: {sim.n_positions} positions, seed {sim.seed}")
    if args.truth is not None:
        truth = sim.write_truth(args.truth, data=Path(path).name, command=_command_line(args))
        print(f"wrote {truth}")
    return 0


def _run_effects(texts: list[str], table, user) -> tuple[dict, dict]:
    """The ``--effect`` options of ``simulate --run``: ``(table effects, instrument effects)``,
    each ``{effect: {parameter: value}}`` with each effect at most once."""
    from ..instrument.simulate import SIMULATED_INSTRUMENT_EFFECTS
    from ..measurement.user_effects import resolve_effects

    table_effects: dict[str, dict[str, float]] = {}
    instrument: dict[str, dict[str, float]] = {}

    def resolve(name: str):
        if name.strip() in SIMULATED_INSTRUMENT_EFFECTS:
            return SIMULATED_INSTRUMENT_EFFECTS[name.strip()]
        try:
            return resolve_effects([name], table, user)[0]
        except InputError as exc:
            raise InputError(
                f"{exc.detail}; instrument effects: {', '.join(SIMULATED_INSTRUMENT_EFFECTS)}"
            ) from None

    for text in texts:
        try:
            name, params = parse_effect_spec(text, resolve)
        except InputError as exc:
            raise InputError(f"--effect '{text}': {exc.detail}") from None
        into = instrument if name in SIMULATED_INSTRUMENT_EFFECTS else table_effects
        if name in into:
            raise InputError(f"--effect '{text}': effect '{name}' is given twice")
        into[name] = params
    return table_effects, instrument


def _command_line(args: argparse.Namespace) -> str:
    """The command that made the data, for the truth file (``--truth`` is no part of it)."""
    argv = list(getattr(args, "argv", ()))
    if "--truth" in argv:
        del argv[argv.index("--truth") : argv.index("--truth") + 2]
    argv = [a for a in argv if not a.startswith("--truth=")]
    return "turntable-pin " + shlex.join(argv) if argv else ""


def _run_simulate_orientation(args: argparse.Namespace) -> int:
    from ..measurement.simulation import MAX_NOISE_ARCSEC, Schedule, simulate_measurements
    from ..measurement.user_effects import inline_effect, load_catalogue

    table = table_from_args(args)
    joints = _generic_joints(table)
    user = load_catalogue(args.catalogue, table)
    effects = effect_options(args.effect, "--effect", table, user)
    user = (*user, *(inline_effect(name, table) for name in effects if "~" in name))
    design = _position_design(args, table, joints)
    if args.noise_spread != 1:
        noise = args.noise_arcsec if isinstance(args.noise_arcsec, tuple) else (args.noise_arcsec,)
        top = max(noise) * args.noise_spread
        if top > MAX_NOISE_ARCSEC or min(noise) / args.noise_spread < MIN_SIGMA_ARCSEC:
            raise InputError(
                f"--noise-spread {args.noise_spread:g}: with --noise-arcsec "
                f"{','.join(f'{v:g}' for v in noise)} the row sigmas would leave "
                f"[{MIN_SIGMA_ARCSEC:g}, {MAX_NOISE_ARCSEC:g}] arcsec"
            )
    schedule = Schedule(
        *(getattr(args, f"phi{k}_step_deg") for k in (1, 2, 3)),
        starts_deg=tuple(getattr(args, f"phi{k}_start_deg") for k in (1, 2, 3)),
        order=args.order,
        repeats=args.repeats,
        dwell_s=args.dwell_s,
        approach=args.approach,
        passes=args.passes,
        **design,
    )
    n_joints = len(table.joint_names)
    if schedule.duration_s(n_joints) > MAX_TIME_S:
        raise InputError(
            f"--dwell-s {args.dwell_s:g}: the run would last "
            f"{schedule.duration_s(n_joints):.7g} s, more than {MAX_TIME_S:.7g} s (a year)"
        )
    sim = simulate_measurements(
        error_values_from_args(table, args, MAX_ORIENTATION_ERROR_DEG),
        effects,
        schedule=schedule,
        noise_arcsec=args.noise_arcsec,
        seed=args.seed,
        turntable=table,
        catalogue=user,
        noise_spread=args.noise_spread,
        not_measured=args.not_measured,
    )
    path = sim.write_csv(args.output, with_sigma=not args.no_sigma, hide_truth=args.hide_truth)
    print(f"wrote {path}: {sim.data.n_positions} positions, seed {sim.seed}")
    return 0


def _position_design(args: argparse.Namespace, table, joints) -> dict:
    """The positions of ``--positions``, ``--sweep`` or ``--random-positions`` as
    :class:`~turntable_pin.measurement.simulation.Schedule` arguments (``{}``: the grid)."""
    from ..measurement.simulation import read_positions

    design = {}
    if args.positions is not None:
        design = read_positions(args.positions, joints)
        given = [f"dir{k}" for k, d in enumerate(design["positions_dirs"], start=1) if d]
        for option, value in (("--repeats", args.repeats > 1), ("--passes", args.passes)):
            if value and design["positions_time_s"] is not None:
                raise InputError(
                    f"{option}: {args.positions} gives time_s, so each of its rows is one "
                    f"measurement; leave out {option} or the time_s column"
                )
        if args.passes and given:
            raise InputError(
                f"--passes: {args.positions} gives {given[0]}, but the passes set the approach "
                f"directions (+1 forward, -1 backward); leave out --passes or the {given[0]} column"
            )
    elif args.sweep is not None:
        design = {"sweep": _sweep_axes(args.sweep, table)}
    elif args.random_positions:
        design = {"random_positions": args.random_positions}
    if design and args.order != "grid":
        raise InputError(
            "--order random shuffles a grid; --positions, --sweep and --random-positions are "
            "measured in their own order"
        )
    return design


def _angle_list(text: str) -> tuple[str, ...]:
    """``dgamma`` or ``dpsi,dgamma``: measured angles by name (argparse type)."""
    names = tuple(a.strip() for a in text.split(",") if a.strip())
    unknown = [a for a in names if a not in ANGLE_NAMES]
    if unknown or not names:
        raise argparse.ArgumentTypeError(
            f"'{text}': expected angles among {', '.join(ANGLE_NAMES)}, comma-separated"
        )
    return names


def _fit_line(label: str, summary: dict) -> str:
    p = summary["p_value"]
    return (
        f"  {label:40s} rms {summary['rms_arcsec']:8.3f} arcsec   chi2_reduced "
        f"{summary['chi2_reduced']:8.3f}   rank {summary['rank']}/{summary['n_params']}"
        + (f"   p {p:.3g}" if p is not None else "")
    )


def run_fit(args: argparse.Namespace) -> int:
    from ..measurement.fit import fit_orientation, refuse_repeated_shapes
    from ..measurement.residuals import analyse_residuals, orientation_residuals
    from ..measurement.user_effects import load_effects_modules, resolve_effects
    from ..report.measurement_figures import write_residual_plots

    table = table_from_args(args)
    data = _read(args, table)
    modules = load_effects_modules(args.effects_module, table)
    effects = resolve_effects(args.effects, table, modules)
    refuse_repeated_shapes(data, effects, turntable=table)
    after = fit_orientation(data, effects, turntable=table)
    before = fit_orientation(data, turntable=table) if effects else after
    # With sigma estimated, both fits are judged with the noise of the fuller model.
    before = before.with_noise_variance(after.result.noise_variance)
    analysis = analyse_residuals(orientation_residuals(after), args.k_sigma)
    plots = []
    if args.plots:
        sets = [orientation_residuals(before)] + ([orientation_residuals(after)] if effects else [])
        plots = [str(p) for p in write_residual_plots(sets, args.plots, args.k_sigma)]
    out = after.to_dict()
    out["before"] = {k: before.to_dict()[k] for k in ("rms_arcsec", "chi2_reduced", "p_value",
                                                     "rank", "n_params")}  # fmt: skip
    out["where_it_fails"] = analysis.to_dict(per_position=True)
    out["plots"] = plots
    if args.write_urdf:
        from ..measurement.identified import write_identified_urdf

        out["identified_urdf"] = write_identified_urdf(after, args.write_urdf, args.urdf)
    if args.json:
        print_json(out)
        return 0
    print(f"{args.data}: {data.n_positions} positions, sigma {out['sigma_source']} "
          f"({out['sigma_arcsec']:.3g} arcsec)")  # fmt: skip
    if effects:
        print(_fit_line("before: base", out["before"]))
    print(_fit_line("fit: " + " + ".join(("base", *after.effect_names)), out))
    print("determined combinations (value +- std):")
    for c in after.result.combinations():
        print(f"  {c['name']:55s} {c['value']:10.3f} +- {c['std']:.3f} {c['unit']}")
    und = after.result.undetermined_combinations()
    if und:
        print("not determined by these data: " + "; ".join(und))
    if out["unobserved_combinations"]:
        print("not observed because cells are empty (angles not measured): "
              + "; ".join(out["unobserved_combinations"]))  # fmt: skip
    if "pointing_terms" in out:
        _print_pointing_terms(out["pointing_terms"])
    print(f"positions beyond {args.k_sigma:g} sigma: {len(analysis.failing)}")
    for f in analysis.failing[:10]:
        where = " ".join(f"phi{k} {f[f'phi{k}_deg']:g}" for k in range(1, data.n_joints + 1))
        print(
            f"  row {f['row']}: {where} deg, "
            f"{f['component']} {f['residual_arcsec']:+.2f} arcsec ({f['sigmas']:+.1f} sigma)"
        )
    for p in plots:
        print(f"wrote {p}")
    if args.write_urdf:
        written = out["identified_urdf"]
        print(f"wrote {written['path']}: {written['rule']}")
    return 0


def _print_pointing_terms(block: dict) -> None:
    """The ``TPOINT terms`` block of ``fit`` on a telescope mount."""
    where = (
        f", latitude {block['latitude_deg']:.4g} deg" if block["latitude_deg"] is not None else ""
    )
    print(f"TPOINT terms ({block['mount']} mount{where}; {block['convention']}):")
    for t in block["terms"]:
        std = f"+- {t['std']:.3f}" if t["std"] is not None else "(not determined)"
        print(f"  {t['name']:5s} {t['value']:12.3f} {std} {t['unit']:8s} {t['formula']}")
    print(f"  {block['note']}")


def _diagnosis(args: argparse.Namespace):
    """The diagnosis ``diagnose`` and ``report`` make of their arguments."""
    from ..measurement.diagnosis import diagnose_measurements

    table = table_from_args(args)
    return diagnose_measurements(
        _read(args, table),
        until_explained=args.until_explained,
        catalogue=_user_catalogue(args, table),
        turntable=table,
        outliers=not args.keep_outliers,
    )


def run_diagnose(args: argparse.Namespace) -> int:
    from ..report.diagnosis_text import diagnosis_lines
    from ..report.measurement_figures import write_diagnosis_plots

    diagnosis = _diagnosis(args)
    out = diagnosis.to_dict()
    if args.plots:
        out["plots"] = [str(p) for p in write_diagnosis_plots(diagnosis, args.plots)]
    if args.json:
        print_json(out)
        return 0
    print("\n".join(diagnosis_lines(out, data=str(args.data))))
    for p in out.get("plots", []):
        print(f"wrote {p}")
    return 0


def run_report(args: argparse.Namespace) -> int:
    from ..report.html_report import write_report

    diagnosis = _diagnosis(args)
    path = write_report(diagnosis, args.output, title=f"Diagnosis of {args.data.name}")
    print(f"wrote {path}")
    return 0
