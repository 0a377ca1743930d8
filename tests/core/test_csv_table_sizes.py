"""CSV files are bounded before and while they are read (issue 27, "Runaway memory and time"):
a regular file of at most MAX_TABLE_FILE_BYTES, at most MAX_TABLE_ROWS data rows of at most
MAX_TABLE_COLUMNS cells, each bound said in one line naming the file (and the row)."""

import os

import pytest

from conftest import write_file
from turntable_pin.core import csv_table
from turntable_pin.core.csv_table import read_csv_table, read_header
from turntable_pin.core.exceptions import InputError


def test_the_limits_hold_the_largest_table_a_command_takes():
    from turntable_pin.core.sizes import (
        MAX_FITTED_ROWS,
        MAX_SIMULATED_ROWS,
        MAX_TABLE_COLUMNS,
        MAX_TABLE_FILE_BYTES,
        MAX_TABLE_ROWS,
    )

    assert MAX_TABLE_ROWS >= max(MAX_FITTED_ROWS, MAX_SIMULATED_ROWS)
    # 1,000,000 rows as simulate writes them (random angles, full precision) are 113 MB
    assert MAX_TABLE_FILE_BYTES == 256_000_000 and MAX_TABLE_COLUMNS == 1_000


def test_a_file_above_the_size_is_refused_with_its_size_before_it_is_read(tmp_path):
    path = tmp_path / "huge.csv"
    with path.open("wb") as handle:  # sparse: 300 MB said, nothing written or read
        handle.truncate(300_000_000)
    with pytest.raises(InputError) as caught:
        read_csv_table(path, ["a"])
    assert str(caught.value) == (
        f"{path}: the file is 300 MB (300,000,000 bytes); a CSV file is read up to 256 MB"
    )
    assert read_header(path) == ((), 0)  # said by read_csv_table, as for an unreadable file


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_device_is_refused(device):
    assert read_header(device) == ((), 0)  # it read /dev/zero for ever, looking for a line
    with pytest.raises(InputError, match=f"{device}: cannot read the file: it is a character"):
        read_csv_table(device, ["a"])


def test_rows_beyond_the_count_are_refused_at_the_first_one(tmp_path, monkeypatch):
    monkeypatch.setattr(csv_table, "MAX_TABLE_ROWS", 3)
    path = write_file(tmp_path, "# a comment\na,b\n1,2\n\n2,3\n3,4\n")
    assert len(read_csv_table(path, ["a", "b"])) == 3  # blank and comment lines do not count
    path = write_file(tmp_path, "# a comment\na,b\n1,2\n\n2,3\n3,4\n4,5\n")
    with pytest.raises(InputError) as caught:
        read_csv_table(path, ["a", "b"])
    assert str(caught.value) == (
        f"{path}, row 7: more than 3 data rows; a CSV table is read up to 3"
    )


def test_a_row_of_too_many_cells_is_refused_before_it_is_split(tmp_path):
    wide = ",".join(["1"] * 1001)
    path = write_file(tmp_path, "a,b\n1,2\n" + wide + "\n")
    with pytest.raises(InputError, match=r"row 3: more than 1,000 cells"):
        read_csv_table(path, ["a", "b"])
    header = ",".join(f"c{i}" for i in range(1000))  # the most: 1,000 cells
    path = write_file(tmp_path, header + "\n" + ",".join(["1"] * 1000) + "\n")
    assert len(read_csv_table(path, ["c0"], extra=True).extra) == 999


def test_a_cell_beyond_the_csv_module_s_field_limit_is_one_line(tmp_path):
    # csv.Error escaped as a traceback
    path = write_file(tmp_path, 'a,b\n1,"' + "2" * 200_000 + '"\n')
    with pytest.raises(InputError, match=r"cannot read it as CSV: field larger than field limit"):
        read_csv_table(path, ["a", "b"])


def test_a_folder_and_a_pipe_are_refused(tmp_path):
    with pytest.raises(InputError, match="it is a folder, not a CSV file"):
        read_csv_table(tmp_path, ["a"])
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    assert read_header(fifo) == ((), 0)
    with pytest.raises(InputError, match="it is a named pipe, not a CSV file"):
        read_csv_table(fifo, ["a"])
