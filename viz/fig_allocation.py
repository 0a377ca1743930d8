"""Paper Figures 8 and 9: sensitivities of the orientation error, and the Monte Carlo check.

Figure 8: mean |d(dpsi, dtheta, dgamma)/d(error)| of the exact Pinocchio chain over the rotation
angles. Figure 9: N random turntables drawn inside the Table 4 allocation (paper inputs, paper
weights), their largest |dpsi|, |dtheta|, |dgamma| over a phi2 grid against the limits (seed 1).
"""

import sys
from pathlib import Path

from turntable_pin import (
    OrientationLimits,
    average_sensitivities,
    plot_monte_carlo,
    plot_sensitivities,
    run_monte_carlo,
)
from turntable_pin.allocation.solver import allocate_tolerances


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    sensitivities = average_sensitivities(phi1_grid_deg=[0.0])
    figure8 = plot_sensitivities(sensitivities, out_dir / "figure8_sensitivities.png")
    limits = OrientationLimits.from_arcmin(1.4801, 1.56, 1.4801)
    allocation = allocate_tolerances(limits, "paper")
    result = run_monte_carlo(
        allocation.upper_bounds_rad,
        limits,
        n=1000 if fast else 10_000,
        seed=1,
        lower_bounds_rad=allocation.capability.lower_bounds_rad,
        progress=False,
    )
    figure9 = plot_monte_carlo(result, out_dir / "figure9_montecarlo.png")
    return [Path(figure8), Path(figure9)]


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
