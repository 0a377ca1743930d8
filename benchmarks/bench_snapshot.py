"""Time the headless snapshot (meshcat static page + headless Chromium) and the image check.

Run by hand: ``python benchmarks/bench_snapshot.py [--repeat 5]``. Prints the median and the
spread of the scene stage (meshcat server start, drawing, static page) and the browser stage.
"""

import argparse
import math
import statistics
import tempfile
import time
from pathlib import Path

from turntable_pin import SetupScene, TurntableErrors, render_snapshot
from turntable_pin.core.resources import models_dir
from turntable_pin.viewer.browser import check_page_images


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    errors = TurntableErrors.from_yaml(models_dir() / "examples" / "errors_example.yaml")
    scene = SetupScene(errors)
    with tempfile.TemporaryDirectory() as tmp:
        for width, height in ((800, 600), (1600, 1200)):
            scene_s, browser_s, total_s = [], [], []
            for i in range(args.repeat):
                start = time.perf_counter()
                out = Path(tmp) / f"shot_{i}.png"
                result = render_snapshot(
                    scene, (math.radians(30), math.radians(45)), out, width=width, height=height
                )
                total_s.append(time.perf_counter() - start)
                scene_s.append(result.scene_seconds)
                browser_s.append(result.browser_seconds)
            print(
                f"snapshot {width}x{height}: total median {statistics.median(total_s):.2f} s "
                f"(min {min(total_s):.2f}, max {max(total_s):.2f}); scene "
                f"{statistics.median(scene_s):.2f} s, browser {statistics.median(browser_s):.2f} s"
            )
        page = Path(tmp) / "index.html"
        page.write_text("".join(f'<img src="shot_{i}.png">' for i in range(args.repeat)))
        times = [check_page_images(page).seconds for _ in range(args.repeat)]
        print(f"image check of a {args.repeat}-image page: median {statistics.median(times):.2f} s")


if __name__ == "__main__":
    main()
