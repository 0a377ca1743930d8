"""Every figure the commands write is legible: no two texts overlap, none leaves the canvas, and
a note placed in a panel stays inside it (rendered through the one PNG saver, ``save_png``)."""

from __future__ import annotations

import importlib

import pytest

from conftest import EXAMPLES_DIR, cli

MODELS = EXAMPLES_DIR.parent
FIGURE_MODULES = ("requirement_figures", "allocation_figures", "measurement_figures", "html_report")


def text_problems(fig) -> list[str]:
    """What is wrong with the drawn texts of ``fig``, in words (empty: legible)."""
    from matplotlib.text import Text

    drawn = []
    draw = Text.draw

    def recording(self, renderer):
        draw(self, renderer)
        if self.get_visible() and self.get_text().strip():
            drawn.append((self, self.get_window_extent(renderer)))

    Text.draw = recording
    try:
        fig.canvas.draw()
    finally:
        Text.draw = draw
    boxes = [(t, b) for t, b in drawn if b.width > 0]
    width, height = fig.bbox.width, fig.bbox.height
    out = []
    for t, b in boxes:
        name = repr(t.get_text()[:40])
        if b.x0 < -1 or b.y0 < -1 or b.x1 > width + 1 or b.y1 > height + 1:
            out.append(f"{name} leaves the canvas")
        if t.axes is not None and t.get_transform() is t.axes.transAxes:
            panel = t.axes.bbox
            if (
                b.x0 < panel.x0 - 1
                or b.x1 > panel.x1 + 1
                or b.y0 < panel.y0 - 1
                or b.y1 > panel.y1 + 1
            ):
                out.append(f"{name} leaves its panel")
    for i, (t, a) in enumerate(boxes):
        for u, b in boxes[i + 1 :]:
            if t.get_rotation() % 90 or u.get_rotation() % 90:
                continue  # slanted labels: their upright boxes overlap, the glyphs do not
            overlap_x = min(a.x1, b.x1) - max(a.x0, b.x0)
            overlap_y = min(a.y1, b.y1) - max(a.y0, b.y0)
            if overlap_x > 1 and overlap_y > 1:
                out.append(f"{t.get_text()[:30]!r} overlaps {u.get_text()[:30]!r}")
    return out


@pytest.fixture
def checked(monkeypatch):
    """Every figure saved while it is active is checked; the problems by figure."""
    from turntable_pin.report import figures

    found: list[tuple[str, list[str]]] = []
    save = figures.save_png

    def checking(fig, path=None, **kw):
        found.append((fig._suptitle.get_text() if fig._suptitle else "", text_problems(fig)))
        return save(fig, path, **kw)

    for name in FIGURE_MODULES:
        monkeypatch.setattr(importlib.import_module(f"turntable_pin.report.{name}"), "save_png",
                            checking)  # fmt: skip
    return found


RUNS = [
    ["fit", "measurements_example.csv", "--effects", "inner_encoder_harmonics"],
    ["diagnose", "measurements_unknown_effect.csv"],
    ["diagnose", "measurements_three_axis.csv", "--urdf", "three_axis_imu_table"],
    ["diagnose", "measurements_rate_table.csv", "--urdf", "single_axis_rate_table"],
    ["requirement"],
    ["allocate"],
    ["montecarlo", "-n", "200"],
]


@pytest.mark.slow
@pytest.mark.parametrize("argv", RUNS, ids=lambda a: "-".join(a[:2]))
def test_every_figure_of_a_command_is_legible(argv, tmp_path, checked):
    result = cli(*argv, "--plots", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert checked, "no figure was drawn"
    assert [p for p in checked if p[1]] == []


@pytest.mark.slow
def test_the_report_s_figures_are_legible(tmp_path, checked):
    result = cli("report", "measurements_example.csv", "-o", str(tmp_path / "r.html"))
    assert result.returncode == 0, result.stderr
    assert checked and [p for p in checked if p[1]] == []


def _without_some_angles(kind: str, folder) -> list[str]:
    """Data and table arguments of a run with angles not measured: the MMT pointing run (no
    dgamma at all) or a simulated grid with dpsi and dgamma empty in some rows."""
    if kind == "pointing":
        run = folder / "mmt_run.csv"
        tpoint = EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"
        assert cli("import-tpoint", str(tpoint), "-o", str(run)).returncode == 0
        return [str(run), "--urdf", "altaz_mount"]
    import dataclasses

    import numpy as np

    from turntable_pin import TurntableErrors
    from turntable_pin.measurement.simulation import simulate_measurements

    errors = TurntableErrors.from_arcsec(dalpha_x1=2)
    sim = simulate_measurements(errors, {"gravity_sag": {"k": 3.0}}, seed=3)
    angles = np.array(sim.data.angles_rad)
    angles[::2, 0] = angles[::3, 2] = np.nan
    data = dataclasses.replace(sim.data, angles_rad=angles)
    return [str(dataclasses.replace(sim, data=data).write_csv(folder / "partial.csv"))]


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["pointing", "partial"])
def test_figures_of_angles_not_measured_are_legible(kind, tmp_path, checked):
    data = _without_some_angles(kind, tmp_path)
    result = cli("report", *data, "-o", str(tmp_path / "r.html"))
    assert result.returncode == 0, result.stderr
    result = cli("diagnose", *data, "--plots", str(tmp_path / "plots"))
    assert result.returncode == 0, result.stderr
    assert checked and [p for p in checked if p[1]] == []


def test_the_check_sees_overlapping_and_escaping_texts():
    from turntable_pin.report.figures import pyplot

    plt = pyplot()
    fig, ax = plt.subplots(figsize=(3, 2))
    ax.text(0.5, 0.5, "one label", transform=ax.transAxes)
    ax.text(0.52, 0.5, "another label", transform=ax.transAxes)
    ax.text(0.2, 0.1, "a note far too long to stay inside this small panel", transform=ax.transAxes)
    problems = text_problems(fig)
    plt.close(fig)
    assert any("overlaps" in p for p in problems)
    assert any("leaves its panel" in p for p in problems)
