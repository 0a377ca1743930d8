"""The setup in 3-D: the turntable, example errors magnified, ideal and actual payload frames.

Rendered by meshcat in headless Chromium (Debian package ``chromium``), at two positions.
"""

import sys
from pathlib import Path

import numpy as np

from turntable_pin import TurntableErrors
from turntable_pin.core.resources import models_dir
from turntable_pin.viewer.scene import SetupScene
from turntable_pin.viewer.snapshot import render_snapshot

POSITIONS_DEG = ((30.0, 45.0), (90.0, 0.0))


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    errors = TurntableErrors.from_yaml(models_dir() / "examples" / "errors_example.yaml")
    scene = SetupScene(errors)
    width, height = (480, 360) if fast else (800, 600)
    written = []
    for phi1_deg, phi2_deg in POSITIONS_DEG[:1] if fast else POSITIONS_DEG:
        out = Path(out_dir) / f"setup_phi1_{phi1_deg:g}_phi2_{phi2_deg:g}.png"
        result = render_snapshot(
            scene, np.radians([phi1_deg, phi2_deg]), out, width=width, height=height
        )
        print(f"wrote {out} ({result.scene_seconds + result.browser_seconds:.1f} s)")
        written.append(out)
    return written


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
