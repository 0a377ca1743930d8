"""Paper Figures 4 and 5: rate-sensing errors against the orientation error, and the requirement.

Figure 4: dwx over (dpsi, dtheta) and dwy over (dtheta, dgamma) for the Table 1 GyroWheel on the
30-degree grid at latitude 45.75 deg (eq. 13 as printed). Figure 5: their contours at
w_m = 0.01 deg/h and the largest centred rectangles inside, giving I_psi, I_theta, I_gamma.
"""

import math
import sys
from pathlib import Path

from turntable_pin import PositionSet, orientation_requirement
from turntable_pin.report.requirement_figures import write_requirement_figures


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    positions = PositionSet.parse("grid:90" if fast else "grid:30")
    result = orientation_requirement(0.01, positions, math.radians(45.75))
    return write_requirement_figures(result, out_dir)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
