"""Argument types and output helpers shared by the subcommands."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
import json
import math
import os
import sys
from pathlib import Path

import numpy as np

from ..core.exceptions import SEED_LIMIT, InputError, one_line
from ..core.notebook import jsonable
from ..model.errors import MAX_ANGULAR_ERROR_DEG, parse_error_value

__all__ = [
    "input_path",
    "OUTPUT_OPTIONS",
    "accuracy_dph",
    "add_error_options",
    "add_mount_option",
    "add_table_options",
    "check_outputs",
    "effect_list",
    "effect_options",
    "effect_spec",
    "FOLDER_OUTPUTS",
    "NamesFiles",
    "position_scheme",
    "bounded_float",
    "error_values_from_args",
    "finite_float",
    "latitude_deg",
    "one_line_errors",
    "positive_float",
    "non_negative_int",
    "one_or_each",
    "own_effects_words",
    "length_errors_words",
    "positive_int",
    "print_json",
    "seed",
    "table_from_args",
    "refuse_inputs_as_outputs",
    "warn_ignored_columns",
]


def finite_float(text: str) -> float:
    """argparse type: a finite float (NaN and inf are refused with a clear message)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got '{text}'")
    return value


def one_or_each(text: str, parse, names: tuple[str, ...]):
    """``text`` as one value (``parse`` of it) or one per name, comma-separated (a tuple)."""
    parts = text.split(",")
    if len(parts) == 1:
        return parse(text)
    if len(parts) != len(names):
        count = {2: "two", 3: "three"}.get(len(names), str(len(names)))
        raise argparse.ArgumentTypeError(
            f"expected one value or {count} ({','.join(names)}), got {len(parts)}: '{text}'"
        )
    return tuple(parse(p.strip()) for p in parts)


def _whole_number(text: str, low: int) -> int:
    """``text`` as a whole number >= ``low``, or an argparse error saying so."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
    if value < low:
        raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got '{text}'")
    return value


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    return _whole_number(text, 1)


def non_negative_int(text: str) -> int:
    """argparse type: an integer >= 0."""
    return _whole_number(text, 0)


def positive_float(text: str) -> float:
    """argparse type: a finite number > 0."""
    value = finite_float(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"expected a number > 0, got '{text}'")
    return value


def latitude_deg(text: str) -> float:
    """argparse type: a latitude in degrees, within +-``MAX_LATITUDE_DEG`` (90)."""
    from ..calibration.site import MAX_LATITUDE_DEG

    value = finite_float(text)
    if abs(value) > MAX_LATITUDE_DEG:
        raise argparse.ArgumentTypeError(
            f"latitude must be within +-{MAX_LATITUDE_DEG:g} degrees, got '{text}'"
        )
    return value


def accuracy_dph(text: str) -> float:
    """argparse type: a required calibration accuracy in ``ACCURACY_RANGE_DPH`` (deg/h)."""
    from ..calibration.requirement import ACCURACY_RANGE_DPH

    value = positive_float(text)
    low, high = ACCURACY_RANGE_DPH
    if not low <= value <= high:
        raise argparse.ArgumentTypeError(
            f"expected an accuracy in [{low:g}, {high:g}] deg/h, got '{text}'"
        )
    return value


def seed(text: str) -> int:
    """argparse type: a random seed, a whole number 0 <= seed < 2**63."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"expected a whole number 0 <= seed < 2**63, got '{text}'"
        ) from None
    if not 0 <= value < SEED_LIMIT:
        raise argparse.ArgumentTypeError(f"expected a whole number 0 <= seed < 2**63, got '{text}'")
    return value


def bounded_float(
    low: float, high: float, unit: str = "", *, low_open: bool = False, why: str = ""
):
    """argparse type: a finite float in ``[low, high]`` (``(low, high]`` if ``low_open``);
    ``unit`` and ``why`` (a few words on the range) go into the message of a refused value."""
    left = "(" if low_open else "["
    suffix = f" {unit}" if unit else ""
    reason = f" ({why})" if why else ""

    def parse(text: str) -> float:
        value = finite_float(text)
        if value > high or value < low or (low_open and value == low):
            raise argparse.ArgumentTypeError(
                f"expected a number in {left}{low:g}, {high:g}]{suffix}{reason}, got '{text}'"
            )
        return value

    parse.__name__ = "number"
    return parse


def one_line_errors(parser: argparse.ArgumentParser) -> argparse.ArgumentParser:
    """Make ``parser`` report a bad argument in one line naming the option (no usage block;
    ``--help`` still shows it), exit status 2."""

    def error(message: str):
        parser.exit(2, f"{parser.prog}: error: {one_line(message)} (see {parser.prog} --help)\n")

    parser.error = error  # type: ignore[method-assign]
    return parser


def input_path(value: str) -> Path:
    """argparse type of a file a command reads: :func:`~turntable_pin.core.resources.bundled_path`
    (the path as given when something is there, else the bundled file of that name)."""
    from ..core.resources import bundled_path

    return bundled_path(value)


def add_table_options(parser: argparse.ArgumentParser) -> None:
    """``--urdf FILE`` and ``--payload-frame NAME``: the table (default: the paper's)."""
    parser.add_argument(
        "--urdf", type=input_path, metavar="FILE.urdf",
        help="the turntable's URDF: 1 to 3 revolute joints in a chain (default: the paper's); "
        "a bundled table by name: altaz_mount, german_equatorial_mount, two_axis_vertical_outer, "
        "three_axis_imu_table, single_axis_rate_table",
    )  # fmt: skip
    parser.add_argument(
        "--payload-frame",
        metavar="NAME",
        help="the payload frame of the URDF (default: the only leaf of its chain)",
    )


def add_mount_option(parser: argparse.ArgumentParser) -> None:
    """``--mount altaz|equatorial|none``: what the table is, overriding its URDF's declaration."""
    from ..model.mount_declaration import MOUNT_KINDS, NO_MOUNT

    parser.add_argument(
        "--mount", choices=(*MOUNT_KINDS, NO_MOUNT),
        help="what the table is: a telescope mount (altaz, equatorial: TPOINT terms and flexure "
        "candidates) or none (a turntable); default: what its URDF declares "
        '(<turntable_pin mount="altaz"/>), a turntable when it declares nothing',
    )  # fmt: skip


def length_errors_words() -> str:
    """The errors that are lengths, in words, from the error definitions: the paper's table's
    (``deta``) and every joint's of a URDF table (``<joint>.offset_a``, ...)."""
    from ..model.generic_table import generic_length_errors
    from ..model.paper_table import PAPER_LAYOUT

    return ", ".join((*PAPER_LAYOUT.length_names, *generic_length_errors()))


def own_effects_words() -> str:
    """Where a table's own effects are named: ``effects --urdf`` (the paper's effect names are
    only its table's; any table has the per-joint kinds ``<kind>@<joint>`` and more)."""
    from ..measurement.catalogue import PER_JOINT_EFFECTS

    kinds = ", ".join(f"{kind}@<joint>" for kind in PER_JOINT_EFFECTS)
    return (
        f"a table given by --urdf has its own effects ({kinds}, ...): "
        "'turntable-pin effects --urdf FILE.urdf' lists them with their parameters"
    )


def add_error_options(parser: argparse.ArgumentParser) -> None:
    """``--error NAME=VALUE`` (repeatable), ``--errors FILE.yaml`` and ``--urdf FILE``."""
    from ..model.errors import DEFAULT_ANGLE_UNIT, DEFAULT_LENGTH_UNIT

    units = {"arcsec": "arc seconds", "mm": "millimetres"}
    parser.add_argument(
        "--error",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help=f"one turntable error: {units.get(DEFAULT_ANGLE_UNIT, DEFAULT_ANGLE_UNIT)} for "
        f"angles, {units.get(DEFAULT_LENGTH_UNIT, DEFAULT_LENGTH_UNIT)} for lengths "
        f"({length_errors_words()}); a unit suffix such as dphi_y1_arcmin=0.1 or deta_m=2e-4 is "
        "also understood; repeatable (default: none, every error zero)",
    )
    parser.add_argument(
        "--errors", type=input_path, metavar="FILE.yaml",
        help="YAML file of turntable errors; --error overrides its entries one by one "
        "(default: none, every error zero)",
    )  # fmt: skip
    add_table_options(parser)


def table_from_args(args: argparse.Namespace):
    """The table of ``--urdf``, ``--payload-frame`` and ``--mount``
    (:func:`~turntable_pin.measurement.checked_table.checked_table`)."""
    from ..measurement.checked_table import checked_table

    return checked_table(
        args.urdf, getattr(args, "payload_frame", None), getattr(args, "mount", None)
    )


def error_values_from_args(
    table, args: argparse.Namespace, max_angle_deg: float = MAX_ANGULAR_ERROR_DEG
) -> np.ndarray:
    """The error vector (rad, m) of ``--errors FILE.yaml`` overridden entry by entry by
    ``--error NAME=VALUE`` (each name once) in ``table``'s names: arcsec and mm unless a unit
    suffix says otherwise, angles up to ``max_angle_deg``, degrees."""
    values = (
        table.errors_from_yaml(args.errors, max_angle_deg=max_angle_deg)
        if args.errors
        else table.values()
    )
    given: dict[str, str] = {}
    for item in args.error:
        if "=" not in item:
            raise InputError(f"--error '{item}': expected NAME=VALUE")
        key, _, text = item.partition("=")
        try:
            name, value = parse_error_value(
                key, text, names=table.parameter_names, length_names=table.length_names,
                max_angle_deg=max_angle_deg,
            )  # fmt: skip
        except InputError as exc:
            raise InputError(f"--error '{item}': {exc.detail}") from None
        if name in given:
            raise InputError(f"--error '{item}': {name} is given twice (also '{given[name]}')")
        given[name] = item
        values[table.parameter_names.index(name)] = value
    return values


def warn_ignored_columns(args: argparse.Namespace, data, path) -> None:
    """One warning line on stderr naming the columns of ``path`` that ``data`` left out as not
    numbers: no column is dropped without a word."""
    from ..core.csv_table import ignored_columns_words

    if data.ignored_columns:
        words = ignored_columns_words(data.ignored_columns)
        print(f"turntable-pin {args.command}: warning: {path}: {words}", file=sys.stderr)


def print_json(payload: dict) -> None:
    """Print one JSON object (numpy values converted, NaN/inf as null)."""
    json.dump(jsonable(payload), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")


OUTPUT_OPTIONS: tuple[str, ...] = ("output", "plots", "write_urdf", "truth", "report")
"""Destinations of the options through which a command writes (a file, or a folder of files)."""
FOLDER_OUTPUTS: tuple[str, ...] = ("plots",)
"""The output options of :data:`OUTPUT_OPTIONS` that name a folder of files."""


class NamesFiles(str):
    """An option's text (a ``str``) with ``input_files``, the files it names (``--effects
    base_tilt,mine.yaml`` names ``mine.yaml``), for :func:`refuse_inputs_as_outputs`."""

    input_files: tuple[Path, ...] = ()

    @classmethod
    def of(cls, text: str, files) -> NamesFiles:
        named = cls(text)
        named.input_files = tuple(files)
        return named


def effect_list(text: str) -> NamesFiles:
    """argparse type of ``--effects A,B``, ``--separate A,B``: names, inline terms, effect files."""
    from ..measurement.user_effects import effect_files_named

    return NamesFiles.of(text, effect_files_named(text))


def effect_spec(text: str) -> NamesFiles:
    """argparse type of ``NAME:P=V,...``; ``NAME`` may be an effect file (an input)."""
    from ..measurement.user_effects import effect_files_named

    return NamesFiles.of(text, effect_files_named(text.partition(":")[0]))


def effect_options(texts, option: str, table, user=()) -> dict[str, dict[str, float]]:
    """``NAME:P=V,...`` options (``option``) as ``{effect: {parameter: value}}``, each effect at
    most once; names of ``table``'s catalogue, of the effects ``user`` or inline terms."""
    from ..measurement.effects import parse_effect_spec
    from ..measurement.user_effects import resolve_effects

    effects: dict[str, dict[str, float]] = {}
    for text in texts:
        try:
            name, params = parse_effect_spec(text, lambda n: resolve_effects([n], table, user)[0])
        except InputError as exc:
            raise InputError(f"{option} '{text}': {exc}") from None
        if name in effects:
            raise InputError(f"{option} '{text}': effect '{name}' is given twice")
        effects[name] = params
    return effects


def position_scheme(text: str) -> NamesFiles:
    """argparse type of ``--positions SCHEME|FILE.csv`` (a scheme starts with ``grid``)."""
    spec = text.strip()
    return NamesFiles.of(text, () if spec.startswith("grid") else (Path(spec),))


def _same_path(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def _input_paths(args: argparse.Namespace) -> list[tuple[str, Path]]:
    """``(option, path)`` of every input file: path options that are no output, and the files
    named inside an option's text (:class:`NamesFiles`)."""
    inputs: list[tuple[str, Path]] = []
    for dest, value in vars(args).items():
        if dest in OUTPUT_OPTIONS:
            continue
        for item in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(item, Path):
                inputs.append((dest, item))
            elif isinstance(item, NamesFiles):
                inputs += [(dest, path) for path in item.input_files]
    return inputs


def refuse_inputs_as_outputs(args: argparse.Namespace) -> None:
    """Refuse an output that is one of the command's inputs (a path option, or a file named in
    an option's text; links count) or another of its outputs: :class:`InputError` naming both."""
    inputs = _input_paths(args)
    for dest in OUTPUT_OPTIONS:
        output = getattr(args, dest, None)
        if not isinstance(output, Path):
            continue
        for name, item in inputs:
            if output.resolve() == item.resolve() or _same_path(output, item):
                option = "the data file" if name == "data" else f"--{name.replace('_', '-')}"
                flag = dest.replace("_", "-")
                raise InputError(
                    f"refusing to write --{flag} {output}: it is {option} {item}, an input of "
                    "this command (choose another output name)"
                )
    outputs = [(d, getattr(args, d, None)) for d in OUTPUT_OPTIONS]
    outputs = [(d, v) for d, v in outputs if isinstance(v, Path)]
    for i, (dest, output) in enumerate(outputs):
        for other, path in outputs[i + 1 :]:
            if output.resolve() == path.resolve() or _same_path(output, path):
                first, second = (f"--{d.replace('_', '-')}" for d in (dest, other))
                raise InputError(
                    f"refusing to write {first} {output} and {second} {path}: "
                    "they are one file (choose two output names)"
                )


def check_outputs(args: argparse.Namespace) -> None:
    """Check every output before any is written (a refused output never follows one that
    replaced a file): none is an input or another output, and each can be written
    (:func:`~turntable_pin.core.files.output_target`). :class:`InputError` names the option."""
    from ..core.files import output_target

    refuse_inputs_as_outputs(args)
    for dest in OUTPUT_OPTIONS:
        output = getattr(args, dest, None)
        if not isinstance(output, Path):
            continue
        try:
            output_target(output, folder=dest in FOLDER_OUTPUTS)
        except InputError as exc:
            raise InputError(f"--{dest.replace('_', '-')} {exc}") from None
