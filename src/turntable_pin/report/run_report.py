"""The diagnosis of a calibration run in words, figures and one HTML page.

Three views of one structured result (``Diagnosis.to_dict()`` of
:func:`~turntable_pin.instrument.diagnosis.diagnose_run`): the text opens with the verdict
(which effect is missing, on the table's side or the instrument's); the HTML page tells the same
story with the residuals against each joint angle, time and temperature before and
after; the figures are written once by :func:`write_run_plots`.
"""

from __future__ import annotations

import html
from pathlib import Path

from ..core.files import write_text_atomic
from .diagnosis_text import diagnosis_lines, headline, verdict_lines
from .html_report import PAGE_STYLE, html_table, img_tag
from .measurement_figures import (
    harmonics_figure,
    residual_figure,
    structure_term_figure,
    write_residual_plots,
    write_structure_plots,
)

__all__ = [
    "coefficient_lines",
    "other_side_lines",
    "run_diagnosis_html",
    "run_report_lines",
    "write_run_plots",
    "write_run_report",
]


def coefficient_lines(d: dict) -> list[str]:
    """The calibrated coefficients of the best model, both axes (deg/h-based units)."""
    lines = ["coefficients of the final model (value +- std):"]
    for axis, terms in d["coefficients_dph"].items():
        for name, entry in terms.items():
            std = "-" if entry["std"] is None else f"{entry['std']:.3g}"
            lines.append(f"  D{axis}{name:3s} = {entry['value']:12.6f} +- {std} {entry['unit']}")
    return lines


def _table_lines(d: dict) -> list[str]:
    t = d["table_from_run"]
    lines = [
        f"the table from the run: its {len(t['errors'])} errors add {t['rank_added']} "
        f"combination(s) the outputs determine (noise {t['sigma_dph']:.3g} deg/h):"
    ]
    lines += [f"  {c['name']} = {c['value']:.3g} +- {c['std']:.2g} {c['unit']}"
              for c in t["determined"]]  # fmt: skip
    absorbed = [f"{a['error']} ({a['correlation']:.2f})" for a in t["absorbed"]]
    if t["with_coefficients"]:
        lines.append("  determined only together with the instrument's coefficients: "
                     + "; ".join(c["name"] for c in t["with_coefficients"][:6]))  # fmt: skip
    if absorbed:
        lines.append(f"  mostly absorbed by the coefficients (correlation > "
                     f"{t['absorbed_above']:g}: the calibration takes them for instrument terms): "
                     + ", ".join(absorbed))  # fmt: skip
    if t["undetermined"]:
        lines.append("  not seen at all (only the sums above are): "
                     + "; ".join(t["undetermined"][:6]))  # fmt: skip
    return lines


def other_side_lines(d: dict) -> list[str]:
    """The effects of the other side (table vs instrument) that move the outputs like the one
    named, on the run's positions: the confounded explanations, and what would separate them."""
    verdict = d["verdict"]
    rivals = verdict.get("other_side", [])
    if not verdict["missing_effect"]:
        return []
    other = "instrument" if verdict["side"] == "table" else "table"
    if not rivals:
        return [
            f"the other side: no effect of the {other} moves the outputs like "
            f"{verdict['missing_effect']} on these positions"
        ]
    lines = [
        f"the other side: on these positions, {len(rivals)} effect(s) of the "
        f"{other} move the outputs like "
        f"{verdict['missing_effect']} (confounded: the run alone cannot say which side it is):"
    ]
    commands = verdict.get("separation_commands", {})
    for r in rivals:
        lines.append(f"  {r['effect']} (noise-free misfit chi2 {r['chi2_run']:.2g} here): "
                     f"{r['words']}")  # fmt: skip
        if r["effect"] in commands:
            lines.append(f"    to settle it, design the next positions: {commands[r['effect']]}")
    return lines


def run_report_lines(d: dict) -> list[str]:
    """The whole run diagnosis in words: verdict first, then the candidates, the verdict's
    reasons, the confounded explanations of the other side, the coefficients and what the run
    tells about the table."""
    data = d.get("source") or "RUN.csv"
    return [*diagnosis_lines(d, data=data), *other_side_lines(d), *coefficient_lines(d),
            *_table_lines(d)]  # fmt: skip


def write_run_plots(diagnosis, directory: str | Path) -> list[Path]:
    """Residuals against each joint angle, time and extra columns (before and after), their
    harmonics, the residual maps, and each structure term, as PNGs into ``directory``."""
    from ..instrument.diagnosis import run_diagnosis_residuals

    base, best = run_diagnosis_residuals(diagnosis)
    sets = [base, best] if diagnosis.steps else [base]
    return [*write_residual_plots(sets, directory), *write_structure_plots(diagnosis.structure,
                                                                           directory)]  # fmt: skip


_FIT_HEADER = ["model", "rms (deg/h)", "chi2_reduced", "rank", "params"]


def _fit_row(label: str, summary: dict) -> list:
    """One row of a table of fits: its label, rms, chi2_reduced, rank and parameter count."""
    return [label, summary["rms_dph"], summary["chi2_reduced"], summary["rank"],
            summary["n_params"]]  # fmt: skip


def run_diagnosis_html(diagnosis, d: dict, *, title: str = "") -> str:
    """The self-contained HTML page of a run diagnosis (``d``: its structured result)."""
    from ..instrument.diagnosis import run_diagnosis_residuals
    from ..measurement.residuals import analyse_residuals

    verdict = d["verdict"]
    base_rs, best_rs = run_diagnosis_residuals(diagnosis)
    explained = not verdict["unexplained"]
    parts = [f"<h1>{html.escape(title or 'GyroWheel calibration run diagnosis')}</h1>"]
    parts.append(
        f'<p class="verdict headline{"" if explained else " warn"}">{html.escape(headline(d))}</p>'
    )
    sigma = (
        "from the file's <code>sigma_dph</code> column"
        if d["sigma_source"] == "column"
        else f"not given: estimated, {d['sigma_dph']:.3g} deg/h"
    )
    parts.append(
        f"<p>Run <code>{html.escape(str(d.get('source') or ''))}</code>: {d['n_positions']} "
        f"positions, {d['n_observations']} outputs, latitude {d['latitude_deg']:g} deg; noise "
        f"{sigma}.</p>"
    )
    parts += [f'<p class="verdict warn">warning: {html.escape(w)}</p>' for w in d["warnings"]]
    parts.append(
        "<h2>1. The base model: eq. 1's 2 x 7 coefficients</h2>"
        + html_table(_FIT_HEADER, [_fit_row("base", d["base"])])
    )
    if not verdict["missing_effect"]:
        parts.append(img_tag(residual_figure([base_rs]), "base residuals"))
    parts.append("<h2>2. Which effect is missing: the table or the instrument?</h2>")
    parts.append(
        html_table(
            ["effect", "side", "delta BIC", "rms (deg/h)", "chi2_reduced", "new rank", "same as"],
            [
                [
                    c["effect"],
                    verdict["sides"].get(c["effect"], ""),
                    "-" if c["delta_bic"] is None else f"{c['delta_bic']:.1f}",
                    "-" if c["rms_dph"] is None else c["rms_dph"],
                    "-" if c["chi2_reduced"] is None else c["chi2_reduced"],
                    c["added_rank"] if c["testable"] else "-",
                    ", ".join(c["alternatives"]),
                ]
                for c in d["candidates"]
            ],
        )  # fmt: skip
    )
    lines = [*verdict_lines(d, d.get("source") or ""), *other_side_lines(d)]
    words = "<br>".join(html.escape(line) for line in lines)
    parts.append(f'<div class="verdict{"" if explained else " warn"}">{words}</div>')
    for term in diagnosis.structure:
        parts.append(f"<p><b>{html.escape(term.name)}</b>: {html.escape(term.description)}</p>")
        if term.factors is not None and term.residual_weighted is not None:
            parts.append(img_tag(structure_term_figure(term), f"structure: {term.name}"))
    if verdict["missing_effect"]:
        parts.append(
            "<h2>3. Add it and watch the error fall</h2>"
            + html_table(
                _FIT_HEADER,
                [_fit_row("base", d["base"])]
                + [_fit_row(f"+ {s['added']}", s) for s in d["steps"]],
            )
            + img_tag(residual_figure([base_rs, best_rs]), "residuals before and after")
            + img_tag(
                harmonics_figure([analyse_residuals(base_rs), analyse_residuals(best_rs)]),
                "harmonics before and after",
            )
        )
    parts.append("<h2>4. Coefficients and the table</h2><p>"
                 + "<br>".join(html.escape(x) for x in coefficient_lines(d)) + "</p><p>"
                 + "<br>".join(html.escape(x) for x in _table_lines(d)) + "</p>")  # fmt: skip
    body = "\n".join(parts)
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title or 'turntable-pin run report')}</title><style>{PAGE_STYLE}"
        f"</style></head><body>{body}</body></html>\n"
    )


def write_run_report(diagnosis, d: dict, path: str | Path, *, title: str = "") -> Path:
    """Write :func:`run_diagnosis_html` to ``path`` atomically."""
    return write_text_atomic(path, run_diagnosis_html(diagnosis, d, title=title))
