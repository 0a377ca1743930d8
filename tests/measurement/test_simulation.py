"""Simulated measurements: the schedule, the seed, the noise and the file format."""

import numpy as np
import pytest

from turntable_pin import InputError, TurntableErrors
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.model.paper_table import paper_table


def test_grid_schedule_and_reproducible_seed():
    a = simulate_measurements(seed=5)
    b = simulate_measurements(seed=5)
    c = simulate_measurements(seed=6)
    assert a.data.n_positions == 144
    np.testing.assert_array_equal(a.data.angles_rad, b.data.angles_rad)
    assert not np.array_equal(a.data.angles_rad, c.data.angles_rad)
    np.testing.assert_allclose(np.degrees(a.data.joint_rad[:, 0][:13]), [0] * 12 + [30], atol=1e-12)
    np.testing.assert_allclose(a.data.time_s[:3], [0, 60, 120])


def test_random_order_with_repeats_is_a_permutation_of_the_grid():
    sim = simulate_measurements(schedule=Schedule(90, 45, order="random", repeats=3), seed=1)
    pairs = sorted(
        zip(
            np.degrees(sim.data.joint_rad[:, 0]).round(6),
            np.degrees(sim.data.joint_rad[:, 1]).round(6),
            strict=True,
        )
    )
    expected = sorted((a, b) for a in (0, 90, 180, 270) for b in range(0, 360, 45)) * 1
    assert pairs == sorted(expected * 3)


def test_motion_approach_follows_the_moves():
    phi1 = (0.0, 30.0, 30.0, 10.0, 10.0, 50.0)
    s = Schedule(approach="motion", positions=tuple((a, 0.0) for a in phi1))
    dirs = s.rows(np.random.default_rng(0), paper_table()).dirs[0]
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
    phi1, phi2 = sim.data.joint_rad[:, 0], sim.data.joint_rad[:, 1]
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
    np.testing.assert_array_equal(back.dirs[0], sim.data.dirs[0])
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


# --- the designs engineers run: positions, sweeps, passes, random positions, uneven noise --------


def _deg(sim):
    return np.degrees(sim.data.joint_rad).round(6)


def test_explicit_positions_are_measured_in_their_order_with_their_dirs_and_times():
    schedule = Schedule(
        positions=((0, 0), (90, 45), (180, 10), (90, 45)),
        positions_dirs=((1, -1, 1, 1), None),
        positions_time_s=(0, 10, 30, 31),
    )
    sim = simulate_measurements(schedule=schedule, seed=3)
    assert _deg(sim).tolist() == [[0, 0], [90, 45], [180, 10], [90, 45]]
    assert sim.data.dirs[0].tolist() == [1, -1, 1, 1]
    assert set(sim.data.dirs[1].tolist()) <= {-1, 1}  # the approach rule (random) for joint 2
    assert sim.data.time_s.tolist() == [0, 10, 30, 31]
    twice = simulate_measurements(schedule=Schedule(positions=((0, 0), (30, 60)), repeats=2))
    assert _deg(twice).tolist() == [[0, 0], [30, 60], [0, 0], [30, 60]]
    np.testing.assert_allclose(twice.data.time_s, [0, 60, 120, 180])


def test_sweeps_move_one_axis_at_a_time_and_hold_the_others_at_their_start():
    schedule = Schedule(90, 120, starts_deg=(0, 90), sweep=("phi1", "phi2"), approach="motion")
    sim = simulate_measurements(schedule=schedule)
    assert _deg(sim).tolist() == [
        [0, 90], [90, 90], [180, 90], [270, 90],  # phi1 swept at phi2 = 90
        [0, 90], [0, 210], [0, 330],  # then phi2 swept at phi1 = 0
    ]  # fmt: skip
    assert sim.data.dirs[0].tolist() == [1, 1, 1, 1, -1, -1, -1]
    assert sim.data.dirs[1].tolist() == [1, 1, 1, 1, 1, 1, 1]
    assert Schedule(90, 120, sweep=("phi2",)).count() == 3
    assert "sweep=phi1,phi2 phi1_step_deg=90 phi2_step_deg=120 held at phi1_start_deg=0 " \
        "phi2_start_deg=90" in sim.comment()  # fmt: skip


def test_passes_go_forward_then_backward_and_the_directions_follow_the_pass():
    sim = simulate_measurements(schedule=Schedule(180, 120, passes=2), seed=1)
    forward = [[0, 0], [0, 120], [0, 240], [180, 0], [180, 120], [180, 240]]
    assert _deg(sim).tolist() == (forward + forward[::-1]) * 2
    expected = ([1] * 6 + [-1] * 6) * 2
    assert sim.data.dirs[0].tolist() == expected and sim.data.dirs[1].tolist() == expected
    assert sim.schedule.approach == "motion" and "approach=motion passes=2" in sim.comment()
    positive = simulate_measurements(schedule=Schedule(180, 120, passes=1, approach="positive"))
    assert set(positive.data.dirs[0].tolist()) == {1}


def test_random_positions_are_uniform_seeded_and_recorded():
    a = simulate_measurements(schedule=Schedule(random_positions=500), seed=4)
    b = simulate_measurements(schedule=Schedule(random_positions=500), seed=4)
    c = simulate_measurements(schedule=Schedule(random_positions=500), seed=5)
    np.testing.assert_array_equal(a.data.joint_rad, b.data.joint_rad)
    assert not np.array_equal(a.data.joint_rad, c.data.joint_rad)
    deg = _deg(a)
    assert deg.min() >= 0 and deg.max() <= 360
    assert np.all(np.histogram(deg[:, 0], bins=4, range=(0, 360))[0] > 90)  # spread over the turn
    assert np.array_equal(deg, np.round(deg, 6))
    assert "schedule: random_positions=500 uniform from phi1_start_deg=0" in a.comment()


def test_uneven_noise_per_row_and_noise_per_angle(tmp_path):
    sim = simulate_measurements(schedule=Schedule(15, 15), noise_arcsec=2.0, noise_spread=4.0,
                                seed=8)  # fmt: skip
    sigma = sim.data.sigma_rad[:, 0] * ARCSEC_PER_RAD
    assert 0.5 <= sigma.min() < 0.7 and 5.7 < sigma.max() <= 8.0
    assert abs(np.mean(np.log(sigma / 2.0))) < 0.1  # log-uniform about the stated sigma
    pulls = (sim.data.angles_rad - sim.truth_rad) / sim.data.sigma_rad
    assert pulls.std() == pytest.approx(1.0, rel=0.05)
    assert "noise_arcsec=2 noise_spread=4" in sim.comment()
    back = read_measurements(sim.write_csv(tmp_path / "spread.csv"))
    np.testing.assert_allclose(back.sigma_rad, sim.data.sigma_rad, rtol=1e-12)
    per_angle = simulate_measurements(noise_arcsec=(0.5, 2.0, 1.0), seed=8)
    noise = (per_angle.data.angles_rad - per_angle.truth_rad) * ARCSEC_PER_RAD
    np.testing.assert_allclose(noise.std(axis=0), [0.5, 2.0, 1.0], rtol=0.15)
    path = per_angle.write_csv(tmp_path / "per_angle.csv")
    header = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")][0]
    assert "sigma_dpsi_arcsec,sigma_dtheta_arcsec,sigma_dgamma_arcsec" in header
    assert "# noise_arcsec=0.5,2,1 (dpsi,dtheta,dgamma)" in path.read_text()
    bare = per_angle.write_csv(tmp_path / "bare.csv", with_sigma=False)
    assert read_measurements(bare).sigma_rad is None


def test_the_existing_options_draw_the_same_numbers():
    # A schedule without the new options, and even noise, must keep every earlier file.
    sim = simulate_measurements(schedule=Schedule(30, 30, order="random"), seed=9)
    rng = np.random.default_rng(9)
    perm = rng.permutation(144)
    np.testing.assert_array_equal(np.degrees(sim.data.joint_rad[:, 0]).round(6),
                                  (np.repeat(np.arange(0, 360, 30), 12)[perm]))  # fmt: skip
    assert sim.schedule.approach == "random"
    assert "schedule: phi1_step_deg=30 phi2_step_deg=30 order=random repeats=1 dwell_s=60 " \
        "approach=random\n" in sim.comment()  # fmt: skip


def test_a_sweep_of_an_axis_the_table_lacks_is_refused():
    with pytest.raises(InputError, match="the table has no axis phi4"):
        simulate_measurements(schedule=Schedule(sweep=("phi4",)))


@pytest.mark.parametrize(
    ("kwargs", "fragment"),
    [
        ({"positions": ((0, 0),), "sweep": ("phi1",)}, "give one design of positions"),
        ({"random_positions": 5, "order": "random"}, "measured in their own order"),
        ({"sweep": ("theta1",)}, "unknown axis 'theta1'"),
        ({"sweep": ("phi1", "phi1")}, "swept twice"),
        ({"positions": ((0, 0),), "positions_time_s": (0,), "repeats": 2}, "give their times"),
        ({"positions": ((0, 0),), "positions_dirs": ((1,),), "passes": 1}, "passes set"),
        ({"positions": ((0, 0),), "positions_dirs": ((2,),)}, "+1 or -1"),
        ({"positions": ((0, 4000),)}, "within +-3600"),
        ({"positions": ((0, 0), (1, 2)), "positions_time_s": (0, -1)}, "positions_time_s"),
        ({"random_positions": 600_000, "passes": 1}, "1,200,000 rows"),
        ({"starts_deg": (5000.0,)}, "phi1_start_deg"),
    ],
)
def test_bad_designs_are_refused(kwargs, fragment):
    with pytest.raises(InputError, match=None) as info:
        Schedule(**kwargs)
    assert fragment in str(info.value)


def test_bad_noise_and_positions_for_the_table():
    with pytest.raises(InputError, match="noise_spread"):
        simulate_measurements(noise_spread=0.5)
    with pytest.raises(InputError, match="would leave"):
        simulate_measurements(noise_arcsec=1000, noise_spread=2)
    with pytest.raises(InputError, match="one number or three"):
        simulate_measurements(noise_arcsec=(1, 2))
    with pytest.raises(InputError, match="the table has 2 joints"):
        simulate_measurements(schedule=Schedule(positions=((0, 0, 0),)))
    with pytest.raises(InputError, match="no axis phi3"):
        simulate_measurements(schedule=Schedule(sweep=("phi3",)))


def test_angles_not_measured_are_empty_and_a_row_without_roll_sees_the_boresight():
    from conftest import REPO_DIR
    from turntable_pin.measurement.effects.base import PositionVariables
    from turntable_pin.measurement.fit import fit_orientation
    from turntable_pin.model.generic_table import GenericTable

    table = GenericTable(REPO_DIR / "models" / "german_equatorial_mount.urdf")
    errors = np.zeros(len(table.parameter_names))
    for name, value_deg in (("hour_angle.position", 5.7), ("tube_mount.rot_z", 0.3)):
        errors[table.parameter_names.index(name)] = np.radians(value_deg)
    sim = simulate_measurements(errors, turntable=table, seed=4, not_measured=("dgamma",))
    data = sim.data
    assert np.isnan(data.angles_rad[:, 2]).all() and not np.isnan(data.angles_rad[:, :2]).any()
    whole = OrientationModel(PositionVariables(data.joint_rad), (), table)
    values = {"hour_angle.position": np.radians(5.7), "tube_mount.rot_z": np.radians(0.3)}
    d_r = whole.rotation_error(whole.parameter_vector(values))
    residual = (data.angles_rad[:, 0] + d_r[:, 2, 0]) * 206264.806  # noise of 1 arcsec
    assert np.sqrt(np.mean(residual**2)) < 1.3
    assert np.sqrt(np.mean((data.angles_rad[:, 0] - d_r[:, 0, 2]) ** 2)) * 206264.806 > 10.0
    assert fit_orientation(data, turntable=table).result.chi2_reduced < 1.3
    with pytest.raises(InputError, match="at least one measured angle"):
        simulate_measurements(seed=1, not_measured=("dpsi", "dtheta", "dgamma"))
