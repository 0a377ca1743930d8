"""Plots that show what the text finds: a planted 3/rev term, projected, fitted, drawn; the map
over both angles; forward and backward passes told apart; angles not measured (empty cells)
named on every figure and never drawn."""

import dataclasses
import io

import numpy as np
import pytest

from conftest import REPO_DIR, figure_texts
from turntable_pin import TurntableErrors
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.diagnosis import OrientationFamily, diagnose_measurements
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.residuals import analyse_residuals, orientation_residuals
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.measurement.user_effects import resolve_effects
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.report.measurement_figures import (
    _positions_mean,
    direction_of,
    map_limit,
    residual_figure,
    residual_map_figure,
    structure_term_figure,
    write_residual_plots,
    write_structure_plots,
)

PLANTED_ARCSEC = 2.0
PHASE_RAD = 0.7


def _png_size(png: bytes) -> tuple[int, int]:
    from PIL import Image

    with Image.open(io.BytesIO(png)) as image:
        image.verify()
    with Image.open(io.BytesIO(png)) as image:
        return image.size


@pytest.fixture(scope="module")
def planted():
    """A 30-degree grid (144 positions, sigma 1 arcsec) with 2 arcsec of 3/rev in phi2 on dtheta."""
    sim = simulate_measurements(TurntableErrors.from_arcsec(deps_y=4, dalpha_x1=2), seed=3)
    data = sim.data
    angles = np.array(data.angles_rad)
    angles[:, 1] += PLANTED_ARCSEC * np.cos(3 * data.joint_rad[:, 1] - PHASE_RAD) / ARCSEC_PER_RAD
    data = dataclasses.replace(data, angles_rad=angles)
    return data, diagnose_measurements(data)


def test_every_probe_factors_into_its_direction_times_its_functions(planted):
    data, _ = planted
    family = OrientationFamily(data)
    probes = family.probes(family.fit([]))
    assert probes and all(p.factors is not None for p in probes)
    for p in probes:
        f = p.factors
        basis = f.functions(f.values)
        rebuilt = (f.direction_matrix()[:, :, None] * basis[:, None, :]).reshape(-1, basis.shape[1])
        columns = p.matrix()
        assert np.allclose(rebuilt, columns, rtol=0, atol=1e-12 * np.abs(columns).max()), p.name


def test_the_planted_term_is_found_and_its_projection_shows_it(planted):
    _, diagnosis = planted
    assert diagnosis.steps == []  # no catalogued effect: the structure search must speak
    [term] = diagnosis.structure
    assert term.name.endswith("3/rev in phi2")
    pr = term.projection()
    assert pr.variable == "phi2" and pr.value_unit == "deg" and pr.unit == "arcsec"
    assert pr.values.shape == pr.projected.shape == pr.fitted.shape == (144,)
    # the data behind the plot carry the planted 3/rev: fit one to the points themselves
    phi2 = np.radians(pr.values)
    design = np.stack([np.cos(3 * phi2), np.sin(3 * phi2)], axis=1)
    coef, *_ = np.linalg.lstsq(design, pr.projected, rcond=None)
    noise = float(np.median(pr.noise))
    assert noise == pytest.approx(1.0, rel=0.05)  # sigma 1 arcsec on dtheta, which it enters 1:1
    amplitude_std = noise * np.sqrt(2 / pr.values.size)
    assert np.hypot(*coef) == pytest.approx(PLANTED_ARCSEC, abs=4 * amplitude_std)
    assert np.arctan2(coef[1], coef[0]) == pytest.approx(PHASE_RAD, abs=0.15)
    # the fitted curve passes through the points: what is left of them is the noise, unbiased
    left = pr.projected - pr.fitted
    assert abs(left.mean()) < 4 * noise / np.sqrt(left.size)
    assert np.sqrt(np.mean(left**2)) == pytest.approx(noise, rel=0.2)
    assert np.allclose(term.curve(np.radians(pr.values)), pr.fitted)
    assert np.hypot(*coef) == pytest.approx(term.amplitude, rel=1e-6)
    # the per-observation data stay out of the JSON
    assert set(term.to_dict()) == {
        "term", "description", "delta_bic", "amplitude", "unit", "coefficients", "effect_spec"
    }  # fmt: skip


def test_term_figure_and_maps_are_valid_pngs(planted):
    _, diagnosis = planted
    png = structure_term_figure(diagnosis.structure[0])
    width, height = _png_size(png)
    assert width > 400 and height > 200
    rs = orientation_residuals(diagnosis.base_fit)
    a_map = residual_map_figure([rs], map_limit([rs]))
    assert _png_size(a_map)[0] > 600
    single = dataclasses.replace(rs, angles_deg={"phi1_deg": rs.angles_deg["phi1_deg"]})
    assert residual_map_figure([single]) is None  # one angle: no map


def test_the_map_shows_the_planted_phi2_structure_in_dtheta(planted):
    _, diagnosis = planted
    rs = orientation_residuals(diagnosis.base_fit)
    phi1, phi2, mean = _positions_mean(rs.angles_deg["phi1_deg"], rs.angles_deg["phi2_deg"],
                                       rs.residuals)  # fmt: skip
    assert mean.shape == (144, 3)
    # averaged over phi1, the dtheta map keeps the 3/rev in phi2; dpsi keeps none of it
    rows = np.unique(phi2)
    profile = np.array([mean[phi2 == v].mean(axis=0) for v in rows])
    trig = np.stack([np.cos(3 * np.radians(rows)), np.sin(3 * np.radians(rows))], axis=1)
    amp = np.hypot(*np.linalg.lstsq(trig, profile, rcond=None)[0])
    assert amp[1] > 1.5 and amp[0] < 0.5


def test_forward_and_backward_passes_are_told_apart():
    sim = simulate_measurements(seed=4)
    rs = orientation_residuals(diagnose_measurements(sim.data).base_fit)
    assert set(direction_of(rs, "phi1_deg")) == {-1.0, 1.0}
    assert np.array_equal(direction_of(rs, "phi2_deg"), sim.data.dirs[1])
    assert direction_of(rs, "time_s") is None
    assert direction_of(dataclasses.replace(rs, others={}), "phi1_deg") is None
    assert _png_size(residual_figure([rs]))[1] > 1000


def test_plot_files_exist_and_are_pngs(planted, tmp_path):
    _, diagnosis = planted
    sets = [orientation_residuals(diagnosis.base_fit), orientation_residuals(diagnosis.best_fit)]
    paths = write_residual_plots(sets, tmp_path)
    assert [p.name for p in paths] == ["residuals.png", "harmonics.png", "residual_maps.png"]
    paths += write_structure_plots(diagnosis.structure, tmp_path / "terms")
    assert paths[-1].name == "structure_1.png" and len(paths) == 4
    for path in paths:
        assert path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        _png_size(path.read_bytes())


def _not_measured(data, rows, angle: int):
    """``data`` with angle ``angle`` (0 dpsi, 1 dtheta, 2 dgamma) emptied at ``rows``."""
    angles = np.array(data.angles_rad)
    angles[rows, angle] = np.nan
    return dataclasses.replace(data, angles_rad=angles)


@pytest.mark.parametrize("urdf", [None, "single_axis_rate_table.urdf"])
def test_an_angle_never_measured_is_named_on_every_figure_and_not_drawn(
    urdf, tmp_path, drawn_figures
):
    """A pointing run has no roll: ``dgamma`` empty in every row (its harmonics are None, which
    the harmonics figure once handed to matplotlib's bar and crashed)."""
    table = None if urdf is None else GenericTable(REPO_DIR / "models" / urdf)
    sim = simulate_measurements(turntable=table, seed=9)
    data = _not_measured(sim.data, slice(None), 2)
    base = orientation_residuals(fit_orientation(data, turntable=table))
    harmonics = analyse_residuals(base).harmonics
    assert harmonics and all(set(h["dgamma"]) == {None} for h in harmonics.values())
    paths = write_residual_plots([base, base], tmp_path)
    names = ["residuals.png", "harmonics.png"] + ([] if urdf else ["residual_maps.png"])
    assert [p.name for p in paths] == names and all(p.stat().st_size > 0 for p in paths)
    assert len(drawn_figures) == len(names)
    for fig in drawn_figures:
        words, legends = figure_texts(fig)
        assert "dgamma: not measured" in words
        assert "dgamma" not in legends and "dgamma residual" not in words
    assert set(figure_texts(drawn_figures[0])[1]) == {"dpsi", "dtheta"}
    if not urdf:  # the maps: two rows (the sets) of dpsi and dtheta, and the colour bar
        assert len(drawn_figures[2].axes) == 2 * 2 + 1


def test_an_angle_measured_at_some_positions_is_drawn_where_measured(tmp_path, drawn_figures):
    sim = simulate_measurements(
        TurntableErrors.from_arcsec(deps_y=4, dalpha_x1=2), {"gravity_sag": {"k": 3.0}}, seed=3
    )
    data = _not_measured(_not_measured(sim.data, slice(None, None, 2), 0), slice(None, None, 3), 2)
    before = orientation_residuals(fit_orientation(data))
    after = orientation_residuals(fit_orientation(data, resolve_effects(["gravity_sag"])))
    paths = write_residual_plots([before, after], tmp_path)
    assert [p.name for p in paths] == ["residuals.png", "harmonics.png", "residual_maps.png"]
    residuals, harmonics, maps = drawn_figures
    for fig in drawn_figures:
        words, _ = figure_texts(fig)
        assert "dpsi: measured at 72 of 144 positions" in words
        assert "dgamma: measured at 96 of 144 positions" in words and "dtheta:" not in words
    assert set(figure_texts(residuals)[1]) == set(figure_texts(harmonics)[1]) == {
        "dpsi", "dtheta", "dgamma"
    }  # fmt: skip
    # against the measurement order: one point per measured dpsi
    [dpsi] = [line for line in residuals.axes[0].get_lines() if line.get_label() == "dpsi"]
    assert np.isfinite(dpsi.get_ydata()).sum() == 72
    # the dpsi map: coloured squares where measured, hollow ones where not
    hollow, coloured = maps.axes[0].collections
    assert len(coloured.get_offsets()) == 72 and len(hollow.get_offsets()) == 72
    assert "hollow grey squares" in figure_texts(maps)[0]


def test_the_map_averages_the_measured_repeats_only():
    x, y = np.array([0.0, 0.0, 90.0]), np.zeros(3)
    values = np.array([[1.0, np.nan], [3.0, 2.0], [np.nan, np.nan]])
    px, py, mean = _positions_mean(x, y, values)
    assert px.tolist() == [0.0, 90.0] and py.tolist() == [0.0, 0.0]
    np.testing.assert_array_equal(mean, [[2.0, 2.0], [np.nan, np.nan]])
