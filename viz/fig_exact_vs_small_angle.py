"""Exact orientation error against the small-angle model of eq. 26.

Left: exact minus eq. 26 for the example errors along phi2 at phi1 = 30 deg (micro-arcseconds).
Right: the largest difference over all positions as the example errors are scaled up; the slope
of 2 on log-log axes shows eq. 26 is exact to first order and its error is second order.
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from turntable_pin import OrientationErrorField, TurntableErrors, small_angle_orientation_error
from turntable_pin.core.resources import models_dir
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.model.paper_table import paper_table

PHI1_DEG = 30.0


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    errors = TurntableErrors.from_yaml(models_dir() / "examples" / "errors_example.yaml")
    phi2_rad = np.radians(np.linspace(0.0, 360.0, 73 if fast else 721))
    scales = np.logspace(0, 3, 7 if fast else 19)

    chain = paper_table().chain
    field = OrientationErrorField.from_chain(chain, errors.as_array()[None])
    exact = field.angles(np.radians(PHI1_DEG), phi2_rad)[0]  # (N, 3)
    small = small_angle_orientation_error(errors, phi2_rad)  # (N, 3)
    diff_uas = (exact - small) * ARCSEC_PER_RAD * 1e6

    # Largest |exact - eq. 26| over a grid of positions, for the errors scaled by each factor.
    grid = np.radians(np.linspace(0.0, 360.0, 25 if fast else 73))
    g1, g2 = (a.ravel() for a in np.meshgrid(grid, grid, indexing="ij"))
    values = scales[:, None] * errors.as_array()[None]
    exact_all = OrientationErrorField.from_chain(chain, values).angles(g1, g2)  # (K, N, 3)
    small_all = small_angle_orientation_error(values[:, None, :], g2[None, :])
    worst_arcsec = np.abs(exact_all - small_all).max(axis=(1, 2)) * ARCSEC_PER_RAD
    largest_error_arcsec = scales * np.abs(errors.angular_array_rad()).max() * ARCSEC_PER_RAD

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    for i, name in enumerate(("dpsi", "dtheta", "dgamma")):
        left.plot(np.degrees(phi2_rad), diff_uas[:, i], label=name)
    left.set_xlabel("phi2 (deg)")
    left.set_ylabel("exact - eq. 26 (micro-arcsec)")
    left.set_title(f"example errors, phi1 = {PHI1_DEG:g} deg")
    left.set_xticks(np.arange(0, 361, 90))
    left.grid(alpha=0.3)
    left.legend(fontsize=8)
    right.loglog(largest_error_arcsec, worst_arcsec, "o-", label="largest |exact - eq. 26|")
    ref = worst_arcsec[0] * (largest_error_arcsec / largest_error_arcsec[0]) ** 2
    right.loglog(largest_error_arcsec, ref, "k--", lw=0.8, label="slope 2")
    right.set_xlabel("largest angular error (arcsec)")
    right.set_ylabel("largest difference over positions (arcsec)")
    right.set_title("example errors scaled 1 to 1000 times")
    right.grid(alpha=0.3, which="both")
    right.legend(fontsize=8)
    fig.tight_layout()
    out = Path(out_dir) / "exact_vs_small_angle.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80 if fast else 120)
    plt.close(fig)
    return [out]


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
