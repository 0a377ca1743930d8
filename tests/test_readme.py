"""The README's Python code runs as written (examples must not rot), from the repository root."""

from __future__ import annotations

import os
import re

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
