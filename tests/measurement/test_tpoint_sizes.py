"""TPOINT run files are bounded before and while they are read (issue 27, "Runaway memory and
time"): a regular file of at most MAX_TPOINT_FILE_BYTES, at most MAX_TPOINT_OBSERVATIONS data
lines. Before, `import-tpoint /dev/zero` was killed at the memory limit and a 3e6-line file took
25 s and 2 GB."""

import pytest

from conftest import write_file
from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement import tpoint
from turntable_pin.measurement.tpoint import read_tpoint

HEADER = "Synthetic run\n: ALTAZ\n+31 41 19.6 2021 8 21 13.0 741 2608.0 0.75\n"


def _lines(count: int) -> str:
    return "".join(f"{10.0 + i} 45.0 {10.01 + i} 45.01\n" for i in range(count))


def test_the_limits():
    from turntable_pin.core.sizes import MAX_TPOINT_FILE_BYTES, MAX_TPOINT_OBSERVATIONS

    assert MAX_TPOINT_FILE_BYTES == 16_000_000 and MAX_TPOINT_OBSERVATIONS == 200_000


def test_a_device_is_refused_before_it_is_read():
    with pytest.raises(InputError) as caught:
        read_tpoint("/dev/zero")
    assert str(caught.value) == (
        "/dev/zero: cannot read the file: it is a character device, not a TPOINT file (give a "
        "regular file)"
    )


def test_a_file_above_the_size_is_refused_with_its_size(tmp_path):
    path = tmp_path / "huge.dat"
    with path.open("wb") as handle:  # sparse: 200 MB said (3 million lines), nothing written
        handle.truncate(200_000_000)
    with pytest.raises(InputError) as caught:
        read_tpoint(path)
    assert str(caught.value) == (
        f"{path}: the file is 200 MB (200,000,000 bytes); a TPOINT file is read up to 16 MB"
    )


def test_observations_beyond_the_count_are_refused_at_the_first_one(tmp_path, monkeypatch):
    monkeypatch.setattr(tpoint, "MAX_TPOINT_OBSERVATIONS", 5)
    assert read_tpoint(write_file(tmp_path, HEADER + _lines(5), "five.dat")).n_stars == 5
    path = write_file(tmp_path, HEADER + _lines(6) + "END\n", "six.dat")
    with pytest.raises(InputError) as caught:
        read_tpoint(path)
    assert str(caught.value) == (
        f"{path}, line 9: more than 5 observations; a TPOINT run is read up to 5 (as many as a "
        "diagnosis takes rows)"
    )
