"""Argument types and output helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..model.errors import TurntableErrors, parse_error_value
from ..model.turntable import TurntableModel

__all__ = [
    "add_error_options",
    "errors_from_args",
    "finite_float",
    "model_from_args",
    "positive_int",
    "print_json",
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


def positive_int(text: str) -> int:
    """argparse type: an integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 1, got '{text}'")
    return value


def add_error_options(parser: argparse.ArgumentParser) -> None:
    """``--error NAME=VALUE`` (repeatable), ``--errors FILE.yaml`` and ``--urdf FILE``."""
    parser.add_argument(
        "--error",
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="one turntable error: arc seconds for angles, millimetres for deta "
        "(a unit suffix such as dphi_y1_arcmin=0.1 or deta_m=2e-4 is also understood); repeatable",
    )
    parser.add_argument(
        "--errors", type=Path, metavar="FILE.yaml", help="YAML file of turntable errors"
    )
    parser.add_argument(
        "--urdf", type=Path, metavar="FILE.urdf", help="nominal turntable URDF (default: bundled)"
    )


def errors_from_args(args: argparse.Namespace) -> TurntableErrors:
    """The error set of ``--errors`` overridden entry by entry by ``--error``."""
    base = TurntableErrors.from_yaml(args.errors) if args.errors else TurntableErrors.zero()
    values = base.as_dict()
    for item in args.error:
        if "=" not in item:
            raise InputError(f"--error '{item}': expected NAME=VALUE")
        key, _, text = item.partition("=")
        name, value = parse_error_value(key, text)
        values[name] = value
    return TurntableErrors(**values)


def model_from_args(args: argparse.Namespace) -> TurntableModel:
    """The :class:`TurntableModel` of ``--urdf`` with the errors of the arguments."""
    return TurntableModel(errors_from_args(args), urdf_path=args.urdf)


def _jsonable(value):
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return _jsonable(value.tolist())
    if isinstance(value, (np.floating, float)):
        value = float(value)
        return value if math.isfinite(value) else None
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.bool_):
        return bool(value)
    if isinstance(value, Path):
        return str(value)
    return value


def print_json(payload: dict) -> None:
    """Print one JSON object (numpy values converted, NaN/inf as null)."""
    json.dump(_jsonable(payload), sys.stdout, indent=2, allow_nan=False)
    sys.stdout.write("\n")
