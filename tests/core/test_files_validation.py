"""The YAML reader refuses what a plain YAML reader silently drops (a key given twice) and turns
every malformed document into one InputError naming the file (and the line where known)."""

import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.core.files import read_yaml


@pytest.mark.parametrize(
    "text, line, first",
    [
        ("dphi_y1: 1\ndeps_x: 2\ndphi_y1: 3\n", 3, 1),
        ("errors:\n  dphi_y1: 1\n  dphi_y1: 2\n", 3, 2),
        ("x:\n  DF: 1\ny:\n  DF: 2\n  x: 1\n  DF: 3\n", 6, 4),
        ("{a: 1, b: 2, a: 3}\n", 1, 1),
    ],
)
def test_a_key_given_twice_is_refused_naming_file_and_line(tmp_path, text, line, first):
    path = tmp_path / "twice.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        read_yaml(path)
    message = str(info.value)
    assert message.startswith(f"{path}, line {line}: key ")
    assert f"given twice (first on line {first})" in message
    assert info.value.line == line and info.value.path == str(path)


def test_same_key_in_different_mappings_and_merge_keys_are_fine(tmp_path):
    path = tmp_path / "ok.yaml"
    path.write_text("x: {DF: 1}\ny: {DF: 2}\nbase: &b {a: 1}\nm:\n  <<: *b\n  a: 2\n")
    assert read_yaml(path) == {"x": {"DF": 1}, "y": {"DF": 2}, "base": {"a": 1}, "m": {"a": 2}}


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("when: 2020-13-45\n", "not valid YAML: month must be in 1..12"),
        ("a: [1, 2\n", "not valid YAML"),
        ("? [1, 2]\n: 3\n", "not valid YAML"),
    ],
)
def test_malformed_documents_are_one_input_error(tmp_path, text, fragment):
    path = tmp_path / "bad.yaml"
    path.write_text(text)
    with pytest.raises(InputError, match=fragment) as info:
        read_yaml(path)
    assert str(info.value).startswith(str(path))
    assert "\n" not in str(info.value)
