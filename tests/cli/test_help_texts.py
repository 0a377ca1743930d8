"""Every option of every command has help text and shows its default (issue 30)."""

import argparse
import re

import pytest

from turntable_pin.cli import COMMANDS, build_parser, shows_default


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    (sub,) = [a for a in parser._actions if isinstance(a, argparse._SubParsersAction)]
    return dict(sub.choices)


def _options(parser: argparse.ArgumentParser):
    for action in parser._actions:
        if not isinstance(action, (argparse._HelpAction, argparse._VersionAction)):
            yield action


def _shown(parser: argparse.ArgumentParser, action: argparse.Action) -> str:
    """The option's help as ``--help`` prints it (defaults expanded), in one line."""
    return " ".join(parser._get_formatter()._expand_help(action).split())


def test_every_command_is_walked():
    assert set(_subparsers()) == set(COMMANDS)


@pytest.mark.parametrize("command", list(COMMANDS))
def test_every_option_has_help_and_shows_its_default(command):
    parser = _subparsers()[command]
    problems = []
    for action in _options(parser):
        name = "/".join(action.option_strings) or action.dest
        text = _shown(parser, action)
        if not text:
            problems.append(f"{name}: no help text")
            continue
        flag = action.nargs == 0  # --json, --quiet: off unless given
        if not action.option_strings or action.required or flag:
            continue
        if shows_default(action):
            # the default written from the option's own value, and no hand-written copy of it
            expected = f"(default: {action.default})"
            written = action.help or ""
            copies = ("(default", f"default {action.default}", f"({action.default})")
            if not text.endswith(expected) or any(c in written for c in copies):
                problems.append(f"{name}: expected one '{expected}' at the end, got {text!r}")
        elif not re.search(r"\bdefault\b", text, re.IGNORECASE):
            problems.append(f"{name}: default {action.default!r} not said in {text!r}")
    assert not problems, "\n".join(problems)


def _help_of(command: str, dest: str) -> str:
    parser = _subparsers()[command]
    (action,) = [a for a in _options(parser) if a.dest == dest]
    return _shown(parser, action)


@pytest.mark.parametrize("name", ["turntable", "three_axis_imu_table", "altaz_mount"])
def test_error_help_says_millimetres_for_every_length_error_of_a_bundled_table(name):
    from turntable_pin.cli.common import input_path
    from turntable_pin.model.paper_table import table_of

    table = table_of(input_path(name), None, None)
    lengths = table.length_names
    assert lengths  # every bundled table has offsets
    text = _help_of("orientation", "error")
    said = text.split("millimetres for lengths (", 1)[1].split(")", 1)[0].split(", ")
    for length in lengths:
        generic = length if "." not in length else "<joint>." + length.split(".", 1)[1]
        assert generic in said, (length, text)


@pytest.mark.parametrize("command", ["simulate", "fit"])
def test_the_effects_help_points_to_effects_urdf_for_a_tables_own_effects(command):
    parser = _subparsers()[command]
    page = " ".join(parser.format_help().split())
    assert "turntable-pin effects --urdf FILE.urdf" in page
    if command == "simulate":  # the paper's names are said to be the paper's table's
        assert "The paper's table's effects: outer_encoder_harmonics," in page
        assert "wobble_harmonics@<joint>" in page
