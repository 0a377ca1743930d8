"""Figures 8 and 9 of the paper: average sensitivities (bar charts), Monte Carlo histograms."""

from __future__ import annotations

from ..allocation.monte_carlo import MonteCarloResult
from ..allocation.sensitivity import Sensitivities
from ..core.units import ARCMIN_PER_RAD
from ..model.angles import ANGLE_NAMES, ANGLE_SYMBOLS
from .figures import pyplot, save_png

__all__ = ["plot_monte_carlo", "plot_sensitivities"]


def plot_sensitivities(average: Sensitivities, path, *, title: str | None = None):
    """Figure 8: bar charts of the average sensitivities, one panel per orientation angle (PNG)."""
    plt = pyplot()
    names = average.error_names
    fig, axes = plt.subplots(1, 3, figsize=(max(12, 1.1 * len(names) + 3), 3.8), sharey=True)
    labels = [f"C{i + 1} {n}" for i, n in enumerate(names)]
    for k, (ax, angle) in enumerate(zip(axes, ANGLE_NAMES, strict=True)):
        bars = ax.bar(range(len(names)), average.values[k], color="tab:blue")
        ax.set_xticks(range(len(names)), labels, fontsize=7, rotation=40, ha="right")
        ax.set_title(f"({'abc'[k]}) {angle}")
        for bar, v in zip(bars, average.values[k], strict=True):
            ax.text(
                bar.get_x() + bar.get_width() / 2, v + 0.02, f"{v:.4f}", ha="center", fontsize=7
            )
        ax.set_ylim(0, 1.15)
    axes[0].set_ylabel("mean |d angle / d error|")
    grid = " x ".join(str(a.size) for a in average.axes_rad)
    fig.suptitle(title or f"Sensitivities of the orientation error (mean over {grid} positions)")
    fig.tight_layout()
    return save_png(fig, path)


def plot_monte_carlo(result: MonteCarloResult, path):
    """Figure 9: histograms of each turntable's largest |dpsi|, |dtheta|, |dgamma| (PNG)."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.8))
    limits = result.limits.as_array() * ARCMIN_PER_RAD
    keys = result.angle_names or result.joint_names
    over = ", ".join(k for k in keys if k not in result.held_at_deg) or "the positions"
    step = ", ".join(sorted({f"{s:g}" for s in result.grid_steps_deg}))
    for k, (ax, name) in enumerate(zip(axes, ANGLE_SYMBOLS, strict=True)):
        values = result.worst_rad[:, k] * ARCMIN_PER_RAD
        ax.hist(values, bins=60, color="tab:blue", alpha=0.85)
        ax.axvline(limits[k], color="tab:red", linestyle="--", label=f"limit {limits[k]:.4f}'")
        ax.set_xlabel(f"max |d{name}| over {over} (arcmin)")
        ax.set_title(f"d{name}: max {values.max():.4f}'")
        ax.legend(fontsize=8)
    axes[0].set_ylabel("turntables")
    fig.suptitle(
        f"Monte Carlo: {result.n} turntables inside the allocated bounds (seed {result.seed}), "
        f"exact chain, grid {step} deg over {', '.join(keys)}"
    )
    fig.tight_layout()
    return save_png(fig, path)
