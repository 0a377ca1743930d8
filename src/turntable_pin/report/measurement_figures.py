"""Figures of the measurement layer: residuals per position and variable, their harmonics, their
map over two angles, and each term the structure search finds, against its variable.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..core.files import write_bytes_atomic
from ..measurement.residuals import ResidualAnalysis, ResidualSet, analyse_residuals
from ..stats.diagnosis_engine import residual_sets
from ..stats.structure_search import FoundTerm
from .figures import pyplot, save_png

__all__ = [
    "COLOURS",
    "DIRECTION_MARKERS",
    "direction_of",
    "harmonics_figure",
    "map_limit",
    "measured_counts",
    "not_measured_note",
    "residual_figure",
    "residual_map_figure",
    "structure_term_figure",
    "write_diagnosis_plots",
    "write_residual_plots",
    "write_structure_plots",
]

COLOURS = ("tab:blue", "tab:orange", "tab:green", "tab:red")
"""Colour of each residual component (dpsi, dtheta, dgamma, ...) in every figure."""

DIRECTION_MARKERS = {1.0: ("^", "forward"), -1.0: ("v", "backward")}
"""Marker and label of the points approached forward (dir +1) and backward (dir -1)."""


def direction_of(rs: ResidualSet, variable: str) -> np.ndarray | None:
    """The approach direction (``dir<k>``, +1/-1 per position) of the angle ``phi<k>_deg``, or
    None."""
    if not variable.startswith("phi") or not variable.endswith("_deg"):
        return None
    value = rs.others.get("dir" + variable[3:-4])
    return None if value is None else np.asarray(value, dtype=float)


def measured_counts(sets: Sequence[ResidualSet]) -> np.ndarray:
    """How many positions measured each component, (C,): the most over ``sets`` (a finite
    residual, or an observation left out as an outlier, counts; an empty cell does not)."""
    counts = []
    for rs in sets:
        seen = np.isfinite(rs.residuals)
        if rs.outliers is not None:
            seen |= np.isfinite(rs.outliers)
        counts.append(seen.sum(axis=0))
    return np.max(counts, axis=0)


def not_measured_note(
    components: Sequence[str], counts, n_positions: int, separator: str = "\n"
) -> str:
    """The components not measured everywhere, one per ``separator``: ``"dgamma: not measured"``,
    ``"dpsi: measured at 40 of 80 positions"``; ``""`` when none."""
    words = []
    for name, count in zip(components, counts, strict=True):
        if count == 0:
            words.append(f"{name}: not measured")
        elif count < n_positions:
            words.append(f"{name}: measured at {int(count)} of {n_positions} positions")
    return separator.join(words)


def _set_note(sets: Sequence[ResidualSet]) -> str:
    """:func:`not_measured_note` of residual sets of one data set."""
    first = sets[0]
    return not_measured_note(first.components, measured_counts(sets), first.residuals.shape[0])


def _finite_max(values) -> float:
    """The largest finite value of ``values``; 0 when there is none (every cell not measured)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return float(values.max()) if values.size else 0.0


def residual_figure(sets: Sequence[ResidualSet], k_sigma: float = 3.0) -> bytes:
    """PNG: one column per residual set (side by side), rows: per position and per variable."""
    plt = pyplot()

    first = sets[0]
    variables = [("position", None), *first.angles_deg.items(), *first.others.items()]
    fig, axes = plt.subplots(
        len(variables), len(sets), figsize=(5.2 * len(sets), 2.4 * len(variables)), squeeze=False
    )
    limit = _finite_max(np.concatenate([np.abs(s.residuals).ravel() for s in sets])) * 1.1 or 1.0
    measured = measured_counts(sets) > 0  # a component no set measured is not drawn, but named
    note = _set_note(sets)
    for col, rs in enumerate(sets):
        sigma = np.nanmedian(np.abs(rs.residuals / np.where(rs.normalised == 0, 1, rs.normalised)))
        for row, (name, _) in enumerate(variables):
            ax = axes[row, col]
            _residual_points(ax, rs, name, measured, limit)
            if np.isfinite(sigma) and sigma > 0:
                for s in (-k_sigma * sigma, k_sigma * sigma):
                    ax.axhline(s, color="grey", lw=0.7, ls="--")
            ax.axhline(0, color="black", lw=0.5)
            ax.set_ylim(-limit, limit)
            if name.startswith("dir"):  # an approach direction: two values, +-1
                ax.set_xticks([-1, 1], ["-1 (backward)", "+1 (forward)"])
                ax.set_xlim(-1.6, 1.6)
            ax.set_xlabel("position (measurement order)" if name == "position" else name)
            ax.set_ylabel(f"residual ({rs.unit})")
            if row == 0:
                ax.set_title(rs.label + (f"\n{note}" if note else ""), fontsize=9 if note else 10)
                ax.legend(fontsize=7, loc="upper right", ncol=3)
    fig.tight_layout()
    return save_png(fig)


def _residual_points(ax, rs: ResidualSet, name: str, measured, limit: float) -> None:
    """The residuals of ``rs`` against the variable ``name`` (by approach direction when it has
    one) and its outliers, on ``ax``."""
    x = np.arange(rs.residuals.shape[0]) if name == "position" else (
        rs.angles_deg.get(name, rs.others.get(name))
    )  # fmt: skip
    direction = direction_of(rs, name)
    for i, comp in enumerate(rs.components):
        if not measured[i]:
            continue
        jitter = 0.0 if name == "position" else (i - 1) * 0.01 * (np.ptp(x) or 1.0)
        if direction is None:
            ax.plot(x + jitter, rs.residuals[:, i], ".", ms=3, color=COLOURS[i],
                    label=comp)  # fmt: skip
            continue
        for sign, (marker, _) in DIRECTION_MARKERS.items():
            pick = direction == sign
            ax.plot(x[pick] + jitter, rs.residuals[pick, i], marker, ms=3.5,
                    color=COLOURS[i], mfc=COLOURS[i] if sign > 0 else "none", mew=0.7,
                    label=comp if sign > 0 else None)  # fmt: skip
    if rs.outliers is not None:
        # Left out of every fit: drawn at their value, or at the edge when beyond it.
        shown = np.clip(rs.outliers, -0.97 * limit, 0.97 * limit)
        for i in range(len(rs.components)):
            pick = np.isfinite(rs.outliers[:, i])
            ax.plot(x[pick], shown[pick, i], "x", ms=6, mew=1.4, color="black",
                    label="outlier (left out)" if i == 0 else None)  # fmt: skip
    if direction is not None:
        ax.text(0.01, 0.02, "filled up-triangles: approached forward (dir +1)\n"
                "open down-triangles: backward (dir -1)", transform=ax.transAxes,
                fontsize=6.5, color="#555")  # fmt: skip


def harmonics_figure(analyses: Sequence[ResidualAnalysis]) -> bytes:
    """PNG: harmonic amplitude of the residuals per axis, in each angle, for each fit."""
    plt = pyplot()

    names = list(analyses[0].harmonics)
    note = _set_note([an.residual_set for an in analyses])
    fig, axes = plt.subplots(
        max(len(names), 1), len(analyses), figsize=(5.2 * len(analyses), 2.6 * max(len(names), 1)),
        squeeze=False,
    )  # fmt: skip
    for col, an in enumerate(analyses):
        for row, name in enumerate(names):
            ax = axes[row, col]
            table = an.harmonics.get(name, {})
            for i, comp in enumerate(an.residual_set.components):
                # None: not measured, or at too few positions for these harmonics: not drawn
                amp = np.array([np.nan if a is None else a for a in table.get(comp, [])], float)
                k = np.arange(1, amp.size + 1)
                ok = np.isfinite(amp)
                if ok.any():
                    ax.bar(k[ok] + (i - 1) * 0.25, amp[ok], width=0.25, color=COLOURS[i],
                           label=comp)  # fmt: skip
            ax.set_xlabel(f"harmonic order in {name.replace('_deg', '')} (per rev)")
            ax.set_ylabel(f"amplitude ({an.residual_set.unit})")
            if row == 0:
                title = an.residual_set.label + (f"\n{note}" if note else "")
                ax.set_title(title, fontsize=9 if note else 10)
                if ax.get_legend_handles_labels()[0]:
                    ax.legend(fontsize=7)
    for row in range(axes.shape[0]):  # one scale per row, so the fall from left to right shows
        top = max(ax.get_ylim()[1] for ax in axes[row])
        for ax in axes[row]:
            ax.set_ylim(0, top)
    fig.tight_layout()
    return save_png(fig)


def _positions_mean(x: np.ndarray, y: np.ndarray, values: np.ndarray):
    """The mean of ``values`` (N, C) at each distinct (x, y) position (repeats averaged; NaN
    cells, not measured, left out of the mean; NaN where a component was never measured there)."""
    keys = np.round(np.stack([np.mod(x, 360.0), np.mod(y, 360.0)], axis=1), 6)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    finite = np.isfinite(values)
    sums = np.zeros((unique.shape[0], values.shape[1]))
    counts = np.zeros((unique.shape[0], values.shape[1]))
    np.add.at(sums, inverse, np.where(finite, values, 0.0))
    np.add.at(counts, inverse, finite)
    mean = np.where(counts > 0, sums / np.maximum(counts, 1), np.nan)
    return unique[:, 0], unique[:, 1], mean


def map_limit(sets: Sequence[ResidualSet]) -> float:
    """A common colour limit for :func:`residual_map_figure` of several sets (largest |mean|)."""
    limits = []
    for rs in sets:
        names = list(rs.angles_deg)
        if len(names) >= 2:
            x, y = rs.angles_deg[names[0]], rs.angles_deg[names[1]]
            limits.append(_finite_max(np.abs(_positions_mean(x, y, rs.residuals)[2])))
    return max(limits, default=0.0) or 1.0


def residual_map_figure(sets: Sequence[ResidualSet], limit: float | None = None) -> bytes | None:
    """PNG: the residual of each measured component over the first two angles, one row per set
    (repeats averaged; hollow grey: not measured there), on one symmetric colour scale
    (``limit``, default :func:`map_limit`), so structure in both angles shows; None with fewer
    than two angles."""
    names = list(sets[0].angles_deg)
    if len(names) < 2:
        return None
    plt = pyplot()

    limit = limit or map_limit(sets)
    counts, n_positions = measured_counts(sets), sets[0].residuals.shape[0]
    drawn = np.flatnonzero(counts > 0)
    n_comp = len(drawn)
    fig, axes = plt.subplots(
        len(sets), n_comp, figsize=(4.6 * n_comp, 4.0 * len(sets)), squeeze=False
    )
    for row, rs in enumerate(sets):
        x, y, mean = _positions_mean(rs.angles_deg[names[0]], rs.angles_deg[names[1]],
                                     rs.residuals)  # fmt: skip
        size = max(8.0, 9000.0 / max(len(x), 1))
        for ax, i in zip(axes[row], drawn, strict=True):
            comp = rs.components[i]
            empty = ~np.isfinite(mean[:, i])
            if empty.any():  # positions where this component was not measured: hollow squares
                ax.scatter(x[empty], y[empty], s=size, marker="s", facecolors="none",
                           edgecolors="0.75", linewidths=0.5)  # fmt: skip
            image = ax.scatter(x[~empty], y[~empty], c=mean[~empty, i], s=size, marker="s",
                               cmap="RdBu_r", vmin=-limit, vmax=limit)  # fmt: skip
            ax.set_xlim(-10, 370)
            ax.set_ylim(-10, 370)
            ax.set_xticks(range(0, 361, 90))
            ax.set_yticks(range(0, 361, 90))
            ax.set_aspect("equal")
            ax.set_xlabel(names[0].replace("_deg", " (deg)"))
            ax.set_ylabel(names[1].replace("_deg", " (deg)"))
            ax.set_title(f"{comp} residual\n{rs.label}", fontsize=9, color=COLOURS[i])
    note = not_measured_note(sets[0].components, counts, n_positions)
    if ((counts > 0) & (counts < n_positions)).any():
        note += "\n(hollow grey squares: positions where a component was not measured)"
    top = 0.88  # matplotlib's; a note above the panels' two-line titles takes 0.16 in a line
    if note:
        fig.suptitle(note, fontsize=9, y=1.0)
        top = min(top, 1.0 - (0.5 + 0.16 * (note.count("\n") + 1)) / fig.get_figheight())
    fig.subplots_adjust(wspace=0.35, hspace=0.3, top=top)
    fig.colorbar(image, ax=axes.ravel().tolist(), label=f"residual ({sets[0].unit})",
                 shrink=0.85 if len(sets) == 1 else 0.6)  # fmt: skip
    return save_png(fig)


def structure_term_figure(term: FoundTerm) -> bytes:
    """PNG: one found term against its variable: the partial residual projected on the term's
    direction (:meth:`FoundTerm.projection`), the fitted term, and +-1 sigma of one point."""
    plt = pyplot()

    pr = term.projection()
    f = term.factors
    angle = pr.value_unit == "deg"
    x = np.mod(pr.values, 360.0) if angle else pr.values
    fig, ax = plt.subplots(figsize=(7.5, 3.4))
    noise = float(np.nanmedian(pr.noise))
    discrete = np.unique(x).size <= 3
    if discrete:
        levels = np.unique(x)
        spread = 0.08 * (np.ptp(levels) or 1.0)
        jitter = np.random.default_rng(0).uniform(-spread, spread, x.size)
        ax.plot(x + jitter, pr.projected, ".", ms=4, color="tab:blue", label="projected residual")
        for level in levels:
            value = float(term.curve(np.array([level]))[0])
            ax.hlines(value, level - 2 * spread, level + 2 * spread, color="tab:red", lw=2,
                      label="fitted term" if level == levels[0] else None)  # fmt: skip
        ax.set_xticks(levels)
    else:
        ax.plot(x, pr.projected, ".", ms=4, color="tab:blue", label="projected residual")
        if angle:
            grid = np.linspace(0.0, 360.0, 721)
        else:
            grid = np.linspace(float(x.min()), float(x.max()), 721)
        ax.plot(grid, term.curve(grid / f.value_scale), color="tab:red", lw=1.6,
                label="fitted term")  # fmt: skip
        ax.set_xlim(grid[0], grid[-1])
        if angle:
            ax.set_xticks(range(0, 361, 45))
    ax.axhspan(-noise, noise, color="grey", alpha=0.25, lw=0,
               label=f"noise of one point (+-1 sigma, {noise:.2g} {pr.unit})")  # fmt: skip
    ax.axhline(0.0, color="black", lw=0.5)
    unit = f" ({pr.value_unit})" if pr.value_unit else ""
    ax.set_xlabel(f"{pr.variable}{unit}")
    ax.set_ylabel(f"size of the term ({pr.unit})")
    ax.set_title(f"{term.name}: amplitude {term.amplitude:.3g} {term.unit}, delta BIC "
                 f"{term.delta_bic:.0f}\n{term.description}", fontsize=9)  # fmt: skip
    ax.legend(fontsize=7, loc="upper right", ncol=3)
    fig.tight_layout()
    return save_png(fig)


def write_residual_plots(sets: Sequence[ResidualSet], directory: str | Path, k_sigma=3.0):
    """Write ``residuals.png``, ``harmonics.png`` and ``residual_maps.png`` (when the sets have
    two angles) into ``directory``; returns the paths."""
    directory = Path(directory)
    analyses = [analyse_residuals(s, k_sigma) for s in sets]
    paths = [
        write_bytes_atomic(directory / "residuals.png", residual_figure(sets, k_sigma)),
        write_bytes_atomic(directory / "harmonics.png", harmonics_figure(analyses)),
    ]
    maps = residual_map_figure(sets)
    if maps is not None:
        paths.append(write_bytes_atomic(directory / "residual_maps.png", maps))
    return paths


def write_structure_plots(terms: Sequence[FoundTerm], directory: str | Path) -> list[Path]:
    """Write :func:`structure_term_figure` of each term that can be drawn as ``structure_<i>.png``
    (i = 1, 2, ... in the order found) into ``directory``; returns the paths."""
    directory = Path(directory)
    return [
        write_bytes_atomic(directory / f"structure_{i}.png", structure_term_figure(term))
        for i, term in enumerate(terms, 1)
        if term.factors is not None and term.residual_weighted is not None
    ]


def write_diagnosis_plots(diagnosis, directory: str | Path) -> list[Path]:
    """The figures of a diagnosis of any family into ``directory``: the residuals before and
    (with a missing effect) after, their harmonics and maps (:func:`write_residual_plots`) and
    each structure term (:func:`write_structure_plots`); returns the paths."""
    base, best = residual_sets(diagnosis)
    sets = [base, best] if diagnosis.steps else [base]
    return [*write_residual_plots(sets, directory),
            *write_structure_plots(diagnosis.structure, directory)]  # fmt: skip
