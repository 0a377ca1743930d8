"""The residuals of a run fit as a :class:`~turntable_pin.measurement.residuals.ResidualSet`:
``out_x, out_y`` in deg/h against each joint angle, time and the extra columns (temperature),
with the outputs left out as outliers kept apart for the plots."""

from __future__ import annotations

import numpy as np

from ..core.units import DEG_PER_RAD
from ..measurement.residuals import ResidualSet
from .model import CHANNELS, RunFit

__all__ = ["run_residuals"]


def run_residuals(fit: RunFit, label: str | None = None) -> ResidualSet:
    """The :class:`ResidualSet` of ``fit`` (deg/h); the outputs its mask leaves out are shown
    as outliers (their residual against this fit), never in the statistics."""
    run = fit.run
    others = {} if run.time_s is None else {"time_s": np.asarray(run.time_s)}
    others.update({name: np.asarray(v) for name, v in run.extra.items()})
    left_out = ~fit.model.mask
    outliers = None
    if left_out.any():
        outliers = np.where(left_out, run.outputs_dph - fit.fitted_dph, np.nan)
    return ResidualSet(
        label=label or " + ".join(("base", *fit.effect_names)),
        components=CHANNELS,
        unit="dph",
        residuals=fit.residuals_dph,
        normalised=fit.normalised_residuals,
        rows=np.asarray(run.rows),
        angles_deg={
            f"phi{k}_deg": run.joint_rad[:, k - 1] * DEG_PER_RAD
            for k in range(1, run.joint_rad.shape[1] + 1)
        },
        others=others,
        outliers=outliers,
    )
