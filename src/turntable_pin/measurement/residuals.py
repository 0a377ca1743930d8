"""Where a fit fails: residuals per position and component, against each variable, harmonics.

Generic over a :class:`ResidualSet` (components such as ``dpsi, dtheta, dgamma``, their residuals
and normalised residuals, the angles to look for harmonics in and any other variables such as
time or approach direction); :func:`orientation_residuals` builds one from an orientation fit.
The plots are drawn by :mod:`turntable_pin.report.measurement_figures`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.exceptions import InputError
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from .data import ANGLE_NAMES

__all__ = [
    "ResidualAnalysis",
    "ResidualSet",
    "analyse_residuals",
    "failing_positions",
    "harmonic_amplitudes",
    "orientation_residuals",
]


@dataclass(frozen=True)
class ResidualSet:
    """Residuals of one fit, with what to plot them against.

    Attributes:
        label: e.g. ``"base"`` or ``"base + inner_encoder_harmonics"``.
        components: names of the residual components (columns).
        unit: unit of ``residuals``.
        residuals: (N, C) measured - fitted (NaN where a component was not measured).
        normalised: (N, C) residuals / sigma (given or estimated; NaN where not measured).
        rows: (N,) file row of each position.
        angles_deg: ``{name: (N,)}`` angle variables (harmonic analysis, plots).
        others: ``{name: (N,)}`` further variables (time, approach direction).
        outliers: (N, C) residuals of the observations left out as outliers (NaN elsewhere), or
            ``None``: shown in the plots, never in the statistics.
    """

    label: str
    components: tuple[str, ...]
    unit: str
    residuals: np.ndarray
    normalised: np.ndarray
    rows: np.ndarray
    angles_deg: dict[str, np.ndarray]
    others: dict[str, np.ndarray] = field(default_factory=dict)
    outliers: np.ndarray | None = None


def orientation_residuals(fit, label: str | None = None, left_out_rad=None) -> ResidualSet:
    """The :class:`ResidualSet` of an :class:`OrientationFit`, in arc seconds; ``left_out_rad``
    (N, 3): the measured values of the angles left out as outliers (NaN elsewhere), whose
    residuals against this fit are kept apart for the plots."""
    data = fit.data
    others = {} if data.time_s is None else {"time_s": np.asarray(data.time_s)}
    others.update({f"dir{k}": np.asarray(d) for k, d in enumerate(data.dirs, 1) if d is not None})
    others.update({name: np.asarray(v) for name, v in data.extra.items()})
    return ResidualSet(
        label=label or " + ".join(("base", *fit.effect_names)),
        components=ANGLE_NAMES,
        unit="arcsec",
        residuals=fit.residuals_rad * ARCSEC_PER_RAD,
        normalised=fit.normalised_residuals,
        rows=np.asarray(data.rows),
        angles_deg={
            f"phi{k}_deg": data.joint_rad[:, k - 1] * DEG_PER_RAD
            for k in range(1, data.n_joints + 1)
        },
        others=others,
        outliers=None
        if left_out_rad is None or not np.isfinite(left_out_rad).any()
        else (np.asarray(left_out_rad) - fit.fitted_rad()) * ARCSEC_PER_RAD,
    )


def failing_positions(rs: ResidualSet, k_sigma: float = 3.0) -> list[dict]:
    """Positions with a component beyond ``k_sigma`` sigma, worst first."""
    out = []
    normalised = np.nan_to_num(np.abs(rs.normalised))  # not measured: never failing
    worst = normalised.max(axis=1)
    for i in np.argsort(-worst):
        if worst[i] <= k_sigma:
            break
        c = int(np.argmax(normalised[i]))
        entry = {"row": int(rs.rows[i])}
        entry.update({k: float(v[i]) for k, v in rs.angles_deg.items()})
        entry.update({k: float(v[i]) for k, v in rs.others.items()})
        entry.update(
            {
                "component": rs.components[c],
                f"residual_{rs.unit}": float(rs.residuals[i, c]),
                "sigmas": float(rs.normalised[i, c]),
            }
        )
        out.append(entry)
    return out


def harmonic_amplitudes(values: np.ndarray, angle_deg: np.ndarray, max_order: int) -> np.ndarray:
    """Amplitudes of harmonics 1..max_order of ``values`` (N, C) in ``angle`` (joint LS fit of
    each component over the rows where it is not NaN; NaN when too few rows remain)."""
    a = np.radians(angle_deg)
    cols = [np.ones_like(a)]
    for k in range(1, max_order + 1):
        cols += [np.cos(k * a), np.sin(k * a)]
    design = np.stack(cols, axis=1)
    values = np.asarray(values, dtype=float)
    out = np.full((max_order, values.shape[1]), np.nan)
    for c in range(values.shape[1]):
        ok = np.isfinite(values[:, c])
        if ok.sum() >= design.shape[1]:
            coef = np.linalg.lstsq(design[ok], values[ok, c], rcond=None)[0]  # (1 + 2K,)
            out[:, c] = np.hypot(coef[1::2], coef[2::2])
    return out  # (K, C)


@dataclass(frozen=True)
class ResidualAnalysis:
    """Summary of where one fit fails."""

    residual_set: ResidualSet
    k_sigma: float
    failing: list[dict]
    rms: dict[str, float]
    rms_by_angle: dict[str, dict[str, list]]
    harmonics: dict[str, dict[str, list[float]]]

    def per_position(self) -> list[dict]:
        """Every position's residuals (user units) and its largest normalised residual."""
        rs = self.residual_set
        out = []
        for i in range(rs.residuals.shape[0]):
            entry = {"row": int(rs.rows[i])}
            entry.update({k: float(v[i]) for k, v in rs.angles_deg.items()})
            entry.update({f"{c}_{rs.unit}": _finite(rs.residuals[i, j])
                          for j, c in enumerate(rs.components)})  # fmt: skip
            entry["max_sigmas"] = float(np.nanmax(np.abs(rs.normalised[i])))
            out.append(entry)
        return out

    def to_dict(self, *, per_position: bool = False) -> dict:
        """The summary as a JSON-ready dict, in the set's unit (every position if asked)."""
        rs = self.residual_set
        extra = {"per_position": self.per_position()} if per_position else {}
        return {
            **extra,
            "label": rs.label,
            "unit": rs.unit,
            "k_sigma": self.k_sigma,
            "n_failing": len(self.failing),
            "failing_positions": self.failing,
            f"rms_{rs.unit}": self.rms,
            "rms_by_angle": self.rms_by_angle,
            "harmonic_amplitudes": self.harmonics,
        }


def _finite(value) -> float | None:
    """``value`` as a float, ``None`` when it is NaN (not measured)."""
    return float(value) if np.isfinite(value) else None


def _rms(values: np.ndarray) -> float | None:
    """Root mean square over the measured (finite) values; ``None`` when there is none."""
    values = values[np.isfinite(values)]
    return float(np.sqrt(np.mean(values**2))) if values.size else None


def analyse_residuals(rs: ResidualSet, k_sigma: float = 3.0) -> ResidualAnalysis:
    """Failing positions, rms per component and per angle value, harmonic content per axis.

    ``k_sigma`` (> 0): a residual beyond ``k_sigma`` sigmas marks its position as failing.
    """
    if not (np.isfinite(k_sigma) and k_sigma > 0):
        raise InputError(f"k_sigma must be a number > 0, got {k_sigma!r}")
    rms = {c: _rms(rs.residuals[:, i]) for i, c in enumerate(rs.components)}
    by_angle, harmonics = {}, {}
    for name, angle in rs.angles_deg.items():
        values = np.unique(np.round(angle, 9))
        table = {"value": values.tolist()}
        for i, c in enumerate(rs.components):
            table[c] = [_rms(rs.residuals[np.isclose(angle, v), i]) for v in values]
        by_angle[name] = table
        distinct = np.unique(np.round(np.mod(angle, 360.0), 9)).size
        order = int(min(6, max(0, (distinct - 1) // 2)))
        if order:
            amp = harmonic_amplitudes(rs.residuals, angle, order)
            harmonics[name] = {c: [_finite(a) for a in amp[:, i]]
                               for i, c in enumerate(rs.components)}  # fmt: skip
    return ResidualAnalysis(rs, k_sigma, failing_positions(rs, k_sigma), rms, by_angle, harmonics)
