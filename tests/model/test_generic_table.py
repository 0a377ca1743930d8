"""The generic error model of any URDF table: exact against finite differences and an independent
numpy chain, Pinocchio and the written URDF agree, the paper's nine errors map onto it, and bad
URDFs are refused with one line naming the problem."""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import PAPER_TO_GENERIC, REPO_DIR, random_errors
from rounding import chain_rounding, error_factors
from spec_reference import Rx, Ry, Rz
from turntable_pin.core.exceptions import ModelError
from turntable_pin.model.generic_table import GenericTable, perpendicular_directions
from turntable_pin.model.paper_table import paper_table

PAPER_URDF = REPO_DIR / "models" / "turntable.urdf"

# A three-axis table: outer azimuth about z, middle about y (0.3 m up, tilted origin), inner
# about x, a mount with a rotation, and the payload. Joint names are free.
THREE_AXIS = """<?xml version="1.0"?>
<robot name="three_axis">
  <link name="ground"/><link name="ring_a"/><link name="ring_b"/><link name="ring_c"/>
  <link name="sensor"/>
  <joint name="az" type="continuous">
    <parent link="ground"/><child link="ring_a"/><origin xyz="0 0 0.1" rpy="0 0 0"/>
    <axis xyz="0 0 1"/>
  </joint>
  <joint name="pitch" type="revolute">
    <parent link="ring_a"/><child link="ring_b"/><origin xyz="0 0 0.3" rpy="0.02 0 -0.01"/>
    <axis xyz="0 1 0"/><limit lower="-7" upper="7" effort="1" velocity="1"/>
  </joint>
  <joint name="roll" type="revolute">
    <parent link="ring_b"/><child link="ring_c"/><origin xyz="0.01 0 0" rpy="0 0.03 0"/>
    <axis xyz="1 0 0"/><limit lower="-7" upper="7" effort="1" velocity="1"/>
  </joint>
  <joint name="sensor_mount" type="fixed">
    <parent link="ring_c"/><child link="sensor"/><origin xyz="0 0 0.02" rpy="0.1 0.2 0.3"/>
  </joint>
</robot>
"""


def _rpy(r, p, y):
    return Rz(y) @ Ry(p) @ Rx(r)


@pytest.fixture(scope="module")
def three_axis(tmp_path_factory):
    path = tmp_path_factory.mktemp("urdf") / "three_axis.urdf"
    path.write_text(THREE_AXIS)
    return GenericTable(path)


def independent_three_axis_dR(e: dict, az, pitch, roll):
    """The stated rule applied by hand: z-axis -> u = x, v = y; y-axis -> u = x, v = -z;
    x-axis -> u = y, v = z."""
    g = lambda n: e.get(n, 0.0)  # noqa: E731
    rt = (
        Rz(g("az.position")) @ Rx(g("az.tilt_a")) @ Ry(g("az.tilt_b")) @ Rz(az)
        @ _rpy(0.02, 0, -0.01) @ Ry(g("pitch.position")) @ Rx(g("pitch.tilt_a"))
        @ Rz(-g("pitch.tilt_b")) @ Ry(pitch)
        @ _rpy(0, 0.03, 0) @ Rx(g("roll.position")) @ Ry(g("roll.tilt_a"))
        @ Rz(g("roll.tilt_b")) @ Rx(roll)
        @ _rpy(0.1, 0.2, 0.3) @ Rx(g("sensor_mount.rot_x")) @ Ry(g("sensor_mount.rot_y"))
        @ Rz(g("sensor_mount.rot_z"))
    )  # fmt: skip
    rd = (
        Rz(az)
        @ _rpy(0.02, 0, -0.01)
        @ Ry(pitch)
        @ _rpy(0, 0.03, 0)
        @ Rx(roll)
        @ _rpy(0.1, 0.2, 0.3)
    )
    return rd.T @ rt


def test_names_follow_the_joints_and_the_rule(three_axis):
    assert three_axis.joint_names == ("az", "pitch", "roll")
    assert three_axis.payload_frame == "sensor" and three_axis.mount == "sensor_mount"
    assert three_axis.parameter_names[:5] == (
        "az.position", "az.tilt_a", "az.tilt_b", "az.offset_a", "az.offset_b",
    )  # fmt: skip
    assert three_axis.parameter_names[-3:] == (
        "sensor_mount.rot_x", "sensor_mount.rot_y", "sensor_mount.rot_z",
    )  # fmt: skip


@pytest.mark.parametrize(
    "axis, u, v",
    [((0, 0, 1), (1, 0, 0), (0, 1, 0)), ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
     ((1, 0, 0), (0, 1, 0), (0, 0, 1))],
)  # fmt: skip
def test_perpendicular_directions_of_the_coordinate_axes(axis, u, v):
    got_u, got_v = perpendicular_directions(axis)
    np.testing.assert_allclose(got_u, u, atol=1e-15)
    np.testing.assert_allclose(got_v, v, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(-1e-2, 1e-2), min_size=12, max_size=12),
       st.lists(st.floats(-2 * np.pi, 2 * np.pi), min_size=3, max_size=3))  # fmt: skip
def test_three_axis_chain_equals_an_independent_numpy_chain(three_axis, rotations, angles):
    rot_names = [n for n in three_axis.parameter_names if ".offset" not in n]
    errors = dict(zip(rot_names, rotations, strict=True))
    values = three_axis.values(errors)
    expected = independent_three_axis_dR(errors, *angles)
    np.testing.assert_allclose(three_axis.rotation_error(values, angles), expected, atol=1e-12)
    # Pinocchio with the errors in its placements agrees
    model = three_axis.pinocchio_model(values)
    nominal = three_axis.nominal_pin_model
    q = three_axis.chain.joint_vector(*angles)
    frame = model.getFrameId("sensor")
    rotations_pin = []
    for m in (model, nominal):
        data = m.createData()
        pin.framesForwardKinematics(m, data, q)
        rotations_pin.append(data.oMf[frame].rotation)
    np.testing.assert_allclose(rotations_pin[1].T @ rotations_pin[0], expected, atol=1e-12)


def test_regressor_equals_finite_differences(three_axis, rng):
    angles = [rng.uniform(-np.pi, np.pi, 6) for _ in range(3)]
    jac = three_axis.regressor(angles)
    h = 1e-7
    # dR's rounding over h, and the truncation h^2 |f3| / 6
    # (f3, a third derivative of unit-size rotation entries, is at most 1).
    fd_tolerance = chain_rounding(error_factors(three_axis)) / h + h**2 / 6
    for k in range(len(three_axis.parameter_names)):
        e = np.zeros(len(three_axis.parameter_names))
        e[k] = h
        diff = three_axis.rotation_error(e, angles) - three_axis.rotation_error(-e, angles)
        fd = np.stack([diff[:, 0, 2], diff[:, 1, 0], diff[:, 2, 1]], axis=1) / (2 * h)
        np.testing.assert_allclose(jac[:, :, k], fd, rtol=0, atol=fd_tolerance)


def test_written_urdf_reproduces_the_errors_in_plain_pinocchio(three_axis, tmp_path, rng):
    values = three_axis.values({n: rng.uniform(-1e-3, 1e-3) for n in three_axis.parameter_names})
    written = three_axis.write_urdf(values, tmp_path / "fitted.urdf")
    plain = pin.buildModelFromUrdf(str(written))
    nominal = three_axis.nominal_pin_model
    for angles in rng.uniform(-np.pi, np.pi, size=(4, 3)):
        q = three_axis.chain.joint_vector(*angles)
        poses = []
        for m in (plain, nominal):
            data = m.createData()
            pin.framesForwardKinematics(m, data, q)
            poses.append(data.oMf[m.getFrameId("sensor")])
        np.testing.assert_allclose(
            poses[1].rotation.T @ poses[0].rotation,
            three_axis.rotation_error(values, angles),
            atol=1e-12,
        )


def test_paper_errors_map_onto_the_generic_parameters(rng):
    """The paper's nine errors are the generic model under other names (to first order; exactly
    for the position errors, which sit where the generic ones do)."""
    generic = GenericTable(PAPER_URDF)
    mapping = PAPER_TO_GENERIC
    for paper_name in ("dphi_y1", "dalpha_z1"):
        errors = random_errors(rng).__class__.from_arcsec(**{paper_name: 30.0})
        values = generic.values({mapping[paper_name]: getattr(errors, paper_name)})
        for angles in rng.uniform(-np.pi, np.pi, size=(3, 2)):
            np.testing.assert_allclose(
                generic.rotation_error(values, angles),
                paper_table().orientation_error(errors.as_array(), angles).dR,
                atol=1e-15,
            )
    errors = random_errors(rng, 20.0)
    generic_values = {}
    for paper_name, name in mapping.items():
        generic_values[name] = generic_values.get(name, 0.0) + getattr(errors, paper_name)
    values = generic.values(generic_values)
    size = np.abs(errors.angular_array_rad()).max()
    for angles in rng.uniform(-np.pi, np.pi, size=(5, 2)):
        exact = paper_table().orientation_error(errors.as_array(), angles).dR
        gap = generic.rotation_error(values, angles) - exact
        assert np.abs(gap).max() <= 10 * size**2


def test_what_orientation_data_determine_on_the_paper_table():
    ident = GenericTable(PAPER_URDF).identifiable
    assert set(ident.combinations) == {
        "outer_axis.position + inner_axis.tilt_b",
        "outer_axis.tilt_a",
        "outer_axis.tilt_b",
        "inner_axis.position + payload_mount.rot_z",
        "inner_axis.tilt_a",
        "payload_mount.rot_x",
        "payload_mount.rot_y",
    }
    assert len(ident.base) == 7
    assert set(ident.no_effect) == {
        "outer_axis.offset_a", "outer_axis.offset_b", "inner_axis.offset_a", "inner_axis.offset_b",
    }  # fmt: skip


def test_three_axis_table_determines_fewer_than_its_parameters(three_axis):
    ident = three_axis.identifiable
    rotations = [n for n in three_axis.parameter_names if ".offset" not in n]
    assert len(ident.base) == len(ident.combinations) < len(rotations)
    assert len(ident.base) + len(ident.undetermined) == len(rotations)


BAD = {
    "mimic": ('<joint name="b" type="revolute"><parent link="l1"/><child link="l2"/>'
              '<axis xyz="0 0 1"/><mimic joint="a"/>'
              '<limit lower="-1" upper="1" effort="1" velocity="1"/></joint>', "mimic joint"),
    "prismatic": ('<joint name="b" type="prismatic"><parent link="l1"/><child link="l2"/>'
                  '<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>'
                  '</joint>', "is prismatic"),
    "floating": ('<joint name="b" type="floating"><parent link="l1"/><child link="l2"/></joint>',
                 "is floating"),
}  # fmt: skip


def _urdf(tmp_path, second_joint: str, extra_links: str = "") -> str:
    text = (
        '<?xml version="1.0"?><robot name="bad"><link name="l0"/><link name="l1"/>'
        f'<link name="l2"/>{extra_links}'
        '<joint name="a" type="continuous"><parent link="l0"/><child link="l1"/>'
        f'<axis xyz="0 0 1"/></joint>{second_joint}</robot>'
    )
    path = tmp_path / "bad.urdf"
    path.write_text(text)
    return path


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_joint_kinds_are_refused(tmp_path, case):
    joint, fragment = BAD[case]
    with pytest.raises(ModelError, match=fragment):
        GenericTable(_urdf(tmp_path, joint))


def test_more_than_three_axes_is_refused(tmp_path):
    joints = "".join(
        f'<joint name="j{i}" type="continuous"><parent link="l{i}"/><child link="l{i + 1}"/>'
        '<axis xyz="0 0 1"/></joint>'
        for i in range(1, 4)
    )
    links = "".join(f'<link name="l{i}"/>' for i in range(3, 5))
    with pytest.raises(ModelError, match="4 revolute joints on the chain"):
        GenericTable(_urdf(tmp_path, joints, links))


def test_a_branch_makes_the_payload_ambiguous_or_not_serial(tmp_path):
    branch = (
        '<joint name="b" type="continuous"><parent link="l0"/><child link="l2"/>'
        '<axis xyz="1 0 0"/></joint>'
    )
    path = _urdf(tmp_path, branch)
    with pytest.raises(ModelError, match="payload frame is ambiguous"):
        GenericTable(path)
    with pytest.raises(ModelError, match="not a serial chain to 'l1'"):
        GenericTable(path, payload_frame="l1")


def test_a_missing_payload_frame_and_bad_xml_are_named(tmp_path):
    fixed = '<joint name="m" type="fixed"><parent link="l1"/><child link="l2"/></joint>'
    with pytest.raises(ModelError, match="no frame 'nowhere'"):
        GenericTable(_urdf(tmp_path, fixed), payload_frame="nowhere")
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot><link name='a'>")
    with pytest.raises(ModelError, match="not a readable URDF"):
        GenericTable(broken)


def test_a_single_axis_table_has_position_and_tilts(tmp_path):
    fixed = '<joint name="m" type="fixed"><parent link="l1"/><child link="l2"/></joint>'
    table = GenericTable(_urdf(tmp_path, fixed))
    assert table.joint_names == ("a",) and table.payload_frame == "l2" and table.mount == "m"
    ident = table.identifiable
    assert "a.tilt_a" in ident.combinations and "a.tilt_b" in ident.combinations
    assert "a.position + m.rot_z" in ident.combinations


def _single_axis(tmp_path):
    fixed = '<joint name="m" type="fixed"><parent link="l1"/><child link="l2"/></joint>'
    return GenericTable(_urdf(tmp_path, fixed))


@pytest.mark.parametrize("table_name", ["single", "paper", "three"])
def test_batch_field_equals_the_chain_for_one_two_and_three_axes(
    table_name, three_axis, tmp_path, rng
):
    from turntable_pin import OrientationErrorField

    table = {"single": lambda: _single_axis(tmp_path), "paper": lambda: GenericTable(PAPER_URDF),
             "three": lambda: three_axis}[table_name]()  # fmt: skip
    sets = rng.uniform(-2e-3, 2e-3, size=(3, len(table.parameter_names)))
    field = OrientationErrorField.from_chain(table.chain, sets)
    angles = [rng.uniform(-4, 4, 50) for _ in table.joint_names]
    got = field.rotation(*angles)
    for k in range(3):
        np.testing.assert_allclose(got[k], table.rotation_error(sets[k], angles), atol=1e-12)
    np.testing.assert_allclose(field.angles(*angles)[:, :, 0], got[:, :, 0, 2], atol=0, rtol=0)
