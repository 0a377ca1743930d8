import os
from pathlib import Path

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


# --- issue 27: what a plain write would refuse, the atomic one refuses too ------------------------
def _protected(folder, name="keep.csv"):
    target = folder / name
    target.write_text("precious")
    target.chmod(0o444)
    return target


def test_root_keeps_to_the_mode_of_a_write_protected_file(tmp_path, monkeypatch):
    # Root may write anything; the rule makes the file's mode bits its owner's say (0444: no).
    monkeypatch.setattr(os, "geteuid", lambda: 0)
    target = _protected(tmp_path)
    with pytest.raises(InputError, match=r"keep.csv: cannot write the file: permission denied"):
        write_text_atomic(target, "new")
    assert target.read_text() == "precious"
    assert target.stat().st_mode & 0o777 == 0o444
    assert [p.name for p in tmp_path.iterdir()] == ["keep.csv"]
    target.chmod(0o640)  # any write bit: written, and the mode kept as a plain write keeps it
    write_text_atomic(target, "new")
    assert target.read_text() == "new" and target.stat().st_mode & 0o777 == 0o640


def _as_user(folder: Path, names: list[str]) -> list[str]:
    """Write each of ``names`` in ``folder`` as an unprivileged user (a forked child that gives up
    root, when the tests run as root; else this user): what happened to each."""
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: no exec, so the interpreter's own folder need not be reachable
        try:
            os.close(read)
            if os.geteuid() == 0:
                os.setgroups([])
                os.setresgid(65534, 65534, 65534)
                os.setresuid(65534, 65534, 65534)
            lines = []
            for name in names:
                try:
                    write_text_atomic(folder / name, "new")
                    lines.append(f"{name} written")
                except InputError as exc:
                    lines.append(f"{name} refused: {exc.detail}")
            os.write(write, "\n".join(lines).encode())
        finally:
            os._exit(0)
    os.close(write)
    with os.fdopen(read) as pipe:
        out = pipe.read()
    os.waitpid(pid, 0)
    return out.splitlines()


def test_a_user_may_not_replace_a_file_or_fill_a_folder_they_may_not_write(tmp_path):
    # A plain open() by this user would fail: so does the atomic write (no rename behind it).
    import shutil
    import tempfile

    root = os.geteuid() == 0
    folder = Path(tempfile.mkdtemp()) if root else tmp_path  # reachable by the unprivileged user
    try:
        folder.chmod(0o777)
        target = _protected(folder)
        (folder / "closed").mkdir()
        (folder / "closed").chmod(0o555)
        (folder / "open.csv").write_text("old")
        (folder / "open.csv").chmod(0o666)
        assert _as_user(folder, ["keep.csv", "closed/new.csv", "open.csv"]) == [
            "keep.csv refused: cannot write the file: permission denied (the file is "
            "write-protected, mode 0444)",
            "closed/new.csv refused: cannot write the file: permission denied (cannot write in "
            f"the folder {folder / 'closed'})",
            "open.csv written",
        ]
        assert target.read_text() == "precious" and target.stat().st_mode & 0o777 == 0o444
        assert (folder / "open.csv").read_text() == "new"
        assert not (folder / "closed" / "new.csv").exists()
    finally:
        if root:
            shutil.rmtree(folder)


def test_a_link_is_written_through_to_its_target(tmp_path):
    real = tmp_path / "real.csv"
    real.write_text("old")
    real.chmod(0o640)
    link = tmp_path / "link.csv"
    link.symlink_to("real.csv")
    assert write_text_atomic(link, "new") == link
    assert link.is_symlink() and os.readlink(link) == "real.csv"
    assert real.read_text() == "new" and real.stat().st_mode & 0o777 == 0o640
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.csv", "real.csv"]


def test_a_link_to_nothing_a_loop_or_a_folder_is_refused(tmp_path):
    from turntable_pin.core.files import output_target

    (tmp_path / "dangling.csv").symlink_to("nowhere.csv")
    with pytest.raises(InputError, match="dangling.csv: .*a link to nowhere.csv, which does not"):
        write_text_atomic(tmp_path / "dangling.csv", "x")
    assert not (tmp_path / "nowhere.csv").exists()
    (tmp_path / "a").symlink_to("b")
    (tmp_path / "b").symlink_to("a")
    with pytest.raises(InputError, match="a link that loops"):
        write_text_atomic(tmp_path / "a", "x")
    (tmp_path / "folder").mkdir()
    (tmp_path / "to_folder").symlink_to("folder")
    with pytest.raises(InputError, match="it is a folder"):
        write_text_atomic(tmp_path / "to_folder", "x")
    assert output_target(tmp_path / "to_folder", folder=True) == (tmp_path / "folder").resolve()


def test_output_target_checks_a_folder_output(tmp_path):
    from turntable_pin.core.files import output_target

    afile = tmp_path / "plots"
    afile.write_text("a file")
    with pytest.raises(InputError, match="plots: cannot write the folder: it is a file, not a"):
        output_target(afile, folder=True)
    with pytest.raises(InputError, match="cannot write the folder: .*plots is a file"):
        output_target(afile / "more", folder=True)
    assert output_target(tmp_path / "new" / "plots", folder=True) == tmp_path / "new" / "plots"
    assert not (tmp_path / "new").exists()  # a check writes nothing
