"""The tutorial notebooks (``notebooks/*.py``, jupytext percent format) executed as a user runs
them: converted by jupytext, run cell by cell by nbclient in an IPython kernel on this checkout's
``src``, in an empty temporary folder. Their key numbers are asserted in their own cells (a
failing assert fails the cell); here: every cell ran, the results showed themselves (HTML, the
figures as PNG), and the notebooks left no file behind, in the folder or in the repository."""

from __future__ import annotations

import os
import subprocess
import time

import pytest

from conftest import REPO_DIR, SRC_DIR

jupytext = pytest.importorskip("jupytext")
nbclient = pytest.importorskip("nbclient")
pytest.importorskip("ipykernel")

NOTEBOOKS = sorted((REPO_DIR / "notebooks").glob("*.py"))
CELL_TIMEOUT_S = 300


def _git_status() -> str | None:
    """``git status --porcelain`` of the repository (``None`` outside a git checkout)."""
    try:
        out = subprocess.run(["git", "status", "--porcelain", "--untracked-files=all"],
                             cwd=REPO_DIR, capture_output=True, text=True, check=True)  # fmt: skip
    except (OSError, subprocess.CalledProcessError):
        return None
    return out.stdout


def _outputs(notebook, kind: str) -> list[str]:
    """The MIME types of every output of ``kind`` (execute_result, display_data), in order."""
    return [
        mime
        for cell in notebook.cells
        if cell.cell_type == "code"
        for output in cell.get("outputs", [])
        if output.get("output_type") == kind
        for mime in output.get("data", {})
    ]


def test_there_are_two_notebooks():
    assert [p.name for p in NOTEBOOKS] == ["01_user_loop.py", "02_telescope_run.py"]


def _run(path, folder, monkeypatch):
    """``path`` executed in ``folder`` by a kernel on this checkout's ``src``; the notebook."""
    monkeypatch.setenv(
        "PYTHONPATH", os.pathsep.join(filter(None, [str(SRC_DIR), os.environ.get("PYTHONPATH")]))
    )
    monkeypatch.setenv("MPLBACKEND", "Agg")
    notebook = jupytext.read(path)
    client = nbclient.NotebookClient(
        notebook, timeout=CELL_TIMEOUT_S, kernel_name="python3",
        resources={"metadata": {"path": str(folder)}},
    )  # fmt: skip
    start = time.perf_counter()
    client.execute()  # a failing cell (an assert of a key number) raises CellExecutionError
    print(f"{path.name}: {time.perf_counter() - start:.1f} s")
    return notebook


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs_and_leaves_nothing_behind(path, tmp_path, monkeypatch):
    status = _git_status()
    notebook = _run(path, tmp_path, monkeypatch)
    results = _outputs(notebook, "execute_result")
    assert "text/html" in results  # the results showed themselves
    assert "image/png" in results  # a figure of plot() as a PNG
    errors = [o for c in notebook.cells for o in c.get("outputs", []) if o.output_type == "error"]
    assert not errors
    assert list(tmp_path.iterdir()) == []
    assert _git_status() == status


@pytest.mark.slow
def test_the_user_loop_runs_without_a_browser(tmp_path, monkeypatch):
    """Without Chromium the snapshot is skipped with its reason; the loop runs on."""
    monkeypatch.setenv("TURNTABLE_PIN_CHROMIUM", "no-such-browser-here")
    notebook = _run(REPO_DIR / "notebooks" / "01_user_loop.py", tmp_path, monkeypatch)
    printed = "".join(
        o.get("text", "") for c in notebook.cells for o in c.get("outputs", [])
        if o.output_type == "stream"
    )  # fmt: skip
    assert "no snapshot: $TURNTABLE_PIN_CHROMIUM is 'no-such-browser-here'" in printed
    assert "display_data" not in {
        o.output_type for c in notebook.cells for o in c.get("outputs", [])
    }
    assert list(tmp_path.iterdir()) == []
