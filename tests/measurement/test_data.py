"""Reading orientation measurements: what is accepted, and what is refused with row and column."""

import numpy as np
import pytest

from conftest import write_file
from turntable_pin import InputError
from turntable_pin.measurement.data import read_measurements

HEAD = "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec"


def grid_rows(extra=lambda i: ""):
    rows = []
    for i, (a, b) in enumerate((a, b) for a in (0, 90, 180) for b in (0, 120, 240)):
        rows.append(f"{a},{b},1.5,-0.5,2.0{extra(i)}")
    return "\n".join(rows) + "\n"


def test_reads_columns_in_any_order_with_extras(tmp_path):
    text = "# comment\nnote,dgamma_arcsec,phi2_deg,phi1_deg,dtheta_arcsec,dpsi_arcsec,"
    text += "sigma_arcsec,time_s,dir1\n"
    text += "x,3,45,30,2,1,0.5,10,-1\ny,6,90,30,5,4,0.5,20,1\n"
    data = read_measurements(write_file(tmp_path, text))
    assert data.n_positions == 2
    np.testing.assert_allclose(np.degrees(data.joint_rad[:, 0]), [30, 30])
    np.testing.assert_allclose(data.angles_rad[0] * 206264.80624709636, [1, 2, 3])
    np.testing.assert_allclose(data.sigma_rad * 206264.80624709636, np.full((2, 3), 0.5))
    assert data.extra == {}  # the text column "note" is not a suspect
    assert (
        data.dirs[1] is None and data.dirs[0].tolist() == [-1, 1] and data.rows.tolist() == [3, 4]
    )


@pytest.mark.parametrize(
    "text, fragment",
    [
        ("phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec\n0,0,1,1\n", "missing required column(s)"),
        ("phi1_deg,phi_2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n0,0,1,1,1\n", "'phi2_deg'"),
        (HEAD + "\n0,0,1,1,1\n0,30,1,x,1\n", "row 3, column 'dtheta_arcsec': expected a number"),
        (HEAD + "\n0,0,1,1,NaN\n", "row 2, column 'dgamma_arcsec': expected a finite"),
        (HEAD + ",sigma_arcsec\n0,0,1,1,1,1\n0,30,1,1,1,0\n", "row 3, column 'sigma_arcsec': "),
        (HEAD + ",sigma_arcsec\n0,0,1,1,1,-2\n", "row 2, column 'sigma_arcsec'"),
        (HEAD + ",dir1\n0,0,1,1,1,1\n0,30,1,1,1,0\n", "row 3, column 'dir1': an approach"),
        (HEAD + ",time_s\n0,0,1,1,1,-5\n", "row 2, column 'time_s'"),
        (HEAD + "\n0,0,1,1,1\n0,30,1,1,1\n0,0,2,2,2\n", "row 4, column 'phi1_deg': the same"),
        (HEAD + ",time_s\n0,0,1,1,1,10\n0,0,1,1,1,10\n", "row 3, column 'phi1_deg'"),
    ],
)  # fmt: skip
def test_bad_files_name_row_and_column(tmp_path, text, fragment):
    with pytest.raises(InputError) as info:
        read_measurements(write_file(tmp_path, text, "m.csv"))
    assert fragment in str(info.value)
    assert "m.csv" in str(info.value)


def test_repeats_at_different_times_or_directions_are_fine(tmp_path):
    text = HEAD + ",time_s\n0,0,1,1,1,10\n0,0,1.2,1,1,20\n"
    assert read_measurements(write_file(tmp_path, text)).n_positions == 2
    text = HEAD + ",dir1\n0,0,1,1,1,1\n0,0,1.2,1,1,-1\n"
    assert read_measurements(write_file(tmp_path, text)).n_positions == 2


def test_radians_in_a_degree_column_are_refused(tmp_path):
    # A 30-degree schedule written in radians: every value is a whole degree when read as rad.
    lines = [HEAD]
    for a in range(0, 360, 90):
        for b in range(0, 360, 30):
            lines.append(f"{float(np.radians(a))!r},{float(np.radians(b))!r},1,1,1")
    with pytest.raises(
        InputError, match="row 2, column 'phi1_deg': these angles look like radians"
    ):
        read_measurements(write_file(tmp_path, "\n".join(lines) + "\n"))
    # Irregular values spread over a radian-sized range.
    rng = np.random.default_rng(3)
    lines = [HEAD] + [f"{a},{b},1,1,1" for a, b in rng.uniform(0, 2 * np.pi, (20, 2))]
    with pytest.raises(InputError, match="look like radians"):
        read_measurements(write_file(tmp_path, "\n".join(lines) + "\n"))


def test_small_angle_degree_data_are_not_mistaken_for_radians(tmp_path):
    lines = [HEAD]
    for a in (-3, -1.5, 0, 1.5, 3):
        for b in (-2.25, 0, 2.25, 4.5):
            lines.append(f"{a},{b},1,1,1")
    data = read_measurements(write_file(tmp_path, "\n".join(lines) + "\n"))
    assert data.n_positions == 20
    # A whole-degree grid is never flagged.
    assert read_measurements(write_file(tmp_path, HEAD + "\n" + grid_rows())).n_positions == 9


# ---- tables other than the paper's, empty cells, per-angle sigma, extra columns ----------------
def test_joint_angle_columns_by_position_or_joint_name(tmp_path):
    joints = ("azimuth", "elevation")
    by_k = "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n10,20,1,2,3\n"
    by_name = "elevation_deg,azimuth_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n20,10,1,2,3\n"
    for text in (by_k, by_name):
        data = read_measurements(write_file(tmp_path, text), joints)
        np.testing.assert_allclose(np.degrees(data.joint_rad), [[10, 20]])
    both = (
        "phi1_deg,azimuth_deg,elevation_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n1,1,2,1,2,3\n"
    )
    with pytest.raises(InputError, match="joint 1 has two angle columns"):
        read_measurements(write_file(tmp_path, both), joints)
    with pytest.raises(InputError, match="'phi2_deg' or 'elevation_deg'"):
        read_measurements(write_file(tmp_path, "phi1_deg,dpsi_arcsec,dtheta_arcsec,"
                                               "dgamma_arcsec\n1,1,2,3\n"), joints)  # fmt: skip
    one = read_measurements(
        write_file(tmp_path, "phi1_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,dir1\n5,1,2,3,-1\n"),
        ("spindle",),
    )
    # Data of a table with more joints, read with the wrong URDF: refused, not kept as an extra
    # column that the structure search would then take for a suspect.
    with pytest.raises(InputError, match="phi2_deg is the angle of a joint this table does not"):
        read_measurements(write_file(tmp_path, by_k), ("spindle",))
    with pytest.raises(InputError, match="it has 2 joint"):
        three = "phi1_deg,phi2_deg,phi3_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n1,2,3,1,2,3\n"
        read_measurements(write_file(tmp_path, three))
    assert one.n_joints == 1 and one.dirs[0].tolist() == [-1.0]


def test_an_empty_angle_cell_is_not_measured_and_a_row_needs_one_angle(tmp_path):
    text = "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec\n0,0,1,,3\n0,30,,,6\n"
    data = read_measurements(write_file(tmp_path, text))
    assert data.measured.tolist() == [[True, False, True], [False, False, True]]
    bad = text + "0,60,,,\n"
    with pytest.raises(InputError, match=r"row 4.*at least one measured angle"):
        read_measurements(write_file(tmp_path, bad))
    with pytest.raises(InputError, match="empty cell"):  # other columns stay strict
        read_measurements(write_file(tmp_path, text.replace("0,30,", ",30,")))


def test_sigma_per_angle_and_extra_numeric_columns(tmp_path):
    text = (
        "phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec,sigma_dpsi_arcsec,"
        "sigma_dtheta_arcsec,sigma_dgamma_arcsec,temperature_c,operator\n"
        "0,0,1,2,3,0.5,1,2,21.5,ann\n0,30,1,2,3,0.5,1,2,22.0,bob\n"
    )
    data = read_measurements(write_file(tmp_path, text))
    np.testing.assert_allclose(data.sigma_rad[0] * 206264.80624709636, [0.5, 1, 2])
    assert list(data.extra) == ["temperature_c"]  # text columns are not suspects
    np.testing.assert_allclose(data.extra["temperature_c"], [21.5, 22.0])
    with pytest.raises(InputError, match="not both"):
        read_measurements(write_file(tmp_path, text.replace("sigma_dpsi_arcsec", "sigma_arcsec")))


def test_a_bad_cell_in_a_numeric_extra_column_is_refused_not_dropped(tmp_path):
    """Issue 27: a 'warm' among temperatures used to drop the column (and the diagnosis said
    it was absent); it is a numeric column with a bad cell, refused naming row and column."""
    temperature = lambda i: ",warm" if i == 4 else f",{20 + i / 4}"  # noqa: E731
    text = HEAD + ",temperature_c\n" + grid_rows(temperature)
    with pytest.raises(InputError) as info:
        read_measurements(write_file(tmp_path, text))
    assert "row 6, column 'temperature_c': 'warm' is not a number" in str(info.value)


def test_a_text_column_is_ignored_and_named_and_an_effect_on_it_is_told_so(tmp_path):
    from turntable_pin.measurement.effect_model import OrientationModel
    from turntable_pin.measurement.user_effects import resolve_effects

    text = HEAD + ",temperature_c,note\n" + grid_rows(lambda i: ",n/a,ok" if i else ",21,ok")
    data = read_measurements(write_file(tmp_path, text))
    assert data.extra == {} and data.ignored_columns == ("temperature_c", "note")
    assert data.without_sigma().ignored_columns == ("temperature_c", "note")  # copies keep it
    with pytest.raises(InputError) as info:
        OrientationModel(data.variables(), resolve_effects(["dpsi~poly1(temperature_c)"]))
    message = str(info.value)
    assert "temperature_c, present in the data but not numbers" in message
    assert "absent" not in message


def test_the_python_api_refuses_nan_where_the_reader_would():
    from turntable_pin.measurement.data import OrientationMeasurements

    joints = np.zeros((3, 2))
    angles = np.zeros((3, 3))
    angles[1, 2] = np.nan  # not measured: fine
    OrientationMeasurements(joints, angles)
    bad = joints.copy()
    bad[2, 1] = np.nan
    with pytest.raises(InputError, match=r"joint_rad: expected finite.*row 4"):
        OrientationMeasurements(bad, angles)
    with pytest.raises(InputError, match="sigma_rad"):
        OrientationMeasurements(joints, angles, sigma_rad=np.array([1e-6, np.nan, 1e-6]))
    with pytest.raises(InputError, match="time_s"):
        OrientationMeasurements(joints, angles, time_s=np.array([0.0, np.inf, 1.0]))
    with pytest.raises(InputError, match="dir2"):
        OrientationMeasurements(joints, angles, dirs=(None, np.array([1.0, 0.0, -1.0])))
