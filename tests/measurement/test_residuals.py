"""Where a fit fails: failing positions, harmonic content, plots."""

import numpy as np
import pytest

from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.residuals import (
    analyse_residuals,
    harmonic_amplitudes,
    orientation_residuals,
)
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.report.measurement_figures import write_residual_plots


def test_harmonic_amplitudes_of_a_pure_harmonic():
    angle = np.arange(0, 360, 30.0)
    values = np.stack([2.0 * np.cos(np.radians(3 * angle) + 0.3), 0.5 + 0 * angle], axis=1)
    amp = harmonic_amplitudes(values, angle, 5)
    np.testing.assert_allclose(amp[:, 0], [0, 0, 2.0, 0, 0], atol=1e-12)
    np.testing.assert_allclose(amp[:, 1], 0, atol=1e-12)


def test_an_outlier_is_the_failing_position_and_harmonics_show_a_missing_term(tmp_path):
    sim = simulate_measurements(seed=4, noise_arcsec=0.5)
    angles = sim.data.angles_rad.copy()
    angles[17, 2] += 6.0 / ARCSEC_PER_RAD  # 12 sigma on dgamma
    angles[:, 1] += (
        2.0 / ARCSEC_PER_RAD * np.sin(2 * sim.data.joint_rad[:, 0])
    )  # 2/rev in phi1 on dtheta
    data = sim.data.replace(angles_rad=angles, dirs=())
    analysis = analyse_residuals(orientation_residuals(fit_orientation(data)), k_sigma=3)
    worst = analysis.failing[0]
    assert worst["row"] == int(data.rows[17]) and worst["component"] == "dgamma"
    assert worst["sigmas"] > 8
    dtheta_phi1 = analysis.harmonics["phi1_deg"]["dtheta"]
    assert int(np.argmax(dtheta_phi1)) == 1 and dtheta_phi1[1] == pytest.approx(2.0, abs=0.2)
    paths = write_residual_plots([orientation_residuals(fit_orientation(data))], tmp_path)
    assert all(p.read_bytes()[:4] == b"\x89PNG" for p in paths)
    assert analysis.to_dict()["n_failing"] == len(analysis.failing)
