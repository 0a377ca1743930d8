"""Sizes checked up front: a run that would not fit in memory (or in a day) is refused before it
starts, with what it would need, instead of growing until the machine gives out.

The limits are generous for turntable work (a 1-degree calibration grid has 129,600 positions; a
long measurement log 1e5-1e6 rows; a Monte Carlo check 1e4-1e6 turntables) and keep every run's
memory bounded by design.
"""

from __future__ import annotations

import math

from .exceptions import InputError

__all__ = [
    "DIAGNOSIS_ROW_BYTES",
    "FIT_ROW_BYTES",
    "MAX_DIAGNOSED_ROWS",
    "MAX_FITTED_ROWS",
    "MAX_MONTE_CARLO_TURNTABLES",
    "MAX_POSITIONS",
    "MAX_SIMULATED_ROWS",
    "MAX_TIME_S",
    "MIN_GRID_STEP_DEG",
    "check_count",
    "turn_grid_count",
]

MAX_POSITIONS = 200_000
"""Most test positions a calibration-layer computation takes (rate error, requirement)."""

MAX_SIMULATED_ROWS = 1_000_000
"""Most rows ``simulate`` writes (about 100 MB of CSV)."""

MAX_TIME_S = 366 * 86400.0
"""Largest ``time_s`` of a measurement file and of a calibration run, seconds (a year): a longer
run is a unit mix-up (ms written as s), and a time of 1e308 s would overflow the fits' squares."""

MIN_GRID_STEP_DEG = 1e-6
"""Smallest step of a grid over a turn, degrees (3.6e8 angles a turn, beyond every size limit
here): a finer step is a typo, and the count ``360 / step`` of a step of 1e-320 is not even a
number."""

MAX_MONTE_CARLO_TURNTABLES = 10_000_000
"""Most random turntables of one Monte Carlo run (240 MB of per-turntable maxima)."""

MAX_DIAGNOSED_ROWS = 200_000
"""Most measurement rows one diagnosis takes (about 5 KB a row: 1 GB at the limit)."""

DIAGNOSIS_ROW_BYTES = 5_000
"""Peak memory of a diagnosis per measurement row, bytes. Measured: the whole ``diagnose --json``
command peaked at 470 MB on 100,000 rows (4.7 KB a row, including about 110 MB of interpreter
and libraries; 3.6 KB a row at the margin between 20,000 and 100,000 rows), with a hidden effect
found (two rounds of candidate fits). It was 18.7 KB a row before the fits shared one reduced
Jacobian at zero and stopped keeping their Jacobians (``benchmarks/bench_diagnose_long.py``)."""

MAX_FITTED_ROWS = 1_000_000
"""Most measurement rows one fit takes (about 3 KB a row)."""

FIT_ROW_BYTES = 3_000
"""Peak memory of a fit per measurement row, bytes. Measured: ``fit FILE --effects
inner_encoder_harmonics --json`` peaked at 292 MB on 100,000 rows (2.9 KB a row, including about
110 MB of interpreter and libraries); it was 4.6 KB a row with the dense per-factor gains."""


def turn_grid_count(step_deg: float) -> int:
    """Number of grid angles ``0, step, ... < 360`` degrees (the grids of the package).

    Raises:
        InputError: a step that is not a number of at least :data:`MIN_GRID_STEP_DEG`.
    """
    step = float(step_deg)
    if not (math.isfinite(step) and step >= MIN_GRID_STEP_DEG):
        raise InputError(
            f"a grid step must be at least {MIN_GRID_STEP_DEG:g} deg (a finer grid exceeds every "
            f"size limit), got {step_deg!r}"
        )
    return math.ceil((360.0 - 1e-9) / step)


def check_count(count: float, limit: int, what: str, bytes_each: float = 0.0) -> int:
    """Refuse ``count`` items above ``limit``, saying how many and what they would need.

    Args:
        count: the number of items the run would have (may be a float: a product of counts).
        limit: the largest number accepted.
        what: what is counted, for the message (``"positions"``).
        bytes_each: memory per item, for the message (0: not stated).

    Returns:
        ``count`` as an int when it is within the limit.
    """
    if not math.isfinite(count) or count > limit:
        need = ""
        if bytes_each and math.isfinite(count):
            need = f", about {count * bytes_each / 1e9:.3g} GB of memory"
        shown = f"{count:,.0f}" if math.isfinite(count) and count < 1e18 else f"{count:.3g}"
        raise InputError(f"{shown} {what} would be needed{need}; at most {limit:,} are accepted")
    return int(count)
