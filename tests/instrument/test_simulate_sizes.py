"""A simulated calibration run checks its size before it draws anything (issue 27, "Runaway memory
and time"): ``simulate --run --random-positions 1000000000`` allocated 16 GB of angles before any
check and was killed by the kernel at 24 GB."""

import tracemalloc

import pytest

from turntable_pin.calibration.positions import PositionSet
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.sizes import MAX_POSITIONS
from turntable_pin.model.paper_table import paper_table


@pytest.mark.parametrize("n", [MAX_POSITIONS + 1, 10**9, 2**63])
def test_random_positions_beyond_the_limit_are_refused_before_they_are_drawn(n):
    table = paper_table()
    tracemalloc.start()
    try:
        with pytest.raises(InputError) as caught:
            PositionSet.random(n, table, seed=0)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert "random positions of a calibration run would be needed" in str(caught.value)
    assert "at most 200,000 are accepted" in str(caught.value)
    assert peak < 10_000_000  # nothing of the size asked was allocated


def test_random_positions_at_the_limit_are_drawn():
    assert len(PositionSet.random(1000, paper_table(), seed=0)) == 1000
