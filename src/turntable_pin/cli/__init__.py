"""The ``turntable-pin`` command line: thin subcommands over the library.

Each subcommand lives in its own module with a ``register(subparsers)`` function; adding one is a
new module and a line in :data:`COMMAND_MODULES`. Every :class:`TurntablePinError` becomes a
one-line message on stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..core.exceptions import TurntablePinError

COMMAND_MODULES: tuple[str, ...] = (
    "orientation",
    "calibration",
    "allocation",
    "measurement",
    "viewer",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="turntable-pin",
        description="Error analysis, error allocation and measurement diagnosis of a two-axis "
        "turntable for inertial-instrument calibration (Pinocchio URDF model).",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(f"{__name__}.{name}").register(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except TurntablePinError as exc:
        print(f"turntable-pin {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: not an error of ours
        import os

        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt:
        print(f"turntable-pin {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
