"""Orientation error of the example turntable against the inner angle phi2.

Exact dR = Rd^T Rt of the Pinocchio model (batch path, OrientationErrorField) as solid lines, the
small-angle model of eq. 26 dashed. dtheta is constant to first order, dpsi and dgamma are
once-per-revolution in phi2. The exact curves do not depend on phi1: Ry(phi1) and the outer
position error Ry(dphi_y1) commute, so Ry(phi1) cancels in Rd^T Rt; the title shows the largest
difference found between phi1 = 0, 45 and 90 deg.
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from turntable_pin import (
    OrientationErrorField,
    TurntableErrors,
    small_angle_orientation_error,
)
from turntable_pin.core.resources import models_dir
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.model.paper_table import paper_table

PHI1_DEG = (0.0, 45.0, 90.0)


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    errors = TurntableErrors.from_yaml(models_dir() / "examples" / "errors_example.yaml")
    field = OrientationErrorField.from_chain(paper_table().chain, errors.as_array()[None])
    phi2_deg = np.linspace(0.0, 360.0, 73 if fast else 721)
    phi2_rad = np.radians(phi2_deg)
    exact = (
        np.stack([field.angles(np.radians(p), phi2_rad)[0].T for p in PHI1_DEG]) * ARCSEC_PER_RAD
    )  # (phi1, 3, M)
    spread_arcsec = np.abs(exact - exact[0]).max()
    small = small_angle_orientation_error(errors, phi2_rad).T * ARCSEC_PER_RAD  # (3, M)

    fig, axes = plt.subplots(3, 1, figsize=(7, 7), sharex=True)
    for ax, name, values, first_order in zip(
        axes, ("dpsi", "dtheta", "dgamma"), exact[0], small, strict=True
    ):
        ax.plot(phi2_deg, values, label="exact (Pinocchio)")
        ax.plot(phi2_deg, first_order, "k--", lw=1, label="eq. 26")
        ax.set_ylabel(f"{name} (arcsec)")
        ax.ticklabel_format(axis="y", useOffset=False)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[-1].set_xlabel("phi2 (deg)")
    axes[-1].set_xticks(np.arange(0, 361, 45))
    fig.suptitle(
        "Orientation error of the example turntable\n"
        f"(phi1 = 0, 45, 90 deg differ by at most {spread_arcsec:.1e} arcsec)",
        fontsize=11,
    )
    fig.tight_layout()
    out = Path(out_dir) / "orientation_vs_phi2.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80 if fast else 120)
    plt.close(fig)
    return [out]


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
