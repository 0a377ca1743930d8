"""Verdict rates of issue 29: over seeded simulated runs and orientation sets, how often the
diagnosis names several simple causes as such, a true many-parameter effect, nothing on clean
data, and never an implausible amplitude; and the verdicts on the two real pointing runs.

Run by hand, from the repository's root:
    python benchmarks/verdict_rates.py [--seeds 50] [--clean-seeds 20] [--cases R1,O3]
                                       [--seed 1000] [--json OUT.json] [--no-real]

The cases (what each plants, sizes, how a verdict is scored) are defined once in
``tests/verdict_cases.py``, which ``tests/stats/test_verdict_rates.py`` runs on a few seeds. Case
k of N uses seeds ``--seed`` .. ``--seed + N - 1``; every diagnosis runs in this process, with
one BLAS thread, timed alone (simulation excluded). Progress goes to stderr; the table to
stdout; ``--json`` writes the seeds, each seed's named effects, their groups and the verdict's
score, per case and for the real runs.
"""

from __future__ import annotations

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from verdict_cases import (  # noqa: E402
    CASES,
    CASES_BY_NAME,
    CLEAN,
    IMPLAUSIBLE,
    MANY,
    REAL_RUNS,
    SIMPLE,
    real_verdict,
    run_case,
    timed,
)

TARGETS = {
    SIMPLE: "named as such",
    MANY: "named",
    CLEAN: "nothing named",
    IMPLAUSIBLE: "marked, unnamed",
}


def _cases(text: str | None):
    if not text:
        return list(CASES)
    names = [n.strip() for n in text.split(",") if n.strip()]
    unknown = [n for n in names if n not in CASES_BY_NAME]
    if unknown:
        raise SystemExit(f"unknown case(s) {', '.join(unknown)}; cases: {', '.join(CASES_BY_NAME)}")
    return [CASES_BY_NAME[n] for n in names]


def _engine_source() -> dict:
    """Where the measured ``turntable_pin`` was imported from, and that checkout's commit."""
    import turntable_pin

    folder = Path(turntable_pin.__file__).resolve().parent
    try:
        out = subprocess.run(  # noqa: S603 - git, fixed arguments
            ["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True,
            cwd=folder,
        )  # fmt: skip
        commit = out.stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        commit = None
    return {"package": str(folder), "commit": commit}


def measure_case(case, seeds: list[int]) -> dict:
    """Every seed of ``case`` run and scored, with the counts and the rate of its target."""
    per_seed = []
    for i, seed in enumerate(seeds, start=1):
        print(f"{case.name} seed {i}/{len(seeds)} ({seed})", file=sys.stderr, flush=True)
        per_seed.append(run_case(case, seed))
    ok = sum(r["ok"] for r in per_seed)
    seconds = [r["seconds"] for r in per_seed]
    return {
        "case": case.name,
        "diagnosis": case.diagnosis,
        "kind": case.kind,
        "title": case.title,
        "planted": list(case.planted),
        "target": TARGETS[case.kind],
        "n": len(seeds),
        "ok": ok,
        "rate": ok / len(seeds),
        "exact": sum(r["exact"] for r in per_seed),
        "false_names": sum(len(r["named"]) for r in per_seed) if case.kind == CLEAN else None,
        "implausible_named": sum(bool(r["implausible_named"]) for r in per_seed),
        "seconds_mean": sum(seconds) / len(seconds),
        "seconds_max": max(seconds),
        "seeds": per_seed,
    }


def _verdict_counts(per_seed: list[dict]) -> str:
    counts: dict[str, int] = {}
    for r in per_seed:
        key = " + ".join(r["named"]) or "(nothing)"
        counts[key] = counts.get(key, 0) + 1
    top = sorted(counts.items(), key=lambda kv: -kv[1])[:3]
    return "; ".join(f"{n}x {k}" for k, n in top)


def print_table(results: list[dict], real: list[dict]) -> None:
    print(f"{'case':5s}{'kind':12s}{'target':>15s}{'ok':>9s}{'rate':>8s}{'impl.':>7s}{'s/diag':>8s}"
          "  most frequent verdicts")  # fmt: skip
    for r in results:
        print(
            f"{r['case']:5s}{r['kind']:12s}{r['target']:>15s}{r['ok']:>4d}/{r['n']:<4d}"
            f"{100 * r['rate']:7.1f}%{r['implausible_named']:>7d}{r['seconds_mean']:8.2f}  "
            f"{_verdict_counts(r['seeds'])}"
        )
        print(f"{'':5s}{r['title']}")
    for run in real:
        named = run["named"] or "nothing"
        print(f"{run['name']} (real run, {run['seconds']:.1f} s): named {named}")
        for name, params in run["amplitudes"].items():
            values = ", ".join(
                f"{p['name'].split('.')[-1]} {p['value']:.4g}"
                + (f" +- {p['std']:.2g}" if p.get("std") else "")
                for p in params
            )
            print(f"    {name}: {values} {params[0]['unit'] if params else ''}")
        for c in run["significant"]:
            mark = f"  IMPLAUSIBLE: {c['implausible']}" if c["implausible"] else ""
            print(f"    candidate {c['effect']}: delta_bic {c['delta_bic']:.0f}, largest "
                  f"|parameter| {c['largest'] or 0:.4g} {c['unit'] or ''}{mark}")  # fmt: skip
        print(f"    marked implausible: {run['marked_implausible'] or 'none'}; "
              f"named among them: {run['implausible_named'] or 'none'}")  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=50, help="seeds per case (default 50)")
    parser.add_argument("--clean-seeds", type=int, default=20, help="seeds per clean case")
    parser.add_argument("--cases", help="comma-separated subset, e.g. R1,O3 (default all)")
    parser.add_argument("--seed", type=int, default=1000, help="first seed (default 1000)")
    parser.add_argument("--json", type=Path, help="write the results here")
    parser.add_argument("--no-real", action="store_true", help="skip the real runs")
    args = parser.parse_args()
    if args.seeds < 1 or args.clean_seeds < 1:
        raise SystemExit("--seeds and --clean-seeds must be >= 1")
    start = time.perf_counter()
    results = []
    for case in _cases(args.cases):
        n = args.clean_seeds if case.kind == CLEAN else args.seeds
        results.append(measure_case(case, list(range(args.seed, args.seed + n))))
    real = []
    if not args.no_real:
        for run in REAL_RUNS:
            print(f"{run.name} (real run)", file=sys.stderr, flush=True)
            d, seconds = timed(run.diagnosis)
            real.append({"name": run.name, "path": run.path.name, "seconds": seconds,
                         **real_verdict(d)})  # fmt: skip
    total = time.perf_counter() - start
    print_table(results, real)
    print(f"total wall time {total / 60:.2f} min (one process, one BLAS thread)")
    if args.json:
        out = {
            "engine": _engine_source(),
            "first_seed": args.seed,
            "seeds": args.seeds,
            "clean_seeds": args.clean_seeds,
            "total_seconds": total,
            "cases": results,
            "real_runs": real,
        }
        args.json.write_text(json.dumps(out, indent=1) + "\n", encoding="utf-8")
        print(f"wrote {args.json}")


if __name__ == "__main__":
    main()
