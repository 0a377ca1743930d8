"""URDF files are checked before they are read (issue 27, "Runaway memory and time"): a regular
file of at most MAX_URDF_FILE_BYTES, for Pinocchio's reader and for yourdfpy's alike."""

import pytest

from conftest import REPO_DIR
from turntable_pin.core.exceptions import InputError
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.urdf_io import YourdfpyTurntable


def test_a_device_is_refused_by_both_readers():
    # Pinocchio's reader said "no such URDF file" of /dev/zero; yourdfpy read it for ever.
    message = "/dev/zero: cannot read the file: it is a character device, not a URDF file"
    with pytest.raises(InputError, match=message):
        GenericTable("/dev/zero")
    with pytest.raises(InputError, match=message):
        YourdfpyTurntable("/dev/zero")


def test_a_file_above_the_size_is_refused_with_its_size(tmp_path):
    path = tmp_path / "huge.urdf"
    with path.open("wb") as handle:  # sparse: nothing written, nothing read
        handle.truncate(16_000_001)  # MAX_URDF_FILE_BYTES + 1
    expected = f"{path}: the file is 16 MB (16,000,001 bytes); a URDF file is read up to 16 MB"
    for read in (GenericTable, YourdfpyTurntable):
        with pytest.raises(InputError) as caught:
            read(path)
        assert str(caught.value) == expected


def test_a_missing_urdf_and_a_folder_are_said_so(tmp_path):
    with pytest.raises(InputError, match="no such URDF file"):
        GenericTable(tmp_path / "missing.urdf")
    with pytest.raises(InputError, match="it is a folder, not a URDF file"):
        GenericTable(tmp_path)
    assert len(GenericTable(REPO_DIR / "models" / "turntable.urdf").joint_names) == 2
