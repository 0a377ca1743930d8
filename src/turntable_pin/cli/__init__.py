"""The ``turntable-pin`` command line: thin subcommands over the library.

Each subcommand lives in a module of this package with a ``register(subparsers)`` function; adding
one is a line in :data:`COMMANDS` (its module and one-line help) and the module. Only the module of
the command being run is imported (``turntable-pin --help`` imports none), so start-up pays for
nothing but what the command uses. Every :class:`TurntablePinError` becomes a one-line message on
stderr and exit status 2, never a traceback.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..core.exceptions import TurntablePinError

__all__ = ["COMMANDS", "build_parser", "main"]

COMMANDS: dict[str, tuple[str, str]] = {
    "orientation": ("orientation", "orientation error dR of the payload at one position"),
    "urdf": ("orientation", "write the URDF with the errors in its joint placements"),
    "rate-error": ("calibration",
        "GyroWheel rate-sensing errors caused by an orientation error (eqs. 7-14)"),
    "requirement": ("calibration",
        "orientation requirement I_psi, I_theta, I_gamma for an accuracy (eqs. 15-16)"),
    "calibrate": ("calibration",
        "fit the 2 x 7 drift coefficients to a calibration run (eqs. 5-6)"),
    "allocate": ("allocation",
        "allocate the eight angular turntable errors to meet orientation limits"),
    "montecarlo": ("allocation",
        "allocate, then check the bounds with random turntables on the exact chain"),
    "simulate": ("measurement", "simulate orientation measurements with hidden effects"),
    "fit": ("measurement", "fit the error model (plus effects) to measurements"),
    "diagnose": ("measurement", "which catalogued physical effect is missing"),
    "report": ("measurement", "one self-contained HTML page with the whole story"),
    "view": ("viewer", "show the turntable and its (magnified) errors in a meshcat 3-D viewer"),
    "snapshot": ("viewer", "render the 3-D view of the setup to a PNG (headless Chromium)"),
}
"""Command name -> (module of this package that registers it, one-line help)."""


class _Subcommands:
    """The ``subparsers`` a command module registers into: adds the one-line help of COMMANDS."""

    def __init__(self, subparsers: argparse._SubParsersAction) -> None:
        self._subparsers = subparsers

    def add_parser(self, name: str, **kwargs) -> argparse.ArgumentParser:
        return self._subparsers.add_parser(name, help=COMMANDS[name][1], **kwargs)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; the full options of ``command``'s module (all when ``None``)."""
    modules = {module for module, _ in COMMANDS.values()}
    return _parser(modules if command is None else {COMMANDS[command][0]})


def _parser(wanted: set[str]) -> argparse.ArgumentParser:
    """The parser with the options of the commands of the modules ``wanted``; others listed."""
    parser = argparse.ArgumentParser(
        prog="turntable-pin",
        description="Error analysis, error allocation and measurement diagnosis of a two-axis "
        "turntable for inertial-instrument calibration (Pinocchio URDF model).",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND")
    subparsers.required = True
    registrar = _Subcommands(subparsers)
    registered: set[str] = set()
    for name, (module, text) in COMMANDS.items():
        if module in wanted:
            if module not in registered:
                importlib.import_module(f"{__name__}.{module}").register(registrar)
                registered.add(module)
        else:  # listed with its help; its options are read only when it is the command
            subparsers.add_parser(name, help=text, add_help=False)
    return parser


def _command(argv: list[str]) -> str | None:
    """The subcommand named in ``argv``, if it is a known one (``--help`` names none)."""
    for arg in argv:
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    command = _command(argv)
    # --help lists every command from the table alone; an unknown command gets argparse's message.
    parser = _parser(set()) if command is None else build_parser(command)
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
