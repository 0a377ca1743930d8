"""core.words: a library text names the Python argument, or the flag while the CLI speaks."""

from __future__ import annotations

import shlex

from hypothesis import given
from hypothesis import strategies as st

from turntable_pin.cli import COMMANDS, build_parser
from turntable_pin.cli.words import CLI_WORDS
from turntable_pin.core.words import CommandLineWords, argument, command, speaking

WORDS = CommandLineWords("prog", {"from_data": "--from"})


def test_an_argument_is_its_python_name_outside_the_command_line():
    assert argument("limits_deg") == "limits_deg"


def test_an_argument_is_its_flag_while_the_command_line_speaks():
    with speaking(WORDS):
        assert argument("limits_deg") == "--limits-deg"
        assert argument("from_data") == "--from"
    assert argument("from_data") == "from_data"  # the words end with the block


def test_a_command_renders_as_a_python_call_and_as_a_shell_command():
    step = command("design", "a b.csv", separate="x,y", from_data="run.csv", urdf=None, run=True)
    assert str(step) == "design('a b.csv', separate='x,y', from_data='run.csv', run=True)"
    with speaking(WORDS):
        assert str(step) == "prog design 'a b.csv' --separate x,y --from run.csv --run"


@given(st.lists(st.text(min_size=1, max_size=12), min_size=1, max_size=4))
def test_a_shell_command_reads_back_into_its_words(values):
    step = command("fit", *values, effects=",".join(values))
    with speaking(WORDS):
        assert shlex.split(str(step)) == ["prog", "fit", *values, "--effects", ",".join(values)]


def test_every_flag_the_command_line_maps_exists_in_some_command():
    options, parsers = set(), [build_parser(name) for name in COMMANDS]
    while parsers:  # the top parsers and their commands' parsers
        for action in parsers.pop()._actions:
            options.update(action.option_strings)
            if isinstance(action.choices, dict):
                parsers += list(action.choices.values())
    assert set(CLI_WORDS.flags.values()) <= options
