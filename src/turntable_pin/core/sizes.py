"""Sizes checked up front: a run that would not fit in memory (or in a day) is refused before it
starts, with what it would need, instead of growing until the machine gives out.

The limits are generous for turntable work (a 1-degree calibration grid has 129,600 positions; a
long measurement log 1e5-1e6 rows; a Monte Carlo check 1e4-1e6 turntables) and keep every run's
memory bounded by design.
"""

from __future__ import annotations

import math
import numbers

from .exceptions import InputError

__all__ = [
    "DIAGNOSIS_ROW_BYTES",
    "FIT_ROW_BYTES",
    "MAX_DIAGNOSED_ROWS",
    "MAX_FITTED_ROWS",
    "MAX_MONTE_CARLO_TURNTABLES",
    "MAX_POSITIONS",
    "MAX_SIMULATED_ROWS",
    "MAX_TABLE_COLUMNS",
    "MAX_TABLE_FILE_BYTES",
    "MAX_TABLE_ROWS",
    "MAX_TPOINT_FILE_BYTES",
    "MAX_TPOINT_OBSERVATIONS",
    "MAX_URDF_FILE_BYTES",
    "MAX_YAML_FILE_BYTES",
    "MAX_YAML_VALUES",
    "MAX_TIME_S",
    "MIN_GRID_STEP_DEG",
    "check_count",
    "check_positions_count",
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
"""Peak memory of a diagnosis per measurement row, bytes. Measured: the whole ``diagnose`` command
(JSON output) peaked at 470 MB on 100,000 rows (4.7 KB a row, including about 110 MB of interpreter
and libraries; 3.6 KB a row at the margin between 20,000 and 100,000 rows), with a hidden effect
found (two rounds of candidate fits). It was 18.7 KB a row before the fits shared one reduced
Jacobian at zero and stopped keeping their Jacobians (``benchmarks/bench_diagnose_long.py``)."""

MAX_FITTED_ROWS = 1_000_000
"""Most measurement rows one fit takes (about 3 KB a row)."""

FIT_ROW_BYTES = 3_000
"""Peak memory of a fit per measurement row, bytes. Measured: the ``fit`` command with effect
inner_encoder_harmonics (JSON output) peaked at 292 MB on 100,000 rows (2.9 KB a row, with about
110 MB of interpreter and libraries); it was 4.6 KB a row with the dense per-factor gains."""


# --- input files: refused before they are read (core.files.check_input_file) ----------------------
MAX_TABLE_FILE_BYTES = 256_000_000
"""Largest CSV file read (measurements, calibration runs, position lists), bytes. A measurement
file of :data:`MAX_FITTED_ROWS` rows as ``simulate`` writes it (random angles, full-precision
values, nine columns) is 113 MB; reading it takes about 4 s and 0.5 GB. The margin is for more
columns (per-angle sigmas, a temperature log)."""

MAX_TABLE_ROWS = MAX_FITTED_ROWS
"""Most data rows of a CSV file (the most any command takes: a fit, a list of positions to
simulate); counted while the file is read, so that short rows cannot pile up."""

MAX_TABLE_COLUMNS = 1_000
"""Most cells of a CSV row (header or data; a measurement file has about ten)."""

MAX_TPOINT_FILE_BYTES = 16_000_000
"""Largest TPOINT run file read, bytes: about 230,000 observations of 70 characters (pointing runs
have hundreds to a few thousand), as many as a diagnosis takes rows."""

MAX_TPOINT_OBSERVATIONS = MAX_DIAGNOSED_ROWS
"""Most observations (data lines) of a TPOINT run, counted while it is read: lines of a few
characters would otherwise put 2 million within ``MAX_TPOINT_FILE_BYTES`` (measured:
``import-tpoint`` took 17 s and 820 MB over 2 million lines ``1 1 1 1``; with the count it stops
at the 200,001st after 2.2 s and at most 260 MB)."""

MAX_URDF_FILE_BYTES = 16_000_000
"""Largest URDF file read, bytes (a turntable's URDF is a few kilobytes; a whole robot's, with its
comments, well under a megabyte)."""

MAX_YAML_FILE_BYTES = 1_000_000
"""Largest YAML file read (errors, GyroWheel coefficients, lower bounds, effect files), bytes. The
bundled ones are under 1 KB; the pure-Python YAML parser takes about 5 s a megabyte."""

MAX_YAML_VALUES = 1_000_000
"""Most values (scalars, lists and mappings) of a YAML document once its aliases are expanded: a
document whose aliases nest ("a billion laughs") stays small as a file and as parsed, but grows
without bound as soon as it is walked. Without aliases a file of ``MAX_YAML_FILE_BYTES`` holds
fewer (a value takes at least two characters), so the limit only stops aliases."""


def turn_grid_count(step_deg: float) -> int:
    """Number of grid angles ``0, step, ... < 360`` degrees; :class:`InputError` for a step that
    is not a number of at least :data:`MIN_GRID_STEP_DEG`."""
    step = float(step_deg)
    if not (math.isfinite(step) and step >= MIN_GRID_STEP_DEG):
        raise InputError(
            f"a grid step must be at least {MIN_GRID_STEP_DEG:g} deg (a finer grid exceeds every "
            f"size limit), got {step_deg!r}"
        )
    return math.ceil((360.0 - 1e-9) / step)


def check_count(count: float, limit: int, what: str, bytes_each: float = 0.0) -> int:
    """``count`` (maybe a float: a product of counts) as an int when at most ``limit``, else an
    :class:`InputError` saying how many ``what`` and the memory (``bytes_each`` per item, 0: not
    stated) they would need."""
    if not math.isfinite(count) or count > limit:
        need = ""
        if bytes_each and math.isfinite(count):
            need = f", about {count * bytes_each / 1e9:.3g} GB of memory"
        shown = f"{count:,.0f}" if math.isfinite(count) and count < 1e18 else f"{count:.3g}"
        raise InputError(f"{shown} {what} would be needed{need}; at most {limit:,} are accepted")
    return int(count)


def check_positions_count(
    n_positions, available: int, name: str = "n_positions", more: str = "more candidates"
) -> int:
    """``n_positions`` as an int when a whole number from 1 to ``available`` (the candidates a
    design chooses among, each once), checked before any work; else :class:`InputError` naming
    the argument ``name`` and how to choose ``more``."""
    if isinstance(n_positions, bool) or not isinstance(n_positions, numbers.Integral):
        raise InputError(f"{name} must be a whole number of positions, got {n_positions!r}")
    count = int(n_positions)
    if count < 1:
        raise InputError(f"{name} must be at least 1, got {count}")
    if count > available:
        raise InputError(
            f"{name} is {count:,}, more than the {available:,} candidate positions a design "
            f"chooses among (each once); ask for fewer, or give {more}"
        )
    return count
