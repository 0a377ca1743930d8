"""Reading a calibration run CSV: the extra columns (suspects for the run diagnosis), a bad cell
among numbers refused where it is, a column of text left out and named."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, temperature_run
from turntable_pin import InputError
from turntable_pin.calibration.run import read_run

LAT_RAD = np.radians(45.75)
TEMPERATURE_RUN = EXAMPLES_DIR / "runs" / "run_temperature.csv"


def test_the_temperature_column_is_read_as_a_suspect():
    run = read_run(TEMPERATURE_RUN, LAT_RAD)
    assert list(run.extra) == ["temperature_c"] and run.ignored_columns == ()
    assert run.column("temperature_c").shape == (run.n_positions,)


def test_one_text_cell_among_temperatures_is_refused_naming_row_and_column(tmp_path):
    """Issue 27: 'warm' in one cell used to drop temperature_c without a word, and the
    diagnosis then blamed bias_drift and called the column absent."""
    path = temperature_run(tmp_path, lambda row, text: "warm" if row == 17 else text)
    with pytest.raises(InputError) as info:
        read_run(path, LAT_RAD)
    message = str(info.value)
    assert f"{path}, row 17, column 'temperature_c': 'warm' is not a number" in message


def test_a_text_column_is_left_out_and_named(tmp_path):
    path = temperature_run(tmp_path, note="fine")
    run = read_run(path, LAT_RAD)
    assert list(run.extra) == ["temperature_c"] and run.ignored_columns == ("note",)
    path = temperature_run(tmp_path, lambda row, text: "n/a", note="fine")
    run = read_run(path, LAT_RAD)
    assert run.extra == {} and run.ignored_columns == ("temperature_c", "note")
    words = run.missing_columns_words(["temperature_c"])
    assert words.startswith("temperature_c, present in the run but not numbers")
