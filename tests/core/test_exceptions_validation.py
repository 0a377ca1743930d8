"""The shared checks of core.exceptions: one-line messages whatever the input quoted, and the
seed rule every random process follows."""

import numpy as np
import pytest

from turntable_pin.core.exceptions import (
    SEED_LIMIT,
    InfeasibleError,
    InputError,
    check_seed,
    one_line,
)


def test_messages_stay_on_one_line_whatever_they_quote():
    error = InputError("expected a number, found 'a\rb\nc\x0bd\u2028e'", path="f.csv", row=3)
    assert str(error) == "f.csv, row 3: expected a number, found 'a\\rb\\nc\\x0bd\\u2028e'"
    assert len(str(InfeasibleError("x\ny")).splitlines()) == 1
    assert one_line("plain text, é ok") == "plain text, é ok"


def test_a_yaml_line_is_named_as_a_line():
    assert str(InputError("key 'a' is given twice", path="e.yaml", line=4)) == (
        "e.yaml, line 4: key 'a' is given twice"
    )


@pytest.mark.parametrize("seed", [0, 1, 2**63 - 1, np.int64(7), np.uint64(2**63 - 1)])
def test_whole_seeds_in_range_are_taken(seed):
    assert check_seed(seed) == int(seed)


@pytest.mark.parametrize("seed", [-1, 2**63, 2**64, 1.0, 0.5, "3", None, True, float("nan")])
def test_other_seeds_are_refused(seed):
    with pytest.raises(InputError, match=r"seed must be a whole number 0 <= seed < 2\*\*63"):
        check_seed(seed)
    assert SEED_LIMIT == 2**63
