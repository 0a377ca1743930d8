"""Regenerate every figure of the project into one folder, with an index page showing them all.

Each figure is a script ``viz/fig_*.py`` exposing ``main(out_dir, fast=False) -> list[Path]``
(the image files it wrote) and a module docstring whose first line is the figure's title and the
rest its caption. Adding a figure is adding such a file. ``--fast`` asks every script for coarse
settings (used by the tests). A script that raises a ``TurntablePinError`` (e.g. no Chromium for
the 3-D snapshot) is listed on the index page as skipped, with the reason; any other exception
stops the run, so a script that rots fails loudly.

    python viz/make_all.py -o figures [--fast] [--only setup]
"""

from __future__ import annotations

import argparse
import html
import importlib.util
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from turntable_pin.core.exceptions import TurntablePinError
from turntable_pin.core.files import write_text_atomic

VIZ_DIR = Path(__file__).resolve().parent


@dataclass
class FigureRun:
    """One script's outcome: the images it wrote (relative to the output folder) or why not."""

    script: str
    title: str
    caption: str
    images: list[str] = field(default_factory=list)
    seconds: float = 0.0
    skipped: str | None = None


def discover(pattern: str = "fig_*.py") -> list[Path]:
    """The figure scripts of ``viz/``, in name order."""
    return sorted(VIZ_DIR.glob(pattern))


def _load(script: Path):
    spec = importlib.util.spec_from_file_location(f"viz_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses and pickling look a module up there
    spec.loader.exec_module(module)
    if not callable(getattr(module, "main", None)):
        raise TypeError(f"{script}: a figure script must define main(out_dir, fast=False)")
    return module


def run_script(script: Path, out_dir: Path, fast: bool) -> FigureRun:
    """Run one figure script into ``out_dir``."""
    module = _load(script)
    doc = (module.__doc__ or script.stem).strip()
    title, _, caption = doc.partition("\n")
    run = FigureRun(script=script.name, title=title.strip(), caption=caption.strip())
    start = time.perf_counter()
    try:
        written = module.main(out_dir, fast=fast)
    except TurntablePinError as exc:
        run.skipped = str(exc)
        written = []
    run.seconds = time.perf_counter() - start
    for path in written or []:
        path = Path(path)
        if not path.is_file():
            raise FileNotFoundError(f"{script.name} says it wrote {path}, which does not exist")
        run.images.append(path.resolve().relative_to(out_dir.resolve()).as_posix())
    if not run.images and run.skipped is None:
        raise RuntimeError(f"{script.name} wrote no figure")
    return run


def index_page(runs: list[FigureRun], fast: bool) -> str:
    """The HTML index: every figure with its title, caption and timing."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8"><title>turntable-pin figures</title>',
        "<style>body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
        "figure{margin:1.5em 0;border-top:1px solid #ccc;padding-top:1em}"
        "img{max-width:100%;height:auto;display:block;margin:.5em 0}"
        "figcaption{color:#333;white-space:pre-line}.skip{color:#a00}</style></head><body>",
        "<h1>turntable-pin figures</h1>",
        f"<p>{len(runs)} figure scripts{' (fast settings)' if fast else ''}; regenerate with "
        "<code>python viz/make_all.py -o DIR</code>.</p>",
    ]
    for run in runs:
        parts.append(f'<figure id="{html.escape(Path(run.script).stem)}">')
        parts.append(f"<h2>{html.escape(run.title)}</h2>")
        for image in run.images:
            parts.append(f'<img src="{html.escape(image)}" alt="{html.escape(run.title)}">')
        if run.skipped is not None:
            parts.append(f'<p class="skip">skipped: {html.escape(run.skipped)}</p>')
        parts.append(
            f"<figcaption>{html.escape(run.caption)}\n"
            f"<small>{html.escape(run.script)}, {run.seconds:.1f} s</small></figcaption>"
        )
        parts.append("</figure>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def make_all(out_dir: Path, fast: bool = False, pattern: str = "fig_*.py") -> list[FigureRun]:
    """Run every matching figure script into ``out_dir`` and write ``out_dir/index.html``."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    scripts = discover(pattern)
    if not scripts:
        raise FileNotFoundError(f"no figure script matches {VIZ_DIR / pattern}")
    runs = []
    for script in scripts:
        run = run_script(script, out_dir, fast)
        status = f"skipped ({run.skipped})" if run.skipped else f"{len(run.images)} image(s)"
        print(f"{script.name}: {status}, {run.seconds:.1f} s", flush=True)
        runs.append(run)
    write_text_atomic(out_dir / "index.html", index_page(runs, fast))
    return runs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("-o", "--output", type=Path, default=Path("figures"), metavar="DIR")
    parser.add_argument(
        "--fast", action="store_true", help="coarse settings (seconds, not minutes)"
    )
    parser.add_argument("--only", default="", metavar="TEXT", help="only scripts fig_*TEXT*.py")
    args = parser.parse_args(argv)
    pattern = f"fig_*{args.only}*.py" if args.only else "fig_*.py"
    make_all(args.output, fast=args.fast, pattern=pattern)
    print(f"wrote {args.output / 'index.html'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
