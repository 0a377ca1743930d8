"""Where a fit fails: residuals per position and component, against each variable, harmonics, plots.

Generic over a :class:`ResidualSet` (components such as ``dpsi, dtheta, dgamma``, their residuals
and normalised residuals, the angles to look for harmonics in and any other variables such as
time or approach direction); :func:`orientation_residuals` builds one from an orientation fit.
"""

from __future__ import annotations

import io
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.files import write_bytes_atomic
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from .data import ANGLE_NAMES

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")


@dataclass(frozen=True)
class ResidualSet:
    """Residuals of one fit, with what to plot them against.

    Attributes:
        label: e.g. ``"base"`` or ``"base + inner_encoder_harmonics"``.
        components: names of the residual components (columns).
        unit: unit of ``residuals``.
        residuals: (N, C) measured - fitted.
        normalised: (N, C) residuals / sigma (given or estimated).
        rows: (N,) file row of each position.
        angles_deg: ``{name: (N,)}`` angle variables (harmonic analysis, plots).
        others: ``{name: (N,)}`` further variables (time, approach direction).
    """

    label: str
    components: tuple[str, ...]
    unit: str
    residuals: np.ndarray
    normalised: np.ndarray
    rows: np.ndarray
    angles_deg: dict[str, np.ndarray]
    others: dict[str, np.ndarray] = field(default_factory=dict)


def orientation_residuals(fit, label: str | None = None) -> ResidualSet:
    """The :class:`ResidualSet` of an :class:`OrientationFit`, in arc seconds."""
    data = fit.data
    others = {}
    for name in ("time_s", "dir1", "dir2"):
        value = getattr(data, name)
        if value is not None:
            others[name] = np.asarray(value)
    return ResidualSet(
        label=label or " + ".join(("base", *fit.effect_names)),
        components=ANGLE_NAMES,
        unit="arcsec",
        residuals=fit.residuals_rad * ARCSEC_PER_RAD,
        normalised=fit.normalised_residuals,
        rows=np.asarray(data.rows),
        angles_deg={
            "phi1_deg": data.phi1_rad * DEG_PER_RAD,
            "phi2_deg": data.phi2_rad * DEG_PER_RAD,
        },
        others=others,
    )


def failing_positions(rs: ResidualSet, k_sigma: float = 3.0) -> list[dict]:
    """Positions with a component beyond ``k_sigma`` sigma, worst first."""
    out = []
    worst = np.abs(rs.normalised).max(axis=1)
    for i in np.argsort(-worst):
        if worst[i] <= k_sigma:
            break
        c = int(np.argmax(np.abs(rs.normalised[i])))
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
    """Amplitudes of harmonics 1..max_order of ``values`` (N, C) in ``angle`` (joint LS fit)."""
    a = np.radians(angle_deg)
    cols = [np.ones_like(a)]
    for k in range(1, max_order + 1):
        cols += [np.cos(k * a), np.sin(k * a)]
    design = np.stack(cols, axis=1)
    coef = np.linalg.lstsq(design, values, rcond=None)[0]  # (1 + 2K, C)
    return np.hypot(coef[1::2], coef[2::2])  # (K, C)


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
            entry.update({f"{c}_{rs.unit}": float(rs.residuals[i, j])
                          for j, c in enumerate(rs.components)})  # fmt: skip
            entry["max_sigmas"] = float(np.abs(rs.normalised[i]).max())
            out.append(entry)
        return out

    def to_dict(self, *, per_position: bool = False) -> dict:
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


def analyse_residuals(rs: ResidualSet, k_sigma: float = 3.0) -> ResidualAnalysis:
    """Failing positions, rms per component and per angle value, harmonic content per axis."""
    rms = {c: float(np.sqrt(np.mean(rs.residuals[:, i] ** 2))) for i, c in enumerate(rs.components)}
    by_angle, harmonics = {}, {}
    for name, angle in rs.angles_deg.items():
        values = np.unique(np.round(angle, 9))
        table = {"value": values.tolist()}
        for i, c in enumerate(rs.components):
            table[c] = [
                float(np.sqrt(np.mean(rs.residuals[np.isclose(angle, v), i] ** 2))) for v in values
            ]
        by_angle[name] = table
        distinct = np.unique(np.round(np.mod(angle, 360.0), 9)).size
        order = int(min(6, max(0, (distinct - 1) // 2)))
        if order:
            amp = harmonic_amplitudes(rs.residuals, angle, order)
            harmonics[name] = {c: amp[:, i].tolist() for i, c in enumerate(rs.components)}
    return ResidualAnalysis(rs, k_sigma, failing_positions(rs, k_sigma), rms, by_angle, harmonics)


def _png(fig) -> bytes:
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=90, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(fig)
    return buffer.getvalue()


def residual_figure(sets: Sequence[ResidualSet], k_sigma: float = 3.0) -> bytes:
    """PNG: one column per residual set (side by side), rows: per position and per variable."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = sets[0]
    variables = [("position", None), *first.angles_deg.items(), *first.others.items()]
    fig, axes = plt.subplots(
        len(variables), len(sets), figsize=(5.2 * len(sets), 2.4 * len(variables)), squeeze=False
    )
    limit = max(float(np.abs(s.residuals).max()) for s in sets) * 1.1 or 1.0
    for col, rs in enumerate(sets):
        sigma = np.median(np.abs(rs.residuals / np.where(rs.normalised == 0, 1, rs.normalised)))
        for row, (name, _) in enumerate(variables):
            ax = axes[row, col]
            x = np.arange(rs.residuals.shape[0]) if name == "position" else (
                rs.angles_deg.get(name, rs.others.get(name))
            )  # fmt: skip
            for i, comp in enumerate(rs.components):
                jitter = 0.0 if name == "position" else (i - 1) * 0.01 * (np.ptp(x) or 1.0)
                ax.plot(x + jitter, rs.residuals[:, i], ".", ms=3, color=COLOURS[i], label=comp)
            if np.isfinite(sigma) and sigma > 0:
                for s in (-k_sigma * sigma, k_sigma * sigma):
                    ax.axhline(s, color="grey", lw=0.7, ls="--")
            ax.axhline(0, color="black", lw=0.5)
            ax.set_ylim(-limit, limit)
            ax.set_xlabel("position (measurement order)" if name == "position" else name)
            ax.set_ylabel(f"residual ({rs.unit})")
            if row == 0:
                ax.set_title(rs.label, fontsize=10)
                ax.legend(fontsize=7, loc="upper right", ncol=3)
    fig.tight_layout()
    return _png(fig)


def harmonics_figure(analyses: Sequence[ResidualAnalysis]) -> bytes:
    """PNG: harmonic amplitude of the residuals per axis, in each angle, for each fit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = list(analyses[0].harmonics)
    fig, axes = plt.subplots(
        max(len(names), 1), len(analyses), figsize=(5.2 * len(analyses), 2.6 * max(len(names), 1)),
        squeeze=False,
    )  # fmt: skip
    for col, an in enumerate(analyses):
        for row, name in enumerate(names):
            ax = axes[row, col]
            table = an.harmonics.get(name, {})
            for i, comp in enumerate(an.residual_set.components):
                amp = np.asarray(table.get(comp, []))
                k = np.arange(1, amp.size + 1)
                ax.bar(k + (i - 1) * 0.25, amp, width=0.25, color=COLOURS[i], label=comp)
            ax.set_xlabel(f"harmonic order in {name.replace('_deg', '')} (per rev)")
            ax.set_ylabel(f"amplitude ({an.residual_set.unit})")
            if row == 0:
                ax.set_title(an.residual_set.label, fontsize=10)
                ax.legend(fontsize=7)
    for row in range(axes.shape[0]):  # one scale per row, so the fall from left to right shows
        top = max(ax.get_ylim()[1] for ax in axes[row])
        for ax in axes[row]:
            ax.set_ylim(0, top)
    fig.tight_layout()
    return _png(fig)


def write_residual_plots(sets: Sequence[ResidualSet], directory: str | Path, k_sigma=3.0):
    """Write ``residuals.png`` and ``harmonics.png`` into ``directory``; returns the paths."""
    directory = Path(directory)
    analyses = [analyse_residuals(s, k_sigma) for s in sets]
    paths = [
        write_bytes_atomic(directory / "residuals.png", residual_figure(sets, k_sigma)),
        write_bytes_atomic(directory / "harmonics.png", harmonics_figure(analyses)),
    ]
    return paths
