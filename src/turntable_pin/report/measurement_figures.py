"""Figures of the measurement layer: residuals per position and variable, and their harmonics."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..core.files import write_bytes_atomic
from ..measurement.residuals import ResidualAnalysis, ResidualSet, analyse_residuals
from .figures import pyplot, save_png

__all__ = ["COLOURS", "harmonics_figure", "residual_figure", "write_residual_plots"]

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
"""Colour of each residual component (dpsi, dtheta, dgamma, ...) in every figure."""


def residual_figure(sets: Sequence[ResidualSet], k_sigma: float = 3.0) -> bytes:
    """PNG: one column per residual set (side by side), rows: per position and per variable."""
    plt = pyplot()

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
    return save_png(fig)


def harmonics_figure(analyses: Sequence[ResidualAnalysis]) -> bytes:
    """PNG: harmonic amplitude of the residuals per axis, in each angle, for each fit."""
    plt = pyplot()

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
    return save_png(fig)


def write_residual_plots(sets: Sequence[ResidualSet], directory: str | Path, k_sigma=3.0):
    """Write ``residuals.png`` and ``harmonics.png`` into ``directory``; returns the paths."""
    directory = Path(directory)
    analyses = [analyse_residuals(s, k_sigma) for s in sets]
    paths = [
        write_bytes_atomic(directory / "residuals.png", residual_figure(sets, k_sigma)),
        write_bytes_atomic(directory / "harmonics.png", harmonics_figure(analyses)),
    ]
    return paths
