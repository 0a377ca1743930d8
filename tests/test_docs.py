"""The README and the docs: every sample is what its command prints, every Python block runs,
nothing documented writes into the checkout, and the README fits on a screen
(``tests/samples.py`` finds, runs and regenerates the samples)."""

from __future__ import annotations

import os
import re
import shlex
import subprocess

import pytest

import samples
from conftest import REPO_DIR

README = REPO_DIR / "README.md"
OUTPUT_OPTIONS = ("-o", "--output", "--plots", "--write-urdf", "--report", "--truth")


def git_status() -> str:
    """``git status --porcelain`` of the checkout ('' outside a git checkout, e.g. an sdist)."""
    proc = subprocess.run(
        ["git", "-C", str(REPO_DIR), "status", "--porcelain", "--untracked-files=all"],
        capture_output=True, text=True,
    )  # fmt: skip
    return proc.stdout if proc.returncode == 0 else ""


def fenced(language: str) -> list[tuple[str, str]]:
    """``(file, block)`` of every fenced block in ``language`` in the README and the docs."""
    pattern = re.compile(rf"^```{language}[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
    return [
        (path.name, block)
        for path in samples.documented_files()
        for block in pattern.findall(path.read_text())
    ]


@pytest.fixture(scope="module")
def documented_runs():
    """Every sample and every Python block of the docs, run once, with the checkout's
    ``git status`` before and after."""
    before = git_status()
    outcomes = samples.run_all()
    with samples.sample_folder() as folder:
        import contextlib
        import io

        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            pages: dict[str, dict] = {}  # a page's blocks read as one script, in order
            for name, block in fenced("python"):
                exec(compile(block, name, "exec"), pages.setdefault(name, {}))
        written = sorted(
            p.relative_to(folder).as_posix() for p in (folder / "out").rglob("*") if p.is_file()
        )
    return outcomes, out.getvalue(), written, before, git_status()


SAMPLES_EXIT_ONLY = "TURNTABLE_PIN_SAMPLES_EXIT_ONLY"
"""Set by CI's run on the dependency floors: the samples are what the README's install (the
newest releases) prints; older NumPy, SciPy and OpenBLAS builds differ in the last bits the
exchange designs turn on, so there every sample must run (exit 0) but may print other digits."""


@pytest.mark.slow
def test_every_sample_output_is_what_its_command_prints(documented_runs):
    outcomes = documented_runs[0]
    assert len(outcomes) >= 30
    for outcome in outcomes:
        sample = outcome.sample
        assert outcome.code == 0, (sample.where, sample.command, outcome.stderr)
        if os.environ.get(SAMPLES_EXIT_ONLY) == "1":
            continue
        assert not outcome.differs, (
            f"{sample.where}: the sample differs from what `{sample.command}` prints "
            "(regenerate: python tests/samples.py --write)",
            sample.shown,
            outcome.expected,
        )


@pytest.mark.slow
def test_every_python_block_of_the_docs_runs_and_writes_under_out(documented_runs):
    printed, written = documented_runs[1], documented_runs[2]
    assert "encoder_harmonics@tilt_axis" in printed
    assert "out/identified.urdf" in written
    assert all(path.startswith("out/") for path in written), written


@pytest.mark.slow
def test_no_documented_command_changes_the_checkout(documented_runs):
    before, after = documented_runs[3], documented_runs[4]
    assert after == before


def test_every_documented_output_path_is_under_out():
    """Also the commands not run (a browser, a server, syntax with placeholders): each output
    option names a path under ``out/`` or a placeholder in capitals."""
    found = 0
    for name, block in fenced("bash") + fenced("console"):
        for line in block.replace("\\\n", " ").splitlines():
            try:
                words = shlex.split(line.removeprefix("$ "), comments=True)
            except ValueError:  # an output line with an apostrophe
                continue
            if "turntable-pin" not in " ".join(words[:1]) and "viz/make_all.py" not in words:
                continue
            for option, value in zip(words, words[1:], strict=False):
                if option in OUTPUT_OPTIONS:
                    found += 1
                    placeholder = value.split("/")[0].split(".")[0].isupper()
                    assert value.startswith("out/") or placeholder, (name, line)
    assert found >= 20


def test_a_sample_is_parsed_with_its_elision():
    sample = samples.Sample(README, 1, "turntable-pin x", ("$ turntable-pin x",), ("a", "...", "z"))
    assert sample.head_tail == (1, 1)
    assert sample.expected(["a", "b", "c", "z"]) == ["a", "...", "z"]
    assert sample.expected(["a", "z"]) == ["a", "z"]
    assert samples.normalise("exact chain, 1.4 s ") == "exact chain, <elapsed> s"
    assert samples.normalise("done in 2.5 s") == "done in <elapsed> s"
    assert samples.normalise("a dwell of 2.5 s per position") == "a dwell of 2.5 s per position"


def test_the_readme_fits_on_a_screen_and_starts_with_the_two_commands():
    text = README.read_text()
    assert len(text.splitlines()) <= 250
    first = re.search(r"^```bash\n(.*?)^```", text, re.S | re.M)[1].splitlines()
    install, tests = first
    assert install.startswith("python3 -m venv .venv && . .venv/bin/activate && ")
    assert install.endswith("turntable-pin diagnose models/examples/measurements_example.csv")
    assert tests == ".venv/bin/python -m pytest -q"
    assert tests in (REPO_DIR / ".ci" / "run").read_text().splitlines()
    assert "\npip " not in text and "`pip " not in text  # the venv's pip, never the system's


def test_every_docs_page_is_in_the_site_s_navigation():
    import yaml

    config = (REPO_DIR / "mkdocs.yml").read_text()
    nav = yaml.safe_load(config)["nav"]

    def pages(entries):
        for entry in entries:
            for value in entry.values() if isinstance(entry, dict) else [entry]:
                yield from pages(value) if isinstance(value, list) else [value]

    listed = set(pages(nav))
    assert {p.name for p in (REPO_DIR / "docs").glob("*.md")} <= listed


def test_the_version_is_the_changelog_s_newest_release():
    """pyproject.toml's version is the first release the changelog lists, and a major version
    (a renamed JSON key) says what it renamed."""
    version = re.search(r'^version = "(.+)"', (REPO_DIR / "pyproject.toml").read_text(), re.M)[1]
    changelog = (REPO_DIR / "docs" / "changelog.md").read_text().split("# Changelog\n", 1)[1]
    releases = re.findall(r"^- \*\*([0-9]+\.[0-9]+\.[0-9]+)\b", changelog, re.M)
    assert releases and releases[0] == version, (version, releases[:3])
    entry = changelog.split(f"- **{version}", 1)[1].split("\n- **", 1)[0]
    if version.endswith(".0.0"):
        assert "old -> new" in entry and "->" in entry
