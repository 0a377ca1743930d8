"""Figures of a separation design (:func:`~turntable_pin.design.separate.design_separate`).

- ``separate_positions.png``: the chosen positions over the joints' ranges (one panel per pair of
  joints; one joint: its angle against the order of measurement), each coloured by its share of
  the misfit the two effects leave of each other there (where they differ most), with the
  positions already measured and the 30-degree grid behind them;
- ``separate_power.png``: the chance that the diagnosis names the right effect against the number
  of positions (this design scaled), with the target, the design's size and the count the target
  needs.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..design.separate import SeparationDesign
from .design_figures import joint_label, joint_range_deg
from .figures import pyplot, save_png

__all__ = ["plot_separation_positions", "plot_separation_power", "write_separate_plots"]


def plot_separation_positions(design: SeparationDesign, path):
    """The chosen positions coloured by their share of the misfit, over the measured ones and
    the grid (PNG)."""
    plt = pyplot()
    space = design.space
    n_joints = space.n_joints
    pairs = [(a, b) for a in range(n_joints) for b in range(a + 1, n_joints)]
    fig, axes = plt.subplots(
        1, max(len(pairs), 1), figsize=(4.8 * max(len(pairs), 1) + 1.2, 4.4), squeeze=False
    )
    share = design.misfit_by_position.sum(axis=1)
    labels = [joint_label(space, k) for k in range(n_joints)]
    dots = None
    if not pairs:  # one joint: the angle of each position in the order first measured
        ax = axes[0, 0]
        ax.plot(np.zeros(len(design.measured_deg)), design.measured_deg[:, 0], "x",
                color="0.5", label="measured")  # fmt: skip
        dots = ax.scatter(np.arange(1, design.n_positions + 1), design.positions_deg[:, 0],
                          c=share, cmap="viridis", label="design")  # fmt: skip
        ax.set_xlabel("position (order of the run; 0: measured)")
        ax.set_ylabel(labels[0])
        ax.set_ylim(*joint_range_deg(space, 0))
    for ax, (a, b) in zip(axes[0], pairs, strict=False):
        grid, measured, chosen = space.grid_deg, design.measured_deg, design.positions_deg
        ax.plot(grid[:, a], grid[:, b], "+", color="0.8", markersize=4, label="30-degree grid")
        if measured.size:
            ax.plot(measured[:, a], measured[:, b], "x", color="0.35", markersize=5,
                    label=f"measured ({measured.shape[0]})")  # fmt: skip
        dots = ax.scatter(chosen[:, a], chosen[:, b], c=share, cmap="viridis", s=30,
                          edgecolors="k", linewidths=0.4,
                          label=f"design ({design.n_positions})")  # fmt: skip
        ax.set_xlim(*joint_range_deg(space, a))
        ax.set_ylim(*joint_range_deg(space, b))
        ax.set_xlabel(labels[a])
        ax.set_ylabel(labels[b])
    if dots is not None:
        fig.colorbar(dots, ax=axes[0].tolist(), label="share of the misfits (chi2)")
    a, b = design.pair
    fig.suptitle(
        f"Positions that tell {a} from {b} on {space.table_name}\n"
        f"(T-optimal, seed {space.seed}, {space.candidates_deg.shape[0]} candidates)",
        fontsize=9,
    )
    axes[0, 0].legend(fontsize=7, loc="upper right")
    return save_png(fig, path)


def plot_separation_power(design: SeparationDesign, path):
    """The chance of the right name against the number of positions (PNG)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    if design.power_curve:
        counts, power = np.array(design.power_curve).T
        ax.plot(counts, 100.0 * power, "-", color="tab:blue",
                label="this design scaled to N positions")  # fmt: skip
    ax.axhline(100.0 * design.target, color="tab:red", linestyle="--",
               label=f"target {design.target:.0%}")  # fmt: skip
    ax.plot([design.n_positions], [100.0 * design.power], "o", color="tab:blue",
            label=f"design: {design.n_positions} positions")  # fmt: skip
    if design.positions_for_power is not None:
        ax.plot([design.positions_for_power], [100.0 * design.power_at_positions_for_power], "s",
                color="tab:red", label=f"{design.positions_for_power} positions "
                + ("designed" if design.positions_for_power_designed else "(scaled)"))  # fmt: skip
    measured = [h.power_measured for h in design.hypotheses if h.power_measured is not None]
    if measured:
        ax.axhline(100.0 * min(measured), color="0.5", linestyle=":",
                   label="positions measured alone")  # fmt: skip
    ax.set_xlabel("positions" + (" besides those measured" if design.n_from else ""))
    ax.set_ylabel("chance of the right name (%)")
    ax.set_ylim(0.0, 102.0)
    ax.set_xlim(left=0.0)
    a, b = design.pair
    ax.set_title(f"{a} or {b}: the smaller chance of the right name", fontsize=10)
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return save_png(fig, path)


def write_separate_plots(design: SeparationDesign, folder) -> list[Path]:
    """Both figures of a separation design in ``folder`` (created); the paths written."""
    folder = Path(folder)
    return [
        plot_separation_positions(design, folder / "separate_positions.png"),
        plot_separation_power(design, folder / "separate_power.png"),
    ]
