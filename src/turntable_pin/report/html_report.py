"""One self-contained HTML page telling the whole story of a diagnosis, of any family of data.

:func:`diagnosis_html` is the one builder: the one-line verdict, then the sections the family
lists in its :class:`~turntable_pin.stats.diagnosis_engine.PageWords` (data, fits, where it
fails, the diagnosis, the missing effect and its parameters; a run's coefficients and table),
each rendered from the one result (``Diagnosis.to_dict()`` and its fits), every plot embedded
once as a base64 PNG (the page needs no other file).
"""

# matplotlib is imported inside functions: import turntable_pin stays light
from __future__ import annotations

import base64
import html
from pathlib import Path

import numpy as np

from ..core.files import write_text_atomic
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..measurement.data import ANGLE_NAMES
from ..measurement.residuals import analyse_residuals
from ..stats.diagnosis_engine import DATA_PLACEHOLDER, residual_sets
from ..stats.model_selection import Diagnosis
from .diagnosis_text import (
    coefficient_lines,
    decision_rule_words,
    headline,
    other_side_lines,
    table_from_run_lines,
    verdict_lines,
)
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


class _Page:
    """What the sections of one page share: the result, its residual sets and figures' inputs
    (each computed once)."""

    def __init__(self, diagnosis: Diagnosis) -> None:
        self.diagnosis = diagnosis
        self.family = diagnosis.family
        self.words = diagnosis.family.page
        self.d = diagnosis.to_dict()
        self.verdict = self.d["verdict"]
        self.effect = self.verdict["missing_effect"]
        self.base_rs, self.best_rs = residual_sets(diagnosis)
        self.base_an = analyse_residuals(self.base_rs)
        self.limit = map_limit([self.base_rs, self.best_rs])
        self.names = {name for name, _ in self.words.sections}

    def fit_table(self, rows: list[tuple[str, dict]]) -> str:
        """The table of fits ``(label, summary)`` in the family's columns."""
        unit = self.family.unit_words
        key = f"rms_{self.family.observation_unit}"
        header = {"rms": f"rms ({unit})", "chi2_reduced": "chi2_reduced", "rank": "rank",
                  "n_params": "params", "p_value": "p-value"}  # fmt: skip

        def cell(column, s):
            if column == "p_value":
                return "-" if s["p_value"] is None else f"{s['p_value']:.3g}"
            return s[key if column == "rms" else column]

        columns = self.words.fit_columns
        return html_table(
            ["model", *(header[c] for c in columns)],
            [[label, *(cell(c, s) for c in columns)] for label, s in rows],
        )


def _heading(text: str) -> str:
    return f"<h2>{text}</h2>" if text else ""


def _measurement_intro(page: _Page, heading: str) -> list[str]:
    """The measurement file, its positions and measured angles, and where its noise comes from."""
    data, d = page.family.data, page.d
    counts = data.measured.sum(axis=0)
    unmeasured = not_measured_note(ANGLE_NAMES, counts, data.n_positions, separator="; ")
    return [
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
            if page.diagnosis.sigma_known
            else f"not given: estimated from the best fit, {d['sigma_arcsec']:.3g} arcsec."
        )
        + "</p>"
    ]


def _run_intro(page: _Page, heading: str) -> list[str]:
    """The run file, its positions and outputs, its latitude and where its noise comes from."""
    d = page.d
    sigma = (
        "from the file's <code>sigma_dph</code> column"
        if d["sigma_source"] == "column"
        else f"not given: estimated, {d['sigma_dph']:.3g} deg/h"
    )
    return [
        f"<p>Run <code>{html.escape(str(d.get('source') or ''))}</code>: {d['n_positions']} "
        f"positions, {d['n_observations']} outputs, latitude {d['latitude_deg']:g} deg; noise "
        f"{sigma}.</p>"
    ]


def _warnings(page: _Page, heading: str) -> list[str]:
    return [f'<p class="verdict warn">warning: {html.escape(w)}</p>' for w in page.d["warnings"]]


def _outliers(page: _Page, heading: str) -> list[str]:
    """The observations left out as gross outliers, shown (never silently dropped)."""
    d = page.d
    if not d.get("outliers"):
        return []
    key = page.family.column_key
    return [
        f"<p>{len(d['outliers'])} gross outlier(s) were left out of every fit (shown here, "
        f"not silently dropped; rule: {html.escape(d['outlier_rule'])}):</p>"
        + html_table(
            ["row", key, "residual (sigma, final model)"],
            [[o["row"], o[key], o["residual_sigma"]] for o in d["outliers"][:50]],
        )
    ]


def _data(page: _Page, heading: str) -> list[str]:
    return [_heading(heading) + img_tag(data_figure(page.family.data), "measured angles")]


def flat_directions(result, words: str) -> list[str]:
    """A fit's undetermined combinations after ``words``: one paragraph, or none."""
    und = result.undetermined_combinations()
    if not und:
        return []
    return [f"<p>{words}: " + ", ".join(f"<code>{html.escape(u)}</code>" for u in und) + ".</p>"]


def combinations_table(result) -> str:
    """The table of the combinations a fit's data determine: value, standard error, unit."""
    return html_table(
        ["combination", "value", "std", "unit"],
        [[c["name"], c["value"], c["std"], c["unit"]] for c in result.combinations()],
    )


def _base(page: _Page, heading: str) -> list[str]:
    """The base model, the combinations of its errors the data determine (``base_errors``) and
    its fit; without a missing effect and without a section on where it fails, its residuals."""
    table = page.fit_table([("base", page.d["base"])])
    if "base_errors" not in page.words.parts:
        parts = [_heading(heading) + table]
    else:
        measured = page.family.table
        result = page.diagnosis.base_fit.result
        parts = [
            _heading(heading)
            + "<p>"
            + f"The {len(measured.base_names)} rotation errors of {html.escape(measured.title)} "
            f"(its {len(measured.chain.error_names) - len(measured.base_names)} offset error(s) "
            "never change the orientation)."
            + f" The data determine {page.d['base']['rank']} combinations of them:</p>",
            combinations_table(result),
        ]
        parts += flat_directions(result, "Not determined by orientation data (flat directions)")
        parts.append(table)
    if not page.effect and "fails" not in page.names:
        parts.append(img_tag(residual_figure([page.base_rs]), "base residuals"))
    return parts


FAILING_SHOWN = 15
"""Most failing positions the page lists (the worst ones; all when fewer fail)."""


def _fails(page: _Page, heading: str) -> list[str]:
    """Where the base model fails: the positions beyond k sigma (the :data:`FAILING_SHOWN`
    worst listed, and said so), the residual map and, without a missing effect, the base
    residuals and their harmonics."""
    failing = page.base_an.failing
    n_positions = page.d["n_positions"]
    listed = ""
    if len(failing) > FAILING_SHOWN:
        listed = (
            f" The {FAILING_SHOWN} largest, worst first (the position's largest residual in "
            "sigmas):"
        )
    elif failing:
        listed = " All of them, worst first (the position's largest residual in sigmas):"
    parts = [
        f"{_heading(heading)}<p>{len(failing)} of {n_positions} positions have a residual "
        f"beyond {page.base_an.k_sigma:g} sigma.{listed}</p>"
    ]
    if failing:
        joints = range(1, page.family.data.n_joints + 1)
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
                    for f in failing[:FAILING_SHOWN]
                ],
            )  # fmt: skip
        )
    base_map = residual_map_figure([page.base_rs], page.limit)
    if base_map is not None:
        parts.append(
            "<p>The residuals over both angles (one square per position, repeats averaged): "
            "structure in phi1 and phi2 at once shows here, while the plots against one angle "
            "average over the other.</p>" + img_tag(base_map, "base residual map")
        )
    if not page.effect:  # else shown before/after in the section of the effect added
        parts.append(img_tag(residual_figure([page.base_rs]), "base residuals"))
        parts.append(img_tag(harmonics_figure([page.base_an]), "base harmonics"))
    return parts


_CANDIDATE_HEADERS = {
    "side": "side", "delta_bic": "delta BIC", "rms": "rms", "chi2_reduced": "chi2_reduced",
    "added_rank": "new rank", "alternatives": "same as",
}  # fmt: skip


def _candidates(page: _Page) -> str:
    """The table of candidates in the family's columns."""
    verdict, first = page.verdict, page.effect
    key = f"rms_{page.family.observation_unit}"
    headers = dict(_CANDIDATE_HEADERS, rms=f"rms ({page.family.unit_words})",
                   after_first=f"on top of {first}" if first else "-")  # fmt: skip

    def cell(column: str, c: dict):
        if column == "side":
            return verdict["sides"].get(c["effect"], "")
        if column == "delta_bic":
            return "-" if c["delta_bic"] is None else f"{c['delta_bic']:.1f}"
        if column == "after_first":
            later = c.get("delta_bic_after_first")
            return "-" if later is None else f"{later:.1f}"
        if column == "rms":
            return "-" if c[key] is None else c[key]
        if column == "chi2_reduced":
            return "-" if c["chi2_reduced"] is None else c["chi2_reduced"]
        if column == "added_rank":
            return c["added_rank"] if c["testable"] else "-"
        return ", ".join(c["alternatives"])

    columns = page.words.candidate_columns
    return html_table(
        ["effect", *(headers[c] for c in columns)],
        [
            [
                c["effect"] + (" (implausible)" if c.get("implausible") else ""),
                *(cell(col, c) for col in columns),
            ]
            for c in page.d["candidates"]
        ],  # fmt: skip
    )


def _diagnosis(page: _Page, heading: str) -> list[str]:
    """Which effect is missing: the candidates, why some are not testable (``untestable``), the
    verdict in words, the effect's story (``story``) and the structure left."""
    d, verdict = page.d, page.verdict
    parts = [_heading(heading), _candidates(page)]
    if "untestable" in page.words.parts:
        notes = [f"<li><b>{html.escape(c['effect'])}</b>: {html.escape(c['reason'])}</li>"
                 for c in d["candidates"] if c.get("reason")]  # fmt: skip
        if notes:
            parts.append("<p>Not testable here:</p><ul>" + "".join(notes) + "</ul>")
    lines = [*verdict_lines(d, page.family.source or DATA_PLACEHOLDER), *other_side_lines(d)]
    words = "<br>".join(html.escape(line) for line in lines)
    parts.append(f'<div class="verdict{" warn" if verdict["unexplained"] else ""}">{words}</div>')
    if page.effect and "story" in page.words.parts:  # why and how to confirm: in the verdict
        story = verdict["effect_story"]
        parts.append(
            f"<p><b>{html.escape(story['effect'])}</b> &mdash; {html.escape(story['title'])}. "
            f"Definition: <code>{html.escape(story['definition'])}</code>.</p>"
        )
    return parts + _structure(page)


def _structure(page: _Page) -> list[str]:
    """The terms the structure search finds: words and one plot per term."""
    terms = page.diagnosis.structure
    if not terms:
        return []
    label = " + ".join(("base", *page.diagnosis.best_fit.effect_names))
    parts = [
        f"<h3>Structure left in the residuals of {html.escape(label)}</h3><p>The structure "
        f"search ({html.escape(page.words.structure_shapes)}) finds the term(s) below. Each "
        "plot shows the residual, with this term's fitted part added back, projected at each "
        "position onto the direction the term enters the "
        f"{html.escape(page.family.observations)} along, against the variable of the term, "
        "with the fitted term over it and the noise of one point as a grey band.</p>"
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


def _added(page: _Page, heading: str) -> list[str]:
    """With a missing effect: the fits as each is added, the residuals and their harmonics
    before and after, and (``maps``) the residual map after."""
    if not page.effect:
        return []
    d = page.d
    rows = [("base", d["base"]), *((f"+ {s['added']}", s) for s in d["steps"])]
    parts = [
        _heading(heading)
        + page.fit_table(rows)
        + img_tag(residual_figure([page.base_rs, page.best_rs]), "residuals before and after")
        + img_tag(
            harmonics_figure([page.base_an, analyse_residuals(page.best_rs)]),
            "harmonics before and after",
        )
    ]
    best_map = None
    if "maps" in page.words.parts:
        best_map = residual_map_figure([page.best_rs], page.limit)
    if best_map is not None:
        parts.append(
            "<p>The residual map after, on the colour scale of the map in section 3:</p>"
            + img_tag(best_map, "residual map after")
        )
    return parts


def _parameters(page: _Page, heading: str) -> list[str]:
    """The combinations of the final model's parameters the data determine, and its flat
    directions."""
    res = page.diagnosis.best_fit.result
    parts = [
        f"{_heading(heading)}<p>Determined combinations (value &plusmn; standard error; rank "
        f"{res.rank} of {res.n_params} parameters):</p>",
        combinations_table(res),
    ]
    parts += flat_directions(res, "Flat directions")
    return parts


def _decision_rule(page: _Page, heading: str) -> list[str]:
    return [
        "<p style='color:#777;font-size:.85em'>Decision rule: "
        f"{html.escape(decision_rule_words(page.d))}; effects whose fit is as good are listed "
        "as alternatives; the "
        "final model is 'unexplained' when it fails the chi2 test (sigma given) or a harmonic "
        "structure search still finds a term.</p>"
    ]


def _run_results(page: _Page, heading: str) -> list[str]:
    """A calibration run's coefficients and what it tells about the table."""
    d = page.d
    return [_heading(heading) + "<p>"
            + "<br>".join(html.escape(x) for x in coefficient_lines(d)) + "</p><p>"
            + "<br>".join(html.escape(x) for x in table_from_run_lines(d)) + "</p>"]  # fmt: skip


SECTIONS = {
    "measurement_intro": _measurement_intro,
    "run_intro": _run_intro,
    "warnings": _warnings,
    "outliers": _outliers,
    "data": _data,
    "base": _base,
    "fails": _fails,
    "diagnosis": _diagnosis,
    "added": _added,
    "parameters": _parameters,
    "decision_rule": _decision_rule,
    "run_results": _run_results,
}
"""The sections a page may have (``PageWords.sections`` names them): ``(page, heading) -> HTML
parts``."""


def diagnosis_body(diagnosis: Diagnosis, *, title: str = "") -> str:
    """The body of :func:`diagnosis_html` (its title, verdict and sections), for a page or a
    notebook cell."""
    page = _Page(diagnosis)
    words = page.words
    anchor = ' id="verdict"' if "anchor" in words.parts else ""
    parts = [
        f"<h1>{html.escape(title or words.title)}</h1>",
        f'<p class="verdict headline{" warn" if page.verdict["unexplained"] else ""}"{anchor}>'
        f"{html.escape(headline(page.d))}</p>",
    ]
    for name, heading in words.sections:
        parts += SECTIONS[name](page, heading)
    return "\n".join(parts)


def diagnosis_html(diagnosis: Diagnosis, *, title: str = "") -> str:
    """The HTML page of a diagnosis of any family (self-contained): its title, the one-line
    verdict and the sections its family's :class:`~turntable_pin.stats.diagnosis_engine.PageWords`
    list (:data:`SECTIONS`)."""
    body = diagnosis_body(diagnosis, title=title)
    words = diagnosis.family.page
    return (
        "<!DOCTYPE html><html><head><meta charset='utf-8'>"
        f"<title>{html.escape(title or words.page_title)}</title><style>{PAGE_STYLE}</style>"
        f"</head><body>{body}</body></html>\n"
    )


def write_report(diagnosis: Diagnosis, path: str | Path, *, title: str = "") -> Path:
    """Write :func:`diagnosis_html` to ``path`` atomically."""
    return write_text_atomic(path, diagnosis_html(diagnosis, title=title))


__all__ = [
    "PAGE_STYLE",
    "SECTIONS",
    "combinations_table",
    "data_figure",
    "diagnosis_body",
    "diagnosis_html",
    "flat_directions",
    "html_table",
    "img_tag",
    "write_report",
]
