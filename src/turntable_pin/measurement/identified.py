"""The identified table written back: the user's URDF with the fitted errors in its placements.

As geometric-calibration tools do, the fitted base errors go into the joint ``<origin>``s of the
nominal URDF, so that any URDF consumer (plain Pinocchio) reproduces the fitted ``dR``. The data
determine only some combinations of the errors; the fit's minimum-norm member (arcsec, columns
normalised) of the equally good error sets is written: all give the same ``dR`` at every
position. Offsets (``deta``, ``<joint>.offset_a``...) never turn the payload and are written as
zero; effects (harmonics, backlash, sag...) vary with the position, are no placements and are
not written.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..core.units import ARCSEC_PER_RAD
from ..model.urdf_io import write_error_urdf

__all__ = ["SPLIT_RULE", "identified_errors", "write_identified_urdf"]

SPLIT_RULE = (
    "combinations the data cannot separate are split by the minimum-norm rule (the smallest "
    "sum of squared errors in arcsec, columns normalised, among the equally good fits); "
    "offsets are written as 0; fitted effects other than the base errors are not written"
)
"""How :func:`write_identified_urdf` splits what the data cannot tell apart, in words."""


def identified_errors(fit) -> np.ndarray:
    """The error vector of the fit's table (rad, m; its chain's ``error_names`` order): the
    fitted base errors, zero offsets."""
    chain = fit.model.table.chain
    fitted = dict(zip(fit.model.parameter_names, fit.result.params, strict=True))
    return np.array([fitted.get(name, 0.0) for name in chain.error_names])


def write_identified_urdf(fit, path: str | Path, urdf_path: str | Path | None = None) -> dict:
    """Write the URDF of ``fit``'s table with the fitted errors in its placements, atomically.

    Args:
        fit: an :class:`~turntable_pin.measurement.fit.OrientationFit`.
        path: the output file.
        urdf_path: the nominal URDF (default: the one the table was read from).

    Returns:
        ``{"path", "rule", "errors_arcsec", "undetermined"}`` for the reports.
    """
    table = fit.model.table
    values = identified_errors(fit)
    written = write_error_urdf(urdf_path or table.urdf_path, table.chain, values, path)
    return {
        "path": str(written),
        "rule": SPLIT_RULE,
        "errors_arcsec": {
            name: float(v * ARCSEC_PER_RAD)
            for name, v in zip(table.chain.error_names, values, strict=True)
            if name in table.base_names
        },
        "undetermined": fit.result.undetermined_combinations(),
    }
