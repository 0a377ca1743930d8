"""The Monte Carlo run checks its seed and size in the library, not only at the command line."""

import pytest

from turntable_pin.allocation.monte_carlo import run_monte_carlo
from turntable_pin.allocation.solver import paper_eq16_limits
from turntable_pin.core.exceptions import InputError


@pytest.mark.parametrize("seed", [-1, 2**63, 1.5, True])
def test_a_bad_seed_is_refused(seed):
    with pytest.raises(InputError, match="seed must be a whole number"):
        run_monte_carlo([1e-5] * 8, paper_eq16_limits(), 10, seed, progress=False)


def test_a_runaway_count_is_refused_before_any_work():
    with pytest.raises(InputError, match="random turntables would be needed"):
        run_monte_carlo([1e-5] * 8, paper_eq16_limits(), 10**12, 1, progress=False)
