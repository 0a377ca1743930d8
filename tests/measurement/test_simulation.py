"""Simulated measurements: the schedule, the seed, the noise and the file format."""

import numpy as np
import pytest

from turntable_pin import InputError, TurntableErrors
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.simulation import Schedule, simulate_measurements


def test_grid_schedule_and_reproducible_seed():
    a = simulate_measurements(seed=5)
    b = simulate_measurements(seed=5)
    c = simulate_measurements(seed=6)
    assert a.data.n_positions == 144
    np.testing.assert_array_equal(a.data.angles_rad, b.data.angles_rad)
    assert not np.array_equal(a.data.angles_rad, c.data.angles_rad)
    np.testing.assert_allclose(np.degrees(a.data.phi1_rad[:13]), [0] * 12 + [30], atol=1e-12)
    np.testing.assert_allclose(a.data.time_s[:3], [0, 60, 120])


def test_random_order_with_repeats_is_a_permutation_of_the_grid():
    sim = simulate_measurements(schedule=Schedule(90, 45, order="random", repeats=3), seed=1)
    pairs = sorted(
        zip(
            np.degrees(sim.data.phi1_rad).round(6),
            np.degrees(sim.data.phi2_rad).round(6),
            strict=True,
        )
    )
    expected = sorted((a, b) for a in (0, 90, 180, 270) for b in range(0, 360, 45)) * 1
    assert pairs == sorted(expected * 3)


def test_motion_approach_follows_the_moves():
    s = Schedule(approach="motion")
    dirs = s.directions(np.array([0.0, 30.0, 30.0, 10.0, 10.0, 50.0]), np.random.default_rng(0))
    assert dirs.tolist() == [1, 1, 1, -1, -1, 1]


def test_noise_and_truth(tmp_path):
    errors = TurntableErrors.from_arcsec(dphi_y1=4, deps_x=-3)
    sim = simulate_measurements(
        errors, {"gravity_sag": {"k": 2.0}}, noise_arcsec=0.5, seed=2,
        schedule=Schedule(15, 15),
    )  # fmt: skip
    noise = (sim.data.angles_rad - sim.truth_rad) * ARCSEC_PER_RAD
    assert noise.std() == pytest.approx(0.5, rel=0.05)
    model = OrientationModel(sim.data.variables(), [])
    expected_base = model.predict(errors.angular_array_rad())
    sag = sim.truth_rad - expected_base
    phi1, phi2 = sim.data.phi1_rad, sim.data.phi2_rad
    # to first order the sag adds k ax to dpsi and -k ay to dgamma (k = 2 arcsec per g)
    np.testing.assert_allclose(
        sag[:, 0] * ARCSEC_PER_RAD, -2 * np.sin(phi1) * np.cos(phi2), atol=1e-3
    )
    np.testing.assert_allclose(
        sag[:, 2] * ARCSEC_PER_RAD, -2 * np.sin(phi1) * np.sin(phi2), atol=1e-3
    )


def test_csv_round_trip_records_seed_and_truth(tmp_path):
    sim = simulate_measurements(
        TurntableErrors.from_arcsec(dalpha_x2=1.5), {"backlash": {"b1": 2.0}}, seed=11
    )
    path = sim.write_csv(tmp_path / "sim.csv")
    text = path.read_text()
    assert "# seed=11" in text and "backlash: b1=2" in text and "dalpha_x2_arcsec=1.5" in text
    back = read_measurements(path)
    np.testing.assert_allclose(back.angles_rad, sim.data.angles_rad, atol=1e-15)
    np.testing.assert_array_equal(back.dir1, sim.data.dir1)
    assert "30.0," in text.splitlines()[-1] or "330.0," in text.splitlines()[-1]
    no_sigma = read_measurements(sim.write_csv(tmp_path / "ns.csv", with_sigma=False))
    assert no_sigma.sigma_rad is None
    blind = sim.write_csv(tmp_path / "blind.csv", hide_truth=True)
    blind_text = blind.read_text()
    assert "# seed=11" in blind_text and "not recorded" in blind_text
    assert "backlash" not in blind_text and "dalpha_x2" not in blind_text
    np.testing.assert_array_equal(read_measurements(blind).angles_rad, back.angles_rad)


def test_bad_simulation_requests():
    with pytest.raises(InputError, match="has no parameter 'q'"):
        simulate_measurements(effects={"gravity_sag": {"q": 1.0}})
    with pytest.raises(InputError, match="unknown effect"):
        simulate_measurements(effects={"gravity": {"k": 1.0}})
    with pytest.raises(InputError, match="noise_arcsec"):
        simulate_measurements(noise_arcsec=0)
    with pytest.raises(InputError, match="order"):
        Schedule(order="spiral")


def test_cli_choices_match_the_library():
    from turntable_pin.cli import measurement
    from turntable_pin.measurement.simulation import APPROACHES, ORDERS

    assert measurement.ORDERS == ORDERS and measurement.APPROACHES == APPROACHES
