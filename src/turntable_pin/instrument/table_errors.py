"""What a calibration run tells about the table: its errors seen through the outputs.

A table error turns gravity and the earth rate away from where eq. 3 puts them, and the outputs
follow (eqs. 8-13). Fitting the 14 coefficients with every base error of the table, the run
determines some combinations of the table's errors on their own, some only together with the
coefficients (the calibration absorbs them: the run cannot tell them from the instrument), and
none of the rest.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..measurement.table import measured_table
from .effects.table_side import PREFIX, TableError
from .model import BASE_NAMES, fit_run

__all__ = ["ABSORBED_CORRELATION", "TableFromRun", "table_from_run"]

ABSORBED_CORRELATION = 0.95
"""A table error whose multiple correlation with the 14 coefficients' columns is above this is
said to be mostly absorbed by the calibration (the threshold of a traded-off parameter)."""


@dataclass(frozen=True)
class TableFromRun:
    """The table's errors as a run's outputs see them.

    Attributes:
        errors: the table's base errors fitted (names without the ``table:`` prefix).
        determined: combinations of table errors alone the run determines: ``{name, value,
            std, unit}`` (arcsec).
        with_coefficients: combinations determined only together with the coefficients.
        undetermined: flat directions (combinations the run does not see at all).
        rank_added: independent table combinations the run adds to the 14 coefficients.
        per_error: for each error, ``{std_alone_arcsec, correlation}``: its standard error
            fitted alone with the coefficients and its multiple correlation with them.
        sigma_dph: the output noise the standard errors are computed with, deg/h.
    """

    errors: tuple[str, ...]
    determined: list[dict]
    with_coefficients: list[dict]
    undetermined: list[str]
    rank_added: int
    per_error: dict[str, dict]
    sigma_dph: float

    @property
    def absorbed(self) -> list[dict]:
        """``{error, correlation}`` of the errors the calibration mostly absorbs."""
        return [
            {"error": name, "correlation": entry["correlation"]}
            for name, entry in self.per_error.items()
            if entry["correlation"] > ABSORBED_CORRELATION
        ]

    def to_dict(self) -> dict:
        """The findings as a JSON-ready dict."""
        return {
            "errors": list(self.errors),
            "rank_added": self.rank_added,
            "determined": [dict(c) for c in self.determined],
            "with_coefficients": [dict(c) for c in self.with_coefficients],
            "undetermined": list(self.undetermined),
            "per_error": {k: dict(v) for k, v in self.per_error.items()},
            "absorbed": self.absorbed,
            "absorbed_above": ABSORBED_CORRELATION,
            "sigma_dph": self.sigma_dph,
        }


def table_from_run(run, table=None, *, mask=None, context=None) -> TableFromRun:
    """Fit the coefficients with every base error of the run's table (module docstring).

    Args:
        run: the :class:`~turntable_pin.calibration.run.CalibrationRun`.
        table: its :class:`~turntable_pin.measurement.table.MeasuredTable` (default the run's).
        mask: (N, 2) the outputs to use (outliers left out), default all.
        context: the :class:`~.effects.base.RunContext` to evaluate in (default the run's).
    """
    table = measured_table(run.table if table is None else table)
    effects = [TableError(table, name) for name in table.base_names]
    base = fit_run(run, (), context=context, mask=mask)
    fit = fit_run(run, effects, context=context or base.model.context, mask=mask)
    result = fit.result
    # Judged at the noise of the base fit (sigma given: 1; else its estimate), so that an
    # error that is not there does not shrink its own standard errors.
    result = result.with_noise_variance(base.result.noise_variance)
    sigma = float(np.sqrt(base.result.noise_variance)) * (
        float(np.median(run.sigma_dph)) if run.sigma_dph is not None else 1.0
    )
    n_base = len(BASE_NAMES)
    determined, mixed = [], []
    for combo, row in zip(result.combinations(), result.identifiability.determined, strict=True):
        pivot = int(np.flatnonzero(row)[0])
        entry = {**combo, "name": combo["name"].replace(PREFIX, "").replace(".value", "")}
        if pivot >= n_base:
            determined.append(entry)
        elif np.any(np.abs(row[n_base:]) > 0):
            mixed.append(entry)
    undetermined = [
        u.replace(PREFIX, "").replace(".value", "") for u in result.undetermined_combinations()
    ]
    per_error = {}
    for effect in effects:
        alone = fit_run(run, [effect], context=fit.model.context, mask=mask).result
        alone = alone.with_noise_variance(base.result.noise_variance)
        entry = alone.parameter_table()[f"{effect.name}.value"]
        jac = alone.jacobian_weighted
        column = jac[:, -1]
        q, _ = np.linalg.qr(jac[:, :n_base])
        norm = float(np.linalg.norm(column))
        correlation = float(np.linalg.norm(q.T @ column) / norm) if norm > 0 else 1.0
        per_error[effect.error] = {
            "std_alone_arcsec": entry["std"],
            "correlation": min(correlation, 1.0),
        }
    return TableFromRun(
        errors=tuple(table.base_names),
        determined=determined,
        with_coefficients=mixed,
        undetermined=undetermined,
        rank_added=result.rank - base.result.rank,
        per_error=per_error,
        sigma_dph=sigma,
    )
