"""One self-contained HTML page telling the whole story of a measurement file.

The one-line verdict first, then data, base fit, where it fails (a residual map over both
angles), the diagnosis (with a plot of each term the structure search finds against its
variable), the fit with the missing effect(s) and the parameters, with every plot embedded once
as a base64 PNG (the page needs no other file).
"""

from __future__ import annotations

import base64
import html
from pathlib import Path

import numpy as np

from ..core.files import write_text_atomic
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..measurement.data import ANGLE_NAMES
from ..measurement.diagnosis import diagnosis_residuals
from ..measurement.residuals import analyse_residuals
from ..stats.model_selection import Diagnosis
from .diagnosis_text import headline, verdict_lines
from .figures import pyplot, save_png
from .measurement_figures import (
    COLOURS,
    harmonics_figure,
    map_limit,
    not_measured_note,
    residual_figure,
    residual_map_figure,
    structure_term_figure,
)

PAGE_STYLE = """
body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;padding:0 1em;color:#222}
h1{font-size:1.5em}h2{font-size:1.2em;border-bottom:1px solid #ccc;margin-top:2em}
table{border-collapse:collapse;font-size:.9em;margin:.5em 0}
td,th{border:1px solid #ddd;padding:.25em .6em;text-align:right}th{background:#f4f4f4}
td.l,th.l{text-align:left}.verdict{background:#eef6ee;padding:.8em;border-left:4px solid #3a3}
.warn{background:#fbf1e6;border-left-color:#d80}img{max-width:100%}code{background:#f4f4f4}
.headline{font-size:1.1em;font-weight:600;margin:.4em 0 1em}
"""


def img_tag(png: bytes, alt: str) -> str:
    """An ``<img>`` with the PNG embedded as base64 (the page needs no other file)."""
    data = base64.b64encode(png).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:image/png;base64,{data}">'


def html_table(header: list[str], rows: list[list], left: int = 1) -> str:
    """An HTML table (floats to 4 digits; the first ``left`` columns aligned left)."""

    def cell(v, i, tag):
        cls = ' class="l"' if i < left else ""
        if isinstance(v, float):
            v = f"{v:.4g}"
        return f"<{tag}{cls}>{html.escape(str(v))}</{tag}>"

    out = ["<table><tr>" + "".join(cell(h, i, "th") for i, h in enumerate(header)) + "</tr>"]
    for row in rows:
        out.append("<tr>" + "".join(cell(v, i, "td") for i, v in enumerate(row)) + "</tr>")
    return "".join(out) + "</table>"


def data_figure(data) -> bytes:
    """PNG: the measured angles against the last joint's angle (phi2 on a two-axis table), one
    panel per angle measured at some position, coloured by the first joint's (phi1); one joint:
    against phi1. The angles not measured at every position are named on the figure."""
    from matplotlib.colors import Normalize

    plt = pyplot()

    counts = data.measured.sum(axis=0)
    drawn = np.flatnonzero(counts > 0)  # a row measures at least one angle: never empty
    fig, axes = plt.subplots(
        1, len(drawn), figsize=(14 * len(drawn) / 3, 3.6), layout="constrained", squeeze=False
    )
    last = data.n_joints
    x = data.joint_rad[:, last - 1] * DEG_PER_RAD
    colour = data.joint_rad[:, 0] * DEG_PER_RAD
    norm = Normalize(float(colour.min()), float(colour.max()))  # one scale for every panel
    for ax, i in zip(axes[0], drawn, strict=True):
        name, ok = ANGLE_NAMES[i], data.measured[:, i]
        sc = ax.scatter(x[ok], data.angles_rad[ok, i] * ARCSEC_PER_RAD, c=colour[ok], s=10,
                        cmap="viridis", norm=norm)  # fmt: skip
        ax.set_xlabel(f"phi{last} (deg)")
        ax.set_ylabel(f"{name} (arcsec)")
        ax.set_title(f"measured {name}", fontsize=10, color=COLOURS[i])
    note = not_measured_note(ANGLE_NAMES, counts, data.n_positions)
    if note:
        fig.suptitle(note, fontsize=10)
    fig.colorbar(sc, ax=axes[0].tolist(), label="phi1 (deg)")
    return save_png(fig)


def _fit_rows(diagnosis: Diagnosis, fits) -> list[list]:
    rows = []
    for label, fit in fits:
        s = diagnosis.summary(fit)
        rows.append(
            [label, s["rms_arcsec"], s["chi2_reduced"], s["rank"], s["n_params"],
             "-" if s["p_value"] is None else f"{s['p_value']:.3g}"]
        )  # fmt: skip
    return rows


def _structure_section(diagnosis: Diagnosis, best_fit) -> list[str]:
    """HTML of the terms the structure search finds: words and one plot per term."""
    terms = diagnosis.structure
    if not terms:
        return []
    label = " + ".join(("base", *best_fit.effect_names))
    parts = [
        f"<h3>Structure left in the residuals of {html.escape(label)}</h3><p>The structure "
        "search (harmonic shapes of each turntable error and of each measured angle, drifts, "
        "steps with the approach direction) finds the term(s) below. Each plot shows the "
        "residual, with this term's fitted part added back, projected at each position onto "
        "the direction the term enters the measured angles along, against the variable of "
        "the term, with the fitted term over it and the noise of one point as a grey "
        "band.</p>"
    ]
    for term in terms:
        words = (
            f"<p><b>{html.escape(term.name)}</b>: {html.escape(term.description)}, amplitude "
            f"{term.amplitude:.3g} {html.escape(term.unit)}, delta BIC {term.delta_bic:.0f}.</p>"
        )
        if term.factors is not None and term.residual_weighted is not None:
            words += img_tag(structure_term_figure(term), f"structure: {term.name}")
        parts.append(words)
    return parts


def diagnosis_html(diagnosis: Diagnosis, *, title: str = "") -> str:
    """The HTML page of a diagnosis (self-contained)."""
    data = diagnosis.family.data
    d = diagnosis.to_dict()
    verdict = d["verdict"]
    base_fit = diagnosis.base_fit.with_noise_variance(diagnosis.noise_variance)
    best_fit = diagnosis.best_fit.with_noise_variance(diagnosis.noise_variance)
    base_rs, best_rs = diagnosis_residuals(diagnosis)
    base_an = analyse_residuals(base_rs)
    explained = not verdict["unexplained"]
    parts = [f"<h1>{html.escape(title or 'Turntable measurement diagnosis')}</h1>"]
    parts.append(
        f'<p class="verdict headline{"" if explained else " warn"}" id="verdict">'
        f"{html.escape(headline(d))}</p>"
    )
    counts = data.measured.sum(axis=0)
    unmeasured = not_measured_note(ANGLE_NAMES, counts, data.n_positions, separator="; ")
    parts.append(
        f"<p>Source: <code>{html.escape(data.source)}</code> &mdash; {data.n_positions} "
        f"positions, {int(data.measured.sum())} measured angles"
        + (
            f" ({html.escape(unmeasured)}; the fits and plots use the measured angles only)"
            if unmeasured
            else ""
        )
        + "; noise sigma "
        + (
            f"from the file's <code>sigma_arcsec</code> column (median {d['sigma_arcsec']:.3g} "
            "arcsec)."
            if diagnosis.sigma_known
            else f"not given: estimated from the best fit, {d['sigma_arcsec']:.3g} arcsec."
        )
        + "</p>"
    )
    parts += [f'<p class="verdict warn">warning: {html.escape(w)}</p>' for w in d["warnings"]]
    if d.get("outliers"):
        parts.append(
            f"<p>{len(d['outliers'])} gross outlier(s) were left out of every fit (shown here, "
            f"not silently dropped; rule: {html.escape(d['outlier_rule'])}):</p>"
            + html_table(
                ["row", "angle", "residual (sigma, final model)"],
                [[o["row"], o["angle"], o["residual_sigma"]] for o in d["outliers"][:50]],
            )
        )
    parts.append("<h2>1. The data</h2>" + img_tag(data_figure(data), "measured angles"))
    b = d["base"]
    parts.append(
        "<h2>2. The base model</h2><p>"
        + (
            "The nine turntable errors of the paper (the intersection error never changes the "
            "orientation, so eight angles are fitted)."
            if diagnosis.family.table.paper
            else f"The {len(diagnosis.family.table.base_names)} rotation errors of the table "
            f"{html.escape(diagnosis.family.table.label)} (its offsets never change the "
            "orientation)."
        )
        + f" The data determine {b['rank']} combinations of them:</p>"
    )
    combos = base_fit.result.combinations()
    parts.append(
        html_table(
            ["combination", "value", "std", "unit"],
            [[c["name"], c["value"], c["std"], c["unit"]] for c in combos],
        )
    )
    und = base_fit.result.undetermined_combinations()
    if und:
        parts.append(
            "<p>Not determined by orientation data (flat directions): "
            + ", ".join(f"<code>{html.escape(u)}</code>" for u in und)
            + ".</p>"
        )
    parts.append(
        html_table(
            ["model", "rms (arcsec)", "chi2_reduced", "rank", "params", "p-value"],
            _fit_rows(diagnosis, [("base", base_fit)]),
        )
    )
    failing = base_an.failing
    parts.append(
        f"<h2>3. Where the base model fails</h2><p>{len(failing)} of {data.n_positions} "
        f"positions have a residual beyond {base_an.k_sigma:g} sigma.</p>"
    )
    if failing:
        joints = range(1, data.n_joints + 1)
        parts.append(
            html_table(
                ["row", *(f"phi{k} (deg)" for k in joints), "angle", "residual (arcsec)", "sigmas"],
                [
                    [
                        f["row"],
                        *(f[f"phi{k}_deg"] for k in joints),
                        f["component"],
                        f["residual_arcsec"],
                        f["sigmas"],
                    ]
                    for f in failing[:15]
                ],
            )  # fmt: skip
        )
    limit = map_limit([base_rs, best_rs])
    base_map = residual_map_figure([base_rs], limit)
    if base_map is not None:
        parts.append(
            "<p>The residuals over both angles (one square per position, repeats averaged): "
            "structure in phi1 and phi2 at once shows here, while the plots against one angle "
            "average over the other.</p>" + img_tag(base_map, "base residual map")
        )
    if not verdict["missing_effect"]:  # else shown before/after in section 5
        parts.append(img_tag(residual_figure([base_rs]), "base residuals"))
        parts.append(img_tag(harmonics_figure([base_an]), "base harmonics"))
    cls = "verdict" if not verdict["unexplained"] else "verdict warn"
    parts.append("<h2>4. Diagnosis: which physical effect is missing?</h2>")
    first = verdict["missing_effect"]
    parts.append(
        html_table(
            [
                "effect",
                "delta BIC",
                f"on top of {first}" if first else "-",
                "rms (arcsec)",
                "chi2_reduced",
                "new rank",
                "same as",
            ],
            [
                [
                    c["effect"],
                    "-" if c["delta_bic"] is None else f"{c['delta_bic']:.1f}",
                    "-"
                    if c.get("delta_bic_after_first") is None
                    else f"{c['delta_bic_after_first']:.1f}",
                    "-" if c["rms_arcsec"] is None else c["rms_arcsec"],
                    "-" if c["chi2_reduced"] is None else c["chi2_reduced"],
                    c["added_rank"] if c["testable"] else "-",
                    ", ".join(c["alternatives"]),
                ]
                for c in d["candidates"]
            ],
        )  # fmt: skip
    )
    notes = [f"<li><b>{html.escape(c['effect'])}</b>: {html.escape(c['reason'])}</li>"
             for c in d["candidates"] if c.get("reason")]  # fmt: skip
    if notes:
        parts.append("<p>Not testable here:</p><ul>" + "".join(notes) + "</ul>")
    words = "<br>".join(html.escape(line) for line in verdict_lines(d, data.source or "DATA.csv"))
    parts.append(f'<div class="{cls}">{words}</div>')
    if verdict["missing_effect"]:
        story = verdict["effect_story"]
        parts.append(
            f"<p><b>{html.escape(story['effect'])}</b> &mdash; {html.escape(story['title'])}. "
            f"Definition: <code>{html.escape(story['definition'])}</code>.</p>"
            f"<p>{html.escape(story['explanation'])}</p>"
            f"<p><i>How to confirm it on the machine:</i> {html.escape(story['confirm'])}</p>"
        )
    parts += _structure_section(diagnosis, best_fit)
    if verdict["missing_effect"]:
        best_an = analyse_residuals(best_rs)
        parts.append(
            "<h2>5. Add it and watch the error fall</h2>"
            + html_table(
                ["model", "rms (arcsec)", "chi2_reduced", "rank", "params", "p-value"],
                _fit_rows(diagnosis, [("base", base_fit)])
                + [
                    [
                        f"+ {s['added']}",
                        s["rms_arcsec"],
                        s["chi2_reduced"],
                        s["rank"],
                        s["n_params"],
                        "-" if s["p_value"] is None else f"{s['p_value']:.3g}",
                    ]
                    for s in d["steps"]
                ],
            )  # fmt: skip
            + img_tag(residual_figure([base_rs, best_rs]), "residuals before and after")
            + img_tag(harmonics_figure([base_an, best_an]), "harmonics before and after")
        )
        best_map = residual_map_figure([best_rs], limit)
        if best_map is not None:
            parts.append(
                "<p>The residual map after, on the colour scale of the map in section 3:</p>"
                + img_tag(best_map, "residual map after")
            )
    res = best_fit.result
    parts.append(
        "<h2>6. Parameters of the final model</h2><p>Determined combinations (value &plusmn; "
        f"standard error; rank {res.rank} of {res.n_params} parameters):</p>"
    )
    parts.append(
        html_table(
            ["combination", "value", "std", "unit"],
            [[c["name"], c["value"], c["std"], c["unit"]] for c in res.combinations()],
        )
    )
    und = res.undetermined_combinations()
    if und:
        parts.append(
            "<p>Flat directions: "
            + ", ".join(f"<code>{html.escape(u)}</code>" for u in und)
            + ".</p>"
        )
    parts.append(
        "<p style='color:#777;font-size:.85em'>Decision rule: an effect is accepted when it "
        "lowers BIC by 6 or more; effects whose fit is as good are listed as alternatives; the "
        "final model is 'unexplained' when it fails the chi2 test (sigma given) or a harmonic "
        "structure search still finds a term.</p>"
    )
    body = "\n".join(parts)
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title or 'turntable-pin report')}</title><style>{PAGE_STYLE}</style>"
        f"</head><body>{body}</body></html>\n"
    )


def write_report(diagnosis: Diagnosis, path: str | Path, *, title: str = "") -> Path:
    """Write :func:`diagnosis_html` to ``path`` atomically."""
    return write_text_atomic(path, diagnosis_html(diagnosis, title=title))


__all__ = ["PAGE_STYLE", "data_figure", "diagnosis_html", "html_table", "img_tag", "write_report"]
