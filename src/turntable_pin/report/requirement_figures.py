"""Figures of the orientation requirement, as PNG files: Figures 4 and 5 of the paper for an
:class:`OrientationRequirement`, and the calibration design (``design_calibration``).

Figure 4: the rate-sensing errors over the orientation-error angles: the surfaces Gamma1
(``dwx`` over dpsi, dtheta) and Gamma2 (``dwy`` over dtheta, dgamma) with the plane ``w_m``, and
slices showing that ``dwx`` hardly depends on dgamma and ``dwy`` hardly on dpsi.
Figure 5: the contour lines ``dwx = w_m`` and ``dwy = w_m`` with the requirement rectangles and
the box that holds (every angle at its limit at once).
``design_calibrate.png``: the designed positions against the reference grid, the boxes and
planes of both, and the search.
"""

# matplotlib is imported inside functions: import turntable_pin stays light
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..calibration.positions import PositionSet, position_inputs
from ..calibration.rate_error import rate_errors_at_angles_dph
from ..calibration.requirement import MAX_ANGLE_RAD, OrientationRequirement
from ..core.units import deg_to_rad, rad_to_deg
from ..design.calibrate import CalibrationDesign
from .figures import pyplot, save_png

__all__ = [
    "plot_calibration_design",
    "plot_figure4",
    "plot_figure5",
    "plot_span_deg",
    "write_calibration_design_figures",
    "write_requirement_figures",
]

_LABELS = {"psi": r"$\Delta\psi$ (deg)", "theta": r"$\Delta\theta$ (deg)",
           "gamma": r"$\Delta\gamma$ (deg)"}  # fmt: skip


def plot_span_deg(result: OrientationRequirement) -> float:
    """Half-width of the plotted angle range: 1.6 times the largest contour intercept below the
    search cap (intercepts at the cap would flatten the figure), degrees."""
    limits = [w for r in result.rectangles for w in r.axis_limits_rad if w < MAX_ANGLE_RAD]
    return float(rad_to_deg(1.6 * max(limits, default=MAX_ANGLE_RAD)))


def _rate_errors(result: OrientationRequirement, angles_rad: np.ndarray) -> np.ndarray:
    """``[dwx, dwy]`` (deg/h) at (M, 3) angle triples."""
    return rate_errors_at_angles_dph(
        result.gyrowheel, result.inputs, angles_rad, exact=result.exact,
        definition=result.definition,
    )  # fmt: skip


def _title(result: OrientationRequirement) -> str:
    return (
        f"positions {result.positions_name} ({result.n_positions}), latitude "
        f"{rad_to_deg(result.latitude_rad):g} deg, w_m = {result.accuracy_dph:g} deg/h, "
        f"{result.definition.replace('_', ' ')}"
    )


def _surfaces(result: OrientationRequirement, points: int):
    """Grids u, v (deg) and the surfaces Gamma1 = dwx(dpsi=u, dtheta=v), Gamma2 = dwy(dtheta=u,
    dgamma=v) on them (deg/h, flat)."""
    span = plot_span_deg(result)
    grid_deg = np.linspace(-span, span, points)
    u, v = np.meshgrid(grid_deg, grid_deg, indexing="ij")
    zeros = np.zeros(u.size)
    gamma1 = _rate_errors(result, deg_to_rad(np.stack([u.ravel(), v.ravel(), zeros], 1)))[:, 0]
    gamma2 = _rate_errors(result, deg_to_rad(np.stack([zeros, u.ravel(), v.ravel()], 1)))[:, 1]
    return u, v, gamma1, gamma2


def plot_figure4(result: OrientationRequirement, path: str | Path, *, points: int = 41) -> Path:
    """Write Figure 4 (surfaces Gamma1, Gamma2 and one-angle slices) to ``path`` (PNG)."""
    plt = pyplot()
    u, v, gamma1, gamma2 = _surfaces(result, points)

    from matplotlib.ticker import MaxNLocator

    fig = plt.figure(figsize=(15, 9))
    fig.suptitle("Figure 4: rate-sensing errors against the orientation error\n" + _title(result))
    for index, (values, names, axis) in enumerate(
        ((gamma1, ("psi", "theta"), "x"), (gamma2, ("theta", "gamma"), "y"))
    ):
        ax = fig.add_subplot(2, 3, 1 + 3 * index, projection="3d")
        ax.plot_surface(u, v, values.reshape(u.shape), cmap="viridis", linewidth=0, alpha=0.9)
        ax.plot_surface(
            u, v, np.full(u.shape, result.accuracy_dph), color="red", alpha=0.25, linewidth=0
        )
        ax.set_xlabel(_LABELS[names[0]], labelpad=12)
        ax.set_ylabel(_LABELS[names[1]], labelpad=12)
        ax.set_zlabel(rf"$\Delta\omega_{axis}$ (deg/h)", labelpad=14)
        ax.tick_params(labelsize=7)
        for axis3d in (ax.xaxis, ax.yaxis, ax.zaxis):
            axis3d.set_major_locator(MaxNLocator(4))
        ax.set_title(
            f"({'ab'[index]}) $\\Gamma_{index + 1}$: $\\Delta\\omega_{axis}$, plane $\\omega_m$"
        )
    # Slices: each error against each angle, the third angle (the "other" one) at three values.
    slices = (
        ("c", 0, 0, 2, "psi", "gamma"),
        ("d", 0, 1, 2, "theta", "gamma"),
        ("e", 1, 2, 0, "gamma", "psi"),
        ("f", 1, 1, 0, "theta", "psi"),
    )
    span = plot_span_deg(result)
    line = np.linspace(-span, span, 161)
    for n, (letter, column, along, other, along_name, other_name) in enumerate(slices):
        ax = fig.add_subplot(2, 3, (2, 3, 5, 6)[n])
        for fraction in (0.0, 0.5, 1.0):
            angles = np.zeros((line.size, 3))
            angles[:, along] = line
            angles[:, other] = fraction * span
            values = _rate_errors(result, deg_to_rad(angles))[:, column]
            ax.plot(line, values, label=f"$\\Delta\\{other_name}$ = {fraction * span:.3g} deg")
        ax.axhline(result.accuracy_dph, color="red", lw=0.8, ls="--", label=r"$\omega_m$")
        ax.set_xlabel(_LABELS[along_name])
        ax.set_ylabel(rf"$\Delta\omega_{'xy'[column]}$ (deg/h)")
        ax.xaxis.set_major_locator(MaxNLocator(6))
        ax.set_title(f"({letter}) $\\Delta\\omega_{'xy'[column]}$ against $\\Delta\\{along_name}$")
        ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return save_png(fig, path)


def plot_figure5(result: OrientationRequirement, path: str | Path, *, points: int = 121) -> Path:
    """Write Figure 5 (contours ``dw = w_m`` and the requirement rectangles) to ``path``."""
    plt = pyplot()
    u, v, gamma1, gamma2 = _surfaces(result, points)
    limits_deg = rad_to_deg(result.limits_rad)
    fig, axes = plt.subplots(1, 2, figsize=(12, 5.5))
    fig.suptitle("Figure 5: requirement of the orientation error\n" + _title(result))
    panels = (
        (axes[0], gamma1, ("psi", "theta"), (limits_deg[0], limits_deg[1]), "x", 0),
        (axes[1], gamma2, ("theta", "gamma"), (limits_deg[1], limits_deg[2]), "y", 1),
    )
    for ax, values, names, (a, b), axis, index in panels:
        ax.contour(u, v, values.reshape(u.shape), levels=[result.accuracy_dph], colors="C0")
        ax.fill(
            [-a, a, a, -a], [-b, -b, b, b], color="black", alpha=0.85,
            label=f"|$\\Delta\\{names[0]}$| <= {a:.4g}, |$\\Delta\\{names[1]}$| <= {b:.4g} deg",
        )  # fmt: skip
        rect = result.rectangles[index]
        ra, rb = rad_to_deg(np.asarray(rect.half_widths_rad))
        ax.plot(
            [-ra, ra, ra, -ra, -ra], [-rb, -rb, rb, rb, -rb], color="C1", ls="--",
            label="largest rectangle of this plane alone",
        )  # fmt: skip
        bu, bv = rad_to_deg(result.box.limits_rad[[index, index + 1]])
        ax.plot(
            [-bu, bu, bu, -bu, -bu], [-bv, -bv, bv, bv, -bv], color="C2", lw=1.8,
            label="largest box that holds (all three angles at once)",
        )  # fmt: skip
        ax.plot([], [], color="C0", label=f"$\\Delta\\omega_{axis} = \\omega_m$")
        ax.set_xlabel(_LABELS[names[0]])
        ax.set_ylabel(_LABELS[names[1]])
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    fig.tight_layout()
    return save_png(fig, path)


def write_requirement_figures(result: OrientationRequirement, directory: str | Path) -> list[Path]:
    """Write ``figure4_rate_errors.png`` and ``figure5_requirement.png`` into ``directory``."""
    directory = Path(directory)
    return [
        plot_figure4(result, directory / "figure4_rate_errors.png"),
        plot_figure5(result, directory / "figure5_requirement.png"),
    ]


# ---- the calibration design (design_calibration) ----------------------------------------------
def _gravity_map(positions: PositionSet) -> tuple[np.ndarray, np.ndarray]:
    """Where gravity points in the payload frame at each position: its azimuth
    ``atan2(a_y, a_x)`` (deg) and ``a_z`` (g): an equal-area map of the sphere."""
    a = position_inputs(positions, 0.0).specific_force_g
    return np.degrees(np.arctan2(a[:, 1], a[:, 0])), a[:, 2]


def plot_calibration_design(design: CalibrationDesign, path: str | Path) -> Path:
    """The calibration design against its reference grid (PNG): (a) the positions over the first
    two joints, (b) where gravity points in the payload frame, (c) the limits of the boxes and of
    the paper's planes, (d) the search: each step's box against its D-efficiency."""
    plt = pyplot()
    fig, axes = plt.subplots(2, 2, figsize=(12, 9.5))
    ref_name, ref = design.reference.name, design.reference
    chosen = design.positions()
    ax = axes[0, 0]
    ref_deg, chosen_deg = np.degrees(ref.angles_rad), design.positions_deg
    ax.plot(ref_deg[:, 0], ref_deg[:, 1], "s", mfc="none", color="0.45", ms=8, label=ref_name)
    ax.plot(chosen_deg[:, 0], chosen_deg[:, 1], "o", color="C0", ms=5, label="design")
    names = [f"phi{r.index} {r.joint}" for r in design.space.ranges]
    ax.set_xlabel(f"{names[0]} (deg)")
    ax.set_ylabel(f"{names[1]} (deg)")
    ax.set_title("(a) positions")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    ax.grid(alpha=0.3)
    ax = axes[0, 1]
    for positions, style, label in (
        (ref, dict(marker="s", mfc="none", color="0.45", ms=8), ref_name),
        (chosen, dict(marker="o", color="C0", ms=5), "design"),
    ):
        azimuth, up = _gravity_map(positions)
        ax.plot(azimuth, up, ls="none", label=label, **style)
    ax.set_xlim(-180, 180)
    ax.set_ylim(-1.05, 1.05)
    ax.set_xlabel(r"azimuth of gravity in the payload frame, atan2($a_y$, $a_x$) (deg)")
    ax.set_ylabel(r"$a_z$ (g)")
    ax.set_title("(b) gravity directions (equal-area map)")
    ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    ax.grid(alpha=0.3)
    ax = axes[1, 0]
    bars = (
        ("design: box that holds", design.box.limits_rad, "C0"),
        (f"{ref_name}: box that holds", design.reference_box.limits_rad, "0.45"),
        ("design: paper's planes", design.planes.limits_rad, "C1"),
        (f"{ref_name}: paper's planes", design.reference_planes.limits_rad, "C3"),
    )
    x = np.arange(3)
    for k, (label, limits, color) in enumerate(bars):
        ax.bar(x + (k - 1.5) * 0.2, np.degrees(limits), 0.2, color=color, label=label,
               hatch="//" if "planes" in label else None, alpha=0.9)  # fmt: skip
    ax.set_xticks(x, [r"$I_\psi$", r"$I_\theta$", r"$I_\gamma$"])
    ax.set_ylabel("limit (deg)")
    ax.set_title(
        f"(c) orientation requirement for {design.accuracy_dph:g} deg/h: "
        f"{design.looser_by:.2f} x looser (geometric mean)"
    )
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, axis="y")
    ax = axes[1, 1]
    volume = np.array([s.volume_rad3 for s in design.steps])
    log_det = np.array([s.log_det for s in design.steps])
    reference_log_det = log_det[-1] - 14 * np.log(design.d_efficiency)
    ratio = (volume / design.steps[0].volume_rad3) ** (1 / 3)
    ax.plot(np.exp((log_det - reference_log_det) / 14), ratio, ".-", color="C0", lw=0.8)
    ax.plot([1.0], [1.0], "s", mfc="none", color="0.45", ms=9, label=ref_name)
    ax.plot(np.exp((log_det[-1] - reference_log_det) / 14), ratio[-1], "o", color="C0", ms=8,
            label="design")  # fmt: skip
    ax.axvline(design.min_efficiency, color="red", ls="--", lw=0.8, label="precision floor")
    ax.set_xlabel("D-efficiency against the reference (14 drift coefficients)")
    ax.set_ylabel("box (geometric mean) / start's")
    ax.set_title(f"(d) the search ({len(design.steps) - 1} steps)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.suptitle(
        f"GyroWheel calibration positions least sensitive to the table's orientation errors: "
        f"{design.n_positions} positions, {design.space.table_name}, seed {design.space.seed}",
        fontsize=10,
    )
    fig.tight_layout()
    return save_png(fig, path)


def write_calibration_design_figures(
    design: CalibrationDesign, directory: str | Path
) -> list[Path]:
    """Write ``design_calibrate.png`` into ``directory``."""
    return [plot_calibration_design(design, Path(directory) / "design_calibrate.png")]
