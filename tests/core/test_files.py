import os

import pytest

from turntable_pin import InputError
from turntable_pin.core.files import read_yaml, write_text_atomic


def test_atomic_write_replaces_and_leaves_no_temporary(tmp_path):
    target = tmp_path / "out.txt"
    write_text_atomic(target, "one")
    write_text_atomic(target, "two")
    assert target.read_text() == "two"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert target.stat().st_mode & 0o777 == 0o666 & ~umask


def test_failed_write_keeps_the_old_file(tmp_path):
    from turntable_pin.core.files import write_atomic

    target = tmp_path / "out.txt"
    target.write_text("precious")

    def boom(tmp):
        tmp.write_text("half")
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError):
        write_atomic(target, boom)
    assert target.read_text() == "precious"
    assert [p.name for p in tmp_path.iterdir()] == ["out.txt"]


def test_read_yaml_names_the_file(tmp_path):
    bad = tmp_path / "x.yaml"
    bad.write_text("a: [1,\n")
    with pytest.raises(InputError, match="x.yaml: not valid YAML"):
        read_yaml(bad)
    with pytest.raises(InputError, match="cannot read the file"):
        read_yaml(tmp_path / "missing.yaml")


def test_unwritable_outputs_are_input_errors(tmp_path):
    blocker = tmp_path / "data.csv"
    blocker.write_text("precious")
    with pytest.raises(InputError, match="data.csv"):
        write_text_atomic(blocker / "residuals.png", "x")  # a 'folder' that is a file
    with pytest.raises(InputError, match="it is a folder"):
        write_text_atomic(tmp_path, "x")
    assert blocker.read_text() == "precious"
