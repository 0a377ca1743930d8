"""What each kind of turntable error does to the setup, one error at a time, magnified.

Each panel is the 3-D scene (meshcat in headless Chromium) with a single error of the example's
size magnified to 6 degrees (deta to 30 mm), at phi1 = 30 deg, phi2 = 45 deg. Orthogonality,
outer-axis wobble and the outer position error tilt the inner axis (magenta rod against the dark
ideal one) and the payload with it; the intersection error moves the axis sideways without
turning anything; inner-axis wobble and the inner position error turn only the payload (the
coloured triad parts from the dark ideal one while the axis stays put).
"""

import math
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mimage
import matplotlib.pyplot as plt

from turntable_pin import Exaggeration, SetupScene, TurntableErrors, render_snapshot

CLOSE_UP_M = (0.42, -0.30, 0.24)  # eye offset from the table centre: the payload fills the view
PANELS = (
    ('orthogonality deps_x = 4"', {"deps_x": 4.0}),
    ("intersection deta = 0.2 mm", {"deta_mm": 0.2}),
    ('outer-axis wobble dalpha_x1 = 3"', {"dalpha_x1": 3.0}),
    ('inner-axis wobble dalpha_y2 = -2.2"', {"dalpha_y2": -2.2}),
    ('inner position dphi_z2 = -1.5"', {"dphi_z2": -1.5}),
    ('outer position dphi_y1 = 2"', {"dphi_y1": 2.0}),
)


def main(out_dir: Path, fast: bool = False) -> list[Path]:
    panels = PANELS[:2] if fast else PANELS
    width, height = (240, 180) if fast else (480, 360)
    images = []
    with tempfile.TemporaryDirectory() as tmp:
        for i, (title, entries) in enumerate(panels):
            errors = TurntableErrors.from_arcsec(**entries)
            k = Exaggeration.for_errors(errors, display_angle_rad=math.radians(6.0))
            shot = Path(tmp) / f"panel_{i}.png"
            scene = SetupScene(
                errors, exaggeration=k, camera_target_m=(0.0, 0.0, 0.0), camera_offset_m=CLOSE_UP_M
            )
            render_snapshot(
                scene,
                (math.radians(30.0), math.radians(45.0)),
                shot,
                width=width,
                height=height,
                legend=False,
            )
            images.append((title, mimage.imread(shot)))
    cols = 2 if fast else 3
    rows = math.ceil(len(images) / cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.6 * rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    for ax, (title, image) in zip(axes.ravel(), images, strict=False):
        ax.imshow(image)
        ax.set_title(title, fontsize=10)
    fig.suptitle("One error at a time, magnified (coloured: actual, dark: ideal)", fontsize=11)
    fig.tight_layout()
    out = Path(out_dir) / "error_effects.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=80 if fast else 110)
    plt.close(fig)
    return [out]


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--fast"]
    main(Path(args[0]) if args else Path("figures"), fast="--fast" in sys.argv)
