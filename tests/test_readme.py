"""The README's Python code runs as written (examples must not rot), from the repository root."""

from __future__ import annotations

import os
import re

import pytest

from conftest import REPO_DIR


def test_every_python_block_of_the_readme_runs(tmp_path, capsys):
    text = (REPO_DIR / "README.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert blocks
    here = os.getcwd()
    os.chdir(REPO_DIR)
    try:
        for block in blocks:
            # Outputs the snippet writes go to a temporary folder, inputs are read from the repo.
            code = block.replace('"identified.urdf"', repr(str(tmp_path / "identified.urdf")))
            exec(compile(code, "README.md", "exec"), {})
    finally:
        os.chdir(here)
    assert "encoder_harmonics@tilt_axis" in capsys.readouterr().out
    assert (tmp_path / "identified.urdf").is_file()


def _commands_with_samples(text: str) -> list[tuple[str, list[str]]]:
    """``(command, sample output lines)`` of the README's shell blocks: a ``turntable-pin``
    command (continued over lines ending in a backslash) followed by ``#`` lines."""
    out = []
    for block in re.findall(r"```bash\n(.*?)```", text, re.S):
        lines = block.splitlines()
        i = 0
        while i < len(lines):
            line = lines[i]
            if not line.startswith("turntable-pin "):
                i += 1
                continue
            command = line
            while command.endswith("\\") and i + 1 < len(lines):
                i += 1
                command = command[:-1] + " " + lines[i].strip()
            samples = []
            while i + 1 < len(lines) and lines[i + 1].startswith("#"):
                i += 1
                samples.append(lines[i][1:].strip())
            if samples:
                out.append((command, samples))
            i += 1
    return out


@pytest.mark.slow
def test_the_readme_s_sample_outputs_are_what_the_commands_print(tmp_path):
    import shlex

    from conftest import cli

    def norm(line: str) -> str:
        return " ".join(line.split())

    found = _commands_with_samples((REPO_DIR / "README.md").read_text())
    assert len(found) >= 7
    here = os.getcwd()
    (tmp_path / "models").symlink_to(REPO_DIR / "models")  # the README's paths, as typed
    os.chdir(tmp_path)  # outputs land here, not in the checkout
    try:
        for command, samples in found:
            proc = cli(*shlex.split(command)[1:])
            assert proc.returncode == 0, (command, proc.stderr)
            printed = {norm(line) for line in proc.stdout.splitlines()}
            for sample in samples:
                if sample in ("...",) or sample.startswith("("):  # an elision, a remark
                    continue
                assert norm(sample) in printed, (command, sample)
    finally:
        os.chdir(here)


def test_the_version_is_the_changelog_s_newest_release():
    """pyproject.toml's version is the first release the changelog lists, and a major version
    (a renamed JSON key) says what it renamed."""
    version = re.search(r'^version = "(.+)"', (REPO_DIR / "pyproject.toml").read_text(), re.M)[1]
    changelog = (REPO_DIR / "README.md").read_text().split("\n## Changelog\n", 1)[1]
    releases = re.findall(r"^- \*\*([0-9]+\.[0-9]+\.[0-9]+)\b", changelog, re.M)
    assert releases and releases[0] == version, (version, releases[:3])
    entry = changelog.split(f"- **{version}", 1)[1].split("\n- **", 1)[0]
    if version.endswith(".0.0"):
        assert "old -> new" in entry and "->" in entry
