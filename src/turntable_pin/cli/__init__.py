"""The ``turntable-pin`` command line: thin subcommands over the library.

Each subcommand is a module of this package with a ``register(subparsers)`` function and a line
in :data:`COMMANDS`; only the module of the command being run is imported (``--help`` imports
none). Every :class:`TurntablePinError` becomes a one-line message on stderr and exit status 2
(a traceback only with ``TURNTABLE_PIN_TRACEBACK=1``); SIGINT and SIGTERM end every command within
a second with status 130 / 143 and one line, leaving no helper process and no temporary folder.
"""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
import importlib
import os
import signal
import sys

from ..core.exceptions import TurntablePinError
from ..core.interrupts import (
    Interrupted,
    exit_on_signal,
    first_signal,
    install_handlers,
    interruption_handled,
    run_cleanups,
    signal_name,
)
from ..core.words import speaking
from .words import CLI_WORDS

__all__ = ["COMMANDS", "HelpFormatter", "build_parser", "main", "shows_default"]

COMMANDS: dict[str, tuple[str, str]] = {
    "orientation": ("orientation", "orientation error dR of the payload at one position"),
    "urdf": ("orientation", "write the URDF with the errors in its joint placements"),
    "rate-error": (
        "calibration",
        "GyroWheel rate-sensing errors caused by an orientation error (eqs. 7-14)",
    ),
    "requirement": (
        "calibration",
        "orientation requirement I_psi, I_theta, I_gamma for an accuracy (eqs. 15-16)",
    ),
    "calibrate": (
        "calibration",
        "fit the 2 x 7 drift coefficients to a calibration run (eqs. 5-6)",
    ),
    "allocate": (
        "allocation",
        "allocate the angular turntable errors to meet orientation limits",
    ),
    "montecarlo": (
        "allocation",
        "allocate, then check the bounds with random turntables on the exact chain",
    ),
    "simulate": ("measurement", "simulate orientation measurements with hidden effects"),
    "fit": ("measurement", "fit the error model (plus effects) to measurements"),
    "diagnose": ("measurement", "which catalogued physical effect is missing"),
    "report": ("measurement", "one self-contained HTML page with the whole story"),
    "import-tpoint": ("tpoint", "a TPOINT pointing run (telescope mount) as a measurement CSV"),
    "design": ("design", "which positions to measure next: identify, separate, calibrate"),
    "effects": ("effects", "list the candidate effects of a table, the catalogue and yours"),
    "view": ("viewer", "show the turntable and its (magnified) errors in a meshcat 3-D viewer"),
    "snapshot": ("viewer", "render the 3-D view of the setup to a PNG (headless Chromium)"),
}
"""Command name -> (module of this package that registers it, one-line help)."""


def shows_default(action: argparse.Action) -> bool:
    """Whether ``--help`` writes ``(default: X)`` after the option's help, ``X`` its default value:
    an optional option that takes a value and has one (not ``None``, not an empty list). The
    others say in their own words what happens without them (``default: ...``)."""
    default = action.default
    return (
        bool(action.option_strings)
        and not action.required
        and action.nargs != 0
        and default is not None
        and default is not argparse.SUPPRESS
        and not (isinstance(default, (list, tuple)) and not default)
    )


class HelpFormatter(argparse.HelpFormatter):
    """Every command's help: each option's text, then ``(default: X)`` from the option's own
    default (:func:`shows_default`), so a default is written once, from the code's value."""

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        return f"{text} (default: %(default)s)" if shows_default(action) else text


class _Subcommands:
    """The ``subparsers`` a command module registers into: adds the one-line help of COMMANDS
    and the :class:`HelpFormatter`."""

    def __init__(self, subparsers: argparse._SubParsersAction) -> None:
        self._subparsers = subparsers

    def add_parser(self, name: str, **kwargs) -> argparse.ArgumentParser:
        kwargs.setdefault("formatter_class", HelpFormatter)
        return self._subparsers.add_parser(name, help=COMMANDS[name][1], **kwargs)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The argument parser; the full options of ``command``'s module (all when ``None``)."""
    modules = {module for module, _ in COMMANDS.values()}
    return _parser(modules if command is None else {COMMANDS[command][0]})


def _parser(wanted: set[str]) -> argparse.ArgumentParser:
    """The parser with the options of the commands of the modules ``wanted``; others listed."""
    parser = argparse.ArgumentParser(
        prog="turntable-pin",
        description="Error analysis, error allocation and measurement diagnosis of a turntable "
        "for inertial-instrument calibration, from its URDF (one to three revolute axes, --urdf; "
        "the paper's two-axis table is bundled and the default).",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
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


def _version() -> str:
    """The installed version (from the package's metadata; no heavy import)."""
    from .. import __version__

    return __version__


def _command(argv: list[str]) -> str | None:
    """The subcommand named in ``argv``, if it is a known one (``--help`` names none)."""
    for arg in argv:
        if not arg.startswith("-"):
            return arg if arg in COMMANDS else None
    return None


def main(argv: list[str] | None = None) -> int:
    """Entry point of the console script; returns the exit status. Without ``argv`` (the
    console script) an interrupted command ends the process at once after its cleanup
    (``os._exit``); with ``argv`` (from Python) the status is returned and the previous signal
    handlers restored."""
    console = argv is None
    restore = None
    command = None
    try:
        restore = install_handlers()  # first, before the command's (heavy) imports
        argv = sys.argv[1:] if argv is None else list(argv)
        command = _command(argv)
        # --help lists every command from the table alone; an unknown command: argparse's message.
        parser = _parser(set()) if command is None else build_parser(command)
        args = parser.parse_args(argv)
        args.argv = tuple(argv)  # the command line as given (a simulation records it)
        command = args.command
        from .common import check_outputs  # every output checked before any is written

        check_outputs(args)
        with speaking(CLI_WORDS):  # the library's texts name flags and shell commands
            status = int(args.func(args) or 0)
        if first_signal() is not None:  # an interruption that some library swallowed
            raise Interrupted(first_signal())
        return status
    except BaseException as exc:
        # After a signal, whatever comes out is the interruption: some libraries swallow it and
        # fail later in its wake (trimesh half-imported), which must not look like an error.
        if isinstance(exc, KeyboardInterrupt) or first_signal() is not None:
            return _interrupted(exc, command, console)
        if isinstance(exc, TurntablePinError):
            _traceback_on_request(exc)
            print(f"turntable-pin {command}: error: {exc}", file=sys.stderr)
            return 2
        if isinstance(exc, BrokenPipeError):  # output piped into e.g. `head`: not our error
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
            return 0
        raise
    finally:
        if console:  # cleanup done: a late signal just ends the process
            exit_on_signal(f"turntable-pin {command}" if command else "turntable-pin")
        elif restore is not None:
            restore()


def _traceback_on_request(exc: BaseException) -> None:
    """With ``TURNTABLE_PIN_TRACEBACK=1``, the traceback of ``exc`` on stderr (an error raised
    inside the user's code: theirs first, as its cause); nothing otherwise."""
    from ..core.user_code import show_traceback

    if show_traceback():
        import traceback

        traceback.print_exception(exc, file=sys.stderr)


def _interrupted(exc: BaseException, command: str | None, console: bool) -> int:
    """Finish the cleanups an interruption cut short, say so in one line; the exit status."""
    interruption_handled()
    signum = first_signal() or getattr(exc, "signum", signal.SIGINT)
    run_cleanups()
    if console:  # the last resort: no helper process of this command outlives it
        from ..viewer.browser import kill_descendant_processes

        kill_descendant_processes()
    name = f"turntable-pin {command}" if command else "turntable-pin"
    print(f"{name}: interrupted ({signal_name(signum)})", file=sys.stderr)
    if console:
        # Everything is cleaned up; the interpreter's own teardown of pinocchio, meshcat, ...
        # would take a few tenths of a second more, which an interrupted program does not owe.
        # The atexit functions (say, a coverage tool's) still run.
        import atexit

        # multiprocessing's exit function joins the pool's queue feeder threads; the workers
        # are killed, so a feeder blocked writing to them would wait for ever (seen 3 in 40).
        util = sys.modules.get("multiprocessing.util")
        if util is not None:
            atexit.unregister(util._exit_function)
        atexit._run_exitfuncs()
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):
                pass
        os._exit(128 + signum)
    return 128 + signum


if __name__ == "__main__":
    sys.exit(main())
