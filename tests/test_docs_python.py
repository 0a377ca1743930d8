"""``docs/python.md`` cannot drift: its Python samples run in order in one namespace (from an
empty temporary folder), each prints exactly the ``text`` block that follows it, the first is the
user's loop in at most ten lines with no deep import, and nothing is written.

The outputs are the test's: ``TURNTABLE_PIN_WRITE_DOCS=1 pytest tests/test_docs_python.py``
writes what the samples print into the page's ``text`` blocks (then review the diff).
"""

from __future__ import annotations

import contextlib
import io
import os
import re

import pytest

from conftest import REPO_DIR

PAGE = REPO_DIR / "docs" / "python.md"
SAMPLE = re.compile(r"```python\n(.*?)```(?:\s*```text\n(.*?)```)?", re.S)


def _samples() -> list[tuple[str, str | None]]:
    """``(code, printed output or None)`` of each Python block of the page, in order."""
    return [(m.group(1), m.group(2)) for m in SAMPLE.finditer(PAGE.read_text())]


def test_the_first_sample_is_the_user_loop_in_ten_lines():
    code, output = _samples()[0]
    assert len(code.strip().splitlines()) <= 10
    assert "import turntable_pin as tp" in code and "turntable_pin." not in code
    assert output and "->" in output


@pytest.mark.slow
def test_every_sample_prints_what_the_page_shows(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    samples = _samples()
    assert len(samples) >= 5
    scope: dict = {}
    outputs = []
    for i, (code, _) in enumerate(samples, start=1):
        printed = io.StringIO()
        with contextlib.redirect_stdout(printed):
            exec(compile(code, f"docs/python.md sample {i}", "exec"), scope)
        outputs.append(printed.getvalue())
    if os.environ.get("TURNTABLE_PIN_WRITE_DOCS") == "1":
        _write_outputs(outputs)
        samples = _samples()
    for i, ((_, expected), printed) in enumerate(zip(samples, outputs, strict=True), start=1):
        if expected is not None:
            assert printed == expected, f"sample {i}"
    from turntable_pin.report.figures import pyplot

    pyplot().close("all")
    assert list(tmp_path.iterdir()) == []
    rms_before, rms_after = scope["before"].result.rms_user, scope["after"].result.rms_user
    assert rms_after < 0.75 * rms_before  # the error fell


def _write_outputs(outputs: list[str]) -> None:
    """Put ``outputs`` into the page's ``text`` blocks, one per Python sample that has one."""
    found = iter(outputs)

    def replace(match: re.Match) -> str:
        printed = next(found)
        if match.group(2) is None:
            return match.group(0)
        return f"```python\n{match.group(1)}```\n\n```text\n{printed}```"

    PAGE.write_text(SAMPLE.sub(replace, PAGE.read_text()))
