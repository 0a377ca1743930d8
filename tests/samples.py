"""The command samples of the README and the docs: found, run, compared, and regenerated.

A *sample* is a fenced ``console`` block of ``README.md`` or ``docs/*.md``: each line starting with
``$ turntable-pin`` is a command (continued over lines ending in a backslash), and the lines up to
the next command are what it prints on standard output. A line ``...`` elides the middle of an
output: the lines above it are the output's first lines, those below its last lines (one ``...``
per command at most). Without ``...`` the whole output is shown.

The commands run in this process (``turntable_pin.cli.main``), one after the other, in a fresh
temporary folder holding a link ``models`` to the repository's ``models/``: the paths as a user
types them in the checkout, and outputs under ``out/`` of that folder. They must exit with status
0.

The samples are produced in one arithmetic, :func:`canonical_environment`: OpenBLAS's Haswell
kernels on one thread and NumPy without its AVX-512 loops, set for a child process when the
caller's is not already in it. Some outputs (the exchange designs, a maximum reached at two
symmetric angles, the order of candidates tied in BIC) turn on the last bits of a sum, which
differ between the kernels OpenBLAS and NumPy pick for each CPU (an AMD Zen machine and an
AVX-512 one print different `design --calibrate` positions); any x86-64 CPU with AVX2 runs
these exact kernels.

The comparison is exact line by line after one normalisation, :data:`RUN_DEPENDENT`: trailing
blanks are dropped, and an elapsed time ``<number> s`` ending a line after ", ", "in " or "took "
(the one number of an output that changes from run to run) reads as ``<elapsed> s``.

Regenerate every sample (after a change of the output):

    python tests/samples.py --write      # rewrites the console blocks in place
    python tests/samples.py              # lists the samples that differ; exit 1 if any
"""

from __future__ import annotations

import contextlib
import io
import os
import pickle
import platform
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

REPO_DIR = Path(__file__).resolve().parents[1]
PROMPT = "$ "
ELISION = "..."
FENCE = re.compile(r"^```console[ \t]*\n(.*?)^```[ \t]*$", re.S | re.M)
RUN_DEPENDENT = re.compile(r"(, |\bin |\btook )[0-9]+(\.[0-9]+)? s$")
"""An elapsed time ending a line (``montecarlo``'s ``..., exact chain, 1.4 s``): the only
run-dependent number of the printed outputs."""


def documented_files() -> list[Path]:
    """``README.md`` and every page of ``docs/``."""
    return [REPO_DIR / "README.md", *sorted((REPO_DIR / "docs").rglob("*.md"))]


@dataclass(frozen=True)
class Sample:
    """One command of a console block and the output lines shown for it."""

    path: Path
    line: int  # 1-based line of the command in the file
    command: str  # without the prompt, continuations joined
    command_lines: tuple[str, ...]  # as written, prompt included
    shown: tuple[str, ...]  # output lines as written

    @property
    def where(self) -> str:
        return f"{self.path.relative_to(REPO_DIR)}:{self.line}"

    @property
    def head_tail(self) -> tuple[int, int] | None:
        """``(head, tail)`` line counts around the elision; None when the output is whole."""
        if ELISION not in self.shown:
            return None
        i = self.shown.index(ELISION)
        if ELISION in self.shown[i + 1 :]:
            raise ValueError(f"{self.where}: more than one '{ELISION}' in one output")
        return i, len(self.shown) - i - 1

    def expected(self, printed: list[str]) -> list[str]:
        """What the block should show for ``printed``: the whole, or its head and tail."""
        ht = self.head_tail
        if ht is None or len(printed) <= ht[0] + ht[1]:
            return list(printed)
        head, tail = ht
        return [*printed[:head], ELISION, *(printed[len(printed) - tail :] if tail else [])]


def parse(path: Path) -> list[Sample]:
    """The samples of one Markdown file, in order."""
    text = path.read_text()
    samples = []
    for match in FENCE.finditer(text):
        first_line = text.count("\n", 0, match.start(1)) + 1
        lines = match.group(1).splitlines()
        i = 0
        while i < len(lines):
            if not lines[i].startswith(PROMPT):
                raise ValueError(f"{path.name}:{first_line + i}: a console block starts with '$ '")
            start = i
            command_lines = [lines[i]]
            while command_lines[-1].endswith("\\") and i + 1 < len(lines):
                i += 1
                command_lines.append(lines[i])
            command = " ".join(c.rstrip("\\").strip() for c in command_lines)[len(PROMPT) :]
            shown = []
            while i + 1 < len(lines) and not lines[i + 1].startswith(PROMPT):
                i += 1
                shown.append(lines[i])
            samples.append(
                Sample(path, first_line + start, command, tuple(command_lines), tuple(shown))
            )
            i += 1
    return samples


def all_samples() -> list[Sample]:
    return [s for path in documented_files() for s in parse(path)]


def normalise(line: str) -> str:
    """One line as compared: :data:`RUN_DEPENDENT` applied, trailing blanks dropped."""
    return RUN_DEPENDENT.sub(r"\1<elapsed> s", line.rstrip())


def run(command: str) -> tuple[int, list[str], str]:
    """Run one documented command in this process, in the current folder: its exit status, the
    lines it printed on standard output and its standard error."""
    from turntable_pin.cli import main

    words = shlex.split(command)
    if not words or words[0] != "turntable-pin":
        raise ValueError(f"a sample runs turntable-pin, not {command!r}")
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            code = main(words[1:])
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 2
    return code, [line.rstrip() for line in out.getvalue().splitlines()], err.getvalue()


@contextlib.contextmanager
def sample_folder():
    """A fresh temporary folder as the current one, with ``models`` linking the repository's."""
    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="turntable-pin-samples-") as folder:
        (Path(folder) / "models").symlink_to(REPO_DIR / "models")
        os.chdir(folder)
        try:
            yield Path(folder)
        finally:
            os.chdir(here)


@dataclass(frozen=True)
class Outcome:
    sample: Sample
    code: int
    stderr: str
    expected: tuple[str, ...]  # what the block should show, from the printed output

    @property
    def differs(self) -> bool:
        shown = [normalise(line) for line in self.sample.shown]
        return self.code != 0 or shown != [normalise(line) for line in self.expected]


CANONICAL = "TURNTABLE_PIN_SAMPLES_ARITHMETIC"
"""Set in the child process :func:`run_all` starts in :func:`canonical_environment`."""


def canonical_environment() -> dict[str, str]:
    """The environment variables of the samples' one arithmetic (module docstring); only the
    marker off x86-64, where OpenBLAS's and NumPy's kernels are the same everywhere."""
    env = {CANONICAL: "1", "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    if platform.machine().lower() in ("x86_64", "amd64"):
        from numpy._core import _multiarray_umath as umath

        wide = [f for f in umath.__cpu_dispatch__ if f.startswith("AVX512") or f == "X86_V4"]
        env.update(OPENBLAS_CORETYPE="Haswell", NPY_DISABLE_CPU_FEATURES=" ".join(wide))
    return env


def _run_in_child() -> list[Outcome]:
    """:func:`run_all` in a child process in :func:`canonical_environment`."""
    with tempfile.TemporaryDirectory(prefix="turntable-pin-samples-") as folder:
        result = Path(folder) / "outcomes.pickle"
        subprocess.run(
            [sys.executable, str(Path(__file__).resolve()), "--pickle", str(result)],
            env={**os.environ, **canonical_environment()},
            check=True,
        )
        return pickle.loads(result.read_bytes())


def run_all(samples: list[Sample] | None = None) -> list[Outcome]:
    """Run every sample, in order, in one temporary folder (a later command may read an earlier
    one's output under ``out/``), in the samples' arithmetic (a child process unless this one
    is in it)."""
    if os.environ.get(CANONICAL) != "1":
        outcomes = _run_in_child()
        wanted = None if samples is None else {(s.path, s.line) for s in samples}
        return [o for o in outcomes if wanted is None or (o.sample.path, o.sample.line) in wanted]
    samples = all_samples() if samples is None else samples
    outcomes = []
    with sample_folder():
        for sample in samples:
            code, printed, stderr = run(sample.command)
            outcomes.append(Outcome(sample, code, stderr, tuple(sample.expected(printed))))
    return outcomes


def write(outcomes: list[Outcome]) -> int:
    """Rewrite the console blocks with the outputs printed; the number of samples changed."""
    changed = 0
    for path in {o.sample.path for o in outcomes}:
        lines = path.read_text().split("\n")
        mine = sorted((o for o in outcomes if o.sample.path == path), key=lambda o: -o.sample.line)
        for o in mine:  # bottom up, so earlier line numbers stay valid
            if o.code != 0:
                raise SystemExit(f"{o.sample.where}: exit status {o.code}\n{o.stderr}")
            if not o.differs:
                continue
            start = o.sample.line - 1 + len(o.sample.command_lines)
            lines[start : start + len(o.sample.shown)] = list(o.expected)
            changed += 1
        path.write_text("\n".join(lines))
    return changed


def main(argv: list[str]) -> int:
    outcomes = run_all()
    if "--pickle" in argv:  # the child of run_all
        Path(argv[argv.index("--pickle") + 1]).write_bytes(pickle.dumps(outcomes))
        return 0
    if "--write" in argv:
        print(f"{write(outcomes)} of {len(outcomes)} samples rewritten")
        return 0
    bad = [o for o in outcomes if o.differs]
    for o in bad:
        print(f"{o.sample.where}: $ {o.sample.command}  (exit {o.code})")
    print(f"{len(bad)} of {len(outcomes)} samples differ from what the commands print")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.path.insert(0, str(REPO_DIR / "src"))
    import samples  # this file by its module name, so a parent process unpickles its outcomes

    sys.exit(samples.main(sys.argv[1:]))
