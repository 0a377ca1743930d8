"""Input files are checked before they are read (issue 27, "Runaway memory and time"): a regular
file within the size its kind may have (core.files.check_input_file), and a YAML document whose
aliases would expand without bound ("a billion laughs") is refused before anyone walks it."""

import os
import time

import pytest

from turntable_pin.core import files
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.files import read_text_file, read_yaml


def laughs(folder, levels: int, name: str = "laughs.yaml", top: str = "terms"):
    """A YAML file of ``levels`` nested aliases, each holding the one before ten times: a few
    hundred bytes whose document has 10**levels leaves once its aliases are expanded."""
    lines = ['a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    for k in range(1, levels):
        lines.append(f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]")
    lines.append(f"{top}: *a{levels - 1}")
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path


def test_a_billion_laughs_is_refused_before_anything_walks_it(tmp_path):
    path = laughs(tmp_path, 9)  # 10**9 leaves: 550 bytes on disk
    start = time.perf_counter()
    with pytest.raises(InputError, match=r"more than 1,000,000 values once its aliases"):
        read_yaml(path)
    assert time.perf_counter() - start < 2.0
    assert path.stat().st_size < 1000


def test_the_value_count_is_exact_at_the_limit(tmp_path, monkeypatch):
    path = laughs(tmp_path, 2, "ok.yaml")
    # the mapping, its 3 keys, a0 (11 values: the list and its 10 items), a1 (1 + 10 * 11) and
    # terms (a1 once more): each alias counts as the whole value it names
    values = 1 + 3 + 11 + 111 + 111
    monkeypatch.setattr(files, "MAX_YAML_VALUES", values - 1)
    with pytest.raises(InputError, match=f"more than {values - 1} values"):
        read_yaml(path)
    monkeypatch.setattr(files, "MAX_YAML_VALUES", values)
    assert read_yaml(path)["terms"][9] == ["lol"] * 10


def test_an_alias_inside_its_own_anchor_is_refused(tmp_path):
    path = tmp_path / "self.yaml"
    path.write_text("name: x\nterms: &t [1, [2, *t]]\n")
    with pytest.raises(
        InputError, match=r"self.yaml, line 2: an alias \(\*name\) inside the value"
    ):
        read_yaml(path)


def test_plain_aliases_and_merge_keys_still_read(tmp_path):
    path = tmp_path / "merge.yaml"
    path.write_text("base: &b {x: 1, y: 2}\nother:\n  <<: *b\n  y: 3\nlist: [*b, *b]\n")
    assert read_yaml(path) == {
        "base": {"x": 1, "y": 2},
        "other": {"x": 1, "y": 3},
        "list": [{"x": 1, "y": 2}, {"x": 1, "y": 2}],
    }


def test_key_lines_come_from_the_one_parse_and_enter_an_alias_once(tmp_path):
    path = tmp_path / "lines.yaml"
    path.write_text("name: x\nterms:\n  - &t {site: dpsi, of: phi1}\n  - *t\n")
    from turntable_pin.core.files import read_yaml_lines

    doc, lines = read_yaml_lines(path)
    assert doc["terms"][1] is doc["terms"][0]
    assert lines[("name",)] == 1 and lines[("terms",)] == 2
    assert lines[("terms", 0, "site")] == 3 and lines[("terms", 1)] == 3
    assert ("terms", 1, "site") not in lines  # the alias's keys: under its anchor's path only


def test_a_yaml_file_above_its_size_is_refused_with_the_size(tmp_path):
    path = tmp_path / "big.yaml"
    with path.open("wb") as handle:  # sparse: nothing written, nothing read
        handle.truncate(300_000_000)
    with pytest.raises(InputError) as caught:
        read_yaml(path)
    message = str(caught.value)
    assert message == (
        f"{path}: the file is 300 MB (300,000,000 bytes); a YAML file is read up to 1 MB"
    )


@pytest.mark.parametrize("device", ["/dev/zero", "/dev/urandom"])
def test_a_device_is_refused_before_it_is_read(device):
    with pytest.raises(
        InputError, match=f"{device}: cannot read the file: it is a character device"
    ):
        read_yaml(device)
    with pytest.raises(InputError, match="not a TPOINT file"):
        read_text_file(device, "TPOINT", max_bytes=10)


def test_a_folder_and_a_pipe_are_refused(tmp_path):
    with pytest.raises(InputError, match="it is a folder, not a YAML file"):
        read_yaml(tmp_path)
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="it is a named pipe, not a YAML file"):
        read_yaml(fifo)  # opening it would wait for a writer for ever


def test_a_file_that_says_it_is_empty_is_read_only_up_to_the_limit(tmp_path, monkeypatch):
    # /proc files say 0 bytes; a file may grow after its size was checked: the read is bounded.
    path = tmp_path / "grows.txt"
    path.write_text("x" * 50)
    real_stat = os.stat_result

    def shrunk(self, *args, **kwargs):
        info = os.stat(self, *args, **kwargs)
        return real_stat((info.st_mode, *info[1:6], 0, *info[7:10]))

    monkeypatch.setattr(type(path), "stat", shrunk)
    assert read_text_file(path, "text", max_bytes=50) == "x" * 50
    with pytest.raises(InputError, match="the file is larger; a text file is read up to"):
        read_text_file(path, "text", max_bytes=49)


def test_the_limits():
    from turntable_pin.core.sizes import MAX_YAML_FILE_BYTES, MAX_YAML_VALUES

    assert MAX_YAML_FILE_BYTES == 1_000_000 and MAX_YAML_VALUES == 1_000_000


def test_a_missing_file_says_so_as_before(tmp_path):
    with pytest.raises(InputError, match="cannot read the file: No such file or directory"):
        read_yaml(tmp_path / "missing.yaml")
