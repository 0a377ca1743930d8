"""The notebook views of the result objects: their HTML (``_repr_html_``) and figures (``plot()``),
registered with :func:`~turntable_pin.core.notebook.register_view` when this module is imported.

Each view reuses the renderer the command line uses for that result: the HTML report of a
diagnosis, the text report of a design, an allocation and a calibration, the report's tables of a
fit; the figures are the ones ``--plots`` writes (drawn by the same functions into a temporary
folder, kept open: :func:`~turntable_pin.report.figures.figures_written`).
"""

from __future__ import annotations

import html
import re
import sys

from ..allocation.solver import Allocation
from ..calibration.drift_fit import CalibrationResult
from ..core.exceptions import TurntablePinError
from ..core.notebook import View, register_view
from ..design.calibrate import CalibrationDesign
from ..design.identify import IdentifyDesign
from ..design.separate import SeparationDesign
from ..measurement.data import OrientationMeasurements
from ..measurement.fit import OrientationFit
from ..measurement.residuals import analyse_residuals, orientation_residuals
from ..measurement.simulation import SimulatedMeasurements
from ..measurement.tpoint import TpointConversion
from ..model.angles import ANGLE_NAMES
from ..stats.model_selection import Diagnosis
from .allocation_figures import plot_sensitivities
from .design_figures import write_identify_plots
from .figures import figures_written
from .html_report import (
    PAGE_STYLE,
    combinations_table,
    data_figure,
    diagnosis_body,
    flat_directions,
    html_table,
    img_tag,
)
from .measurement_figures import write_diagnosis_plots, write_residual_plots
from .requirement_figures import write_calibration_design_figures
from .separation_figures import write_separate_plots

__all__ = ["SCOPE", "scoped_style"]

SCOPE = "turntable-pin"
"""The CSS class of every notebook view's ``<div>``: the report's style applies inside it only."""


def scoped_style(css: str, scope: str = SCOPE) -> str:
    """``css`` with every selector confined to ``.scope`` (``body`` becomes ``.scope`` itself),
    so that a view styles itself and not the notebook around it."""

    def scoped(match: re.Match) -> str:
        selectors = [s.strip() for s in match.group(1).split(",")]
        return ",".join(f".{scope}" if s == "body" else f".{scope} {s}" for s in selectors) + "{"

    return re.sub(r"([^{}]+)\{", scoped, css)


def _div(*parts: str) -> str:
    return f'<div class="{SCOPE}"><style>{scoped_style(PAGE_STYLE)}</style>{"".join(parts)}</div>'


def _pre(text: str) -> str:
    return f"<pre>{html.escape(text)}</pre>"


def _data_figures(data: OrientationMeasurements) -> list:
    return figures_written(lambda folder: data_figure(data))


# ---- measurements ---------------------------------------------------------------------------
def _measurements_parts(data: OrientationMeasurements) -> list[str]:
    """What the measurements are (source, positions, joints, angles measured) and their figure."""
    measured = ", ".join(
        f"{name} {int(n)}" for name, n in zip(ANGLE_NAMES, data.measured.sum(0), strict=True)
    )
    return [
        f"<p>{html.escape(data.source or 'measurements')}: {data.n_positions} positions, "
        f"{data.n_joints} joint(s); positions measuring each angle: {measured}.</p>",
        img_tag(data_figure(data), "measured angles"),
    ]


def _measurements_html(data: OrientationMeasurements) -> str:
    return _div(*_measurements_parts(data))


def _simulated_html(sim: SimulatedMeasurements) -> str:
    return _div(_pre(sim.comment()), *_measurements_parts(sim.data))


# ---- fits and diagnoses ---------------------------------------------------------------------
def _fit_html(fit: OrientationFit) -> str:
    out = fit.to_dict()
    p = out["p_value"]
    summary = html_table(
        ["model", "rms (arcsec)", "chi2_reduced", "rank", "params", "p-value"],
        [[" + ".join(("base", *fit.effect_names)), out["rms_arcsec"], out["chi2_reduced"],
          out["rank"], out["n_params"], "-" if p is None else f"{p:.3g}"]],
    )  # fmt: skip
    failing = analyse_residuals(orientation_residuals(fit)).failing
    parts = [
        f"<p>{fit.data.n_positions} positions, sigma {out['sigma_source']} "
        f"({out['sigma_arcsec']:.3g} arcsec).</p>",
        summary,
        "<p>Determined combinations:</p>",
        combinations_table(fit.result),
        *flat_directions(fit.result, "Not determined by these data"),
        f"<p>{len(failing)} of {fit.data.n_positions} positions have a residual beyond "
        "3 sigma.</p>",
    ]
    if "pointing_terms" in out:  # a telescope mount: TPOINT's terms by name, as fit prints them
        block = out["pointing_terms"]
        parts += [
            f"<p>TPOINT terms ({html.escape(block['mount'])} mount; "
            f"{html.escape(block['convention'])}):</p>",
            html_table(
                ["term", "value", "std", "unit", "formula"],
                [
                    [
                        t["name"],
                        t["value"],
                        "-" if t["std"] is None else t["std"],
                        t["unit"],
                        t["formula"],
                    ]
                    for t in block["terms"]
                ],
            ),  # fmt: skip
            f"<p>{html.escape(block['note'])}</p>",
        ]
    return _div(*parts)


def _fit_figures(fit: OrientationFit) -> list:
    return figures_written(
        lambda folder: write_residual_plots([orientation_residuals(fit)], folder)
    )


def _diagnosis_html(diagnosis: Diagnosis) -> str:
    return _div(diagnosis_body(diagnosis))


def _diagnosis_figures(diagnosis: Diagnosis) -> list:
    return figures_written(lambda folder: write_diagnosis_plots(diagnosis, folder))


# ---- designs, allocations, calibrations -----------------------------------------------------
def _report_html(result) -> str:
    return _div(_pre(result.report()))


def _separation_figures(design: SeparationDesign) -> list:
    if design.plan is None:  # no positions separate the two: nothing to draw
        return []
    return figures_written(lambda folder: write_separate_plots(design, folder))


def _allocation_figures(allocation: Allocation) -> list:
    return figures_written(
        lambda folder: plot_sensitivities(
            allocation.sensitivities, folder / "figure8_sensitivities.png"
        )
    )


def _no_figures(result) -> list:
    raise TurntablePinError(
        f"a {type(result).__name__} has no figure (the command line draws none for it); "
        "calibrate(..., diagnose=True) draws a run's residuals"
    )


# ---- TPOINT runs ----------------------------------------------------------------------------
def _tpoint_html(conversion: TpointConversion) -> str:
    return _div(
        _pre("\n".join(conversion.comment_lines())), *_measurements_parts(conversion.measurements())
    )


def _tpoint_figures(conversion: TpointConversion) -> list:
    return _data_figures(conversion.measurements())


register_view(OrientationMeasurements, View(_measurements_html, _data_figures))
register_view(SimulatedMeasurements, View(_simulated_html, lambda s: _data_figures(s.data)))
register_view(OrientationFit, View(_fit_html, _fit_figures))
register_view(Diagnosis, View(_diagnosis_html, _diagnosis_figures))
register_view(
    IdentifyDesign,
    View(_report_html, lambda d: figures_written(lambda f: write_identify_plots(d, f))),
)
register_view(SeparationDesign, View(_report_html, _separation_figures))
register_view(
    CalibrationDesign,
    View(_report_html, lambda d: figures_written(lambda f: write_calibration_design_figures(d, f))),
)
register_view(Allocation, View(_report_html, _allocation_figures))
register_view(CalibrationResult, View(_report_html, _no_figures))
register_view(TpointConversion, View(_tpoint_html, _tpoint_figures))


def _figures_as_png_in_ipython() -> None:
    """In IPython (a notebook), show a matplotlib figure that is a cell's value as a PNG: the
    package draws on the Agg backend, which registers no display of its own. Nothing outside
    IPython (IPython is not imported here)."""
    if "IPython" not in sys.modules:
        return
    from IPython import get_ipython
    from IPython.core.pylabtools import select_figure_formats

    shell = get_ipython()
    if shell is not None:
        select_figure_formats(shell, {"png"})


_figures_as_png_in_ipython()
