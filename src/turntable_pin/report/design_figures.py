"""Figures of a design (its plots folder): where to measure, and how well.

- ``design_positions.png``: the chosen positions over the joints' ranges (one panel per pair of
  joints; one joint: its angle against the order of measurement), with the 30-degree grid within
  the limits behind them;
- ``design_standard_errors.png``: the expected standard error of each determined combination
  from the design, against the grid's at the same number of positions.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..design.identify import IdentifyDesign
from .figures import pyplot, save_png

__all__ = [
    "joint_label",
    "joint_range_deg",
    "plot_design_positions",
    "plot_design_standard_errors",
    "write_identify_plots",
]

_LABEL_CHARS = 48
"""Longest combination name shown on an axis (longer ones are cut, with an ellipsis)."""


def joint_label(space, k: int) -> str:
    """The axis label of joint ``k`` of a design space: ``phiK <joint> (deg)``."""
    r = space.ranges[k]
    return f"phi{r.index} {r.joint} (deg)"


def joint_range_deg(space, k: int) -> tuple[float, float]:
    """Joint k's range with a margin of 3 % (points at the limits stay whole)."""
    r = space.ranges[k]
    low, high = (r.low_deg, r.low_deg + 360.0) if r.full_turn else (r.low_deg, r.high_deg)
    pad = 0.03 * max(high - low, 1.0)
    return low - pad, high + pad


def plot_design_positions(design: IdentifyDesign, path):
    """The chosen positions over the joints' ranges, the grid behind them (PNG)."""
    plt = pyplot()
    space = design.space
    n_joints = space.n_joints
    pairs = [(a, b) for a in range(n_joints) for b in range(a + 1, n_joints)]
    panels = max(len(pairs), 1)
    fig, axes = plt.subplots(1, panels, figsize=(4.6 * panels + 0.6, 4.4), squeeze=False)
    chosen, grid = design.positions_deg, space.grid_deg
    if not pairs:  # one joint: the angle of each measurement in the run's order
        ax = axes[0, 0]
        ax.plot(
            np.arange(1, design.plan.n_rows + 1),
            design.plan.rows.angles_deg()[:, 0],
            "o",
            color="tab:blue",
            label=f"design ({design.n_positions} positions)",
        )
        for angle in grid[:, 0]:
            ax.axhline(angle, color="0.85", linewidth=0.8, zorder=0)
        ax.set_xlabel("measurement (order of the run)")
        ax.set_ylabel(joint_label(space, 0))
        ax.set_ylim(*joint_range_deg(space, 0))
        ax.legend(fontsize=8, loc="upper right")
    for ax, (a, b) in zip(axes[0], pairs, strict=False):
        for points, marker, colour, label in (
            (grid, "+", "0.6", f"30-degree grid ({design.n_grid})"),
            (chosen, "o", "tab:blue", f"design ({design.n_positions})"),
        ):
            ax.plot(points[:, a], points[:, b], marker, color=colour, markersize=5, label=label)
        ax.set_xlim(*joint_range_deg(space, a))
        ax.set_ylim(*joint_range_deg(space, b))
        ax.set_xlabel(joint_label(space, a))
        ax.set_ylabel(joint_label(space, b))
    effects = " + ".join(("base", *space.effect_names))
    fig.suptitle(
        f"D-optimal positions on {space.table_name}\nfor {effects}\n"
        f"(seed {space.seed}, {space.candidates_deg.shape[0]} candidates)",
        fontsize=9,
    )
    if pairs:
        handles, labels = axes[0, 0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=2, fontsize=8, frameon=False)
        fig.tight_layout(rect=(0, 0.07, 1, 1))
    else:
        fig.tight_layout()
    return save_png(fig, path)


def plot_design_standard_errors(design: IdentifyDesign, path):
    """Expected standard error of each combination: the design against the grid scaled to its
    number of positions (PNG, log scale; a combination the grid does not determine has no grid
    bar)."""
    plt = pyplot()
    combinations = design.combinations
    count = len(combinations)
    fig, ax = plt.subplots(figsize=(9.0, 1.2 + 0.32 * count))
    y = np.arange(count)
    ours = np.array([c["std"] for c in combinations], dtype=float)
    grid = np.array(
        [np.nan if c["std_grid_same_n"] is None else c["std_grid_same_n"] for c in combinations]
    )
    ax.barh(
        y - 0.2,
        ours,
        height=0.38,
        color="tab:blue",
        label=f"design, {design.n_positions} positions",
    )
    ax.barh(
        y + 0.2,
        np.nan_to_num(grid),
        height=0.38,
        color="0.6",
        label=f"30-degree grid ({design.n_grid}) scaled to {design.n_positions} positions",
    )
    for i in np.flatnonzero(np.isnan(grid)):
        ax.text(ours[i], y[i] + 0.2, "  grid: not determined", va="center", fontsize=7)
    labels = [
        (c["name"] if len(c["name"]) <= _LABEL_CHARS else c["name"][: _LABEL_CHARS - 3] + "...")
        + f" [{c['unit']}]"
        for c in combinations
    ]
    ax.set_yticks(y, labels, fontsize=7)
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel(f"expected standard error (noise {design.noise_arcsec:.3g} arcsec per angle)")
    efficiency = (
        f"D-efficiency {design.d_efficiency:.3f} per position"
        if design.d_efficiency is not None
        else "the grid does not determine every combination"
    )
    ax.set_title(f"What the design determines, against the grid: {efficiency}", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return save_png(fig, path)


def write_identify_plots(design: IdentifyDesign, folder) -> list[Path]:
    """Both figures of an identify design in ``folder`` (created); the paths written."""
    folder = Path(folder)
    return [
        plot_design_positions(design, folder / "design_positions.png"),
        plot_design_standard_errors(design, folder / "design_standard_errors.png"),
    ]
