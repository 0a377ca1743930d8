"""The error chain read off a URDF: against an independent numpy chain, and the same object behind
Pinocchio evaluation, the batch field, the measurement fit and the sensitivities."""

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from allocation_reference import sensitivity_matrix_fd
from conftest import random_errors
from turntable_pin import OrientationErrorField, TurntableErrors
from turntable_pin.allocation.sensitivity import sensitivity_matrix
from turntable_pin.calibration.positions import PositionSet
from turntable_pin.core.exceptions import ModelError
from turntable_pin.measurement.effect_model import OrientationModel
from turntable_pin.measurement.effects.base import PositionVariables
from turntable_pin.model.chain import ErrorChain
from turntable_pin.model.errors import ERROR_NAMES
from turntable_pin.model.paper_table import PLACEMENT_ERROR_FACTORS, paper_table

# A two-axis table whose URDF origins are not the identity: an offset, tilted outer bearing, an
# inner joint placed off the outer axis, and a payload mount with a rotation and an offset, then a
# payload frame further along a second fixed joint. The chain must follow all of it.
OFFSET_URDF = """<?xml version="1.0"?>
<robot name="offset_table">
  <link name="base"/>
  <link name="outer_frame"/>
  <link name="inner_frame"/>
  <link name="mount_plate"/>
  <link name="gyrowheel"/>
  <joint name="outer_axis" type="revolute">
    <parent link="base"/><child link="outer_frame"/>
    <origin xyz="0.1 -0.2 0.3" rpy="0.01 -0.02 0.03"/>
    <axis xyz="0 1 0"/><limit lower="-7" upper="7" effort="1" velocity="1"/>
  </joint>
  <joint name="inner_axis" type="revolute">
    <parent link="outer_frame"/><child link="inner_frame"/>
    <origin xyz="0.0 0.05 -0.04" rpy="-0.02 0.01 0.2"/>
    <axis xyz="0 0 1"/><limit lower="-7" upper="7" effort="1" velocity="1"/>
  </joint>
  <joint name="payload_mount" type="fixed">
    <parent link="inner_frame"/><child link="mount_plate"/>
    <origin xyz="0.02 0 0.03" rpy="0.3 0.0 -0.1"/>
  </joint>
  <joint name="sensor_offset" type="fixed">
    <parent link="mount_plate"/><child link="gyrowheel"/>
    <origin xyz="0 0.01 0.02" rpy="0 0.2 0"/>
  </joint>
</robot>
"""


def _rot(axis, a):
    c, s = np.cos(a), np.sin(a)
    i = "xyz".index(axis)
    r = np.eye(3)
    j, k = (i + 1) % 3, (i + 2) % 3
    r[j, j] = r[k, k] = c
    r[j, k], r[k, j] = -s, s
    return r


def _rpy(r, p, y):
    return _rot("z", y) @ _rot("y", p) @ _rot("x", r)


def independent_dR(e: TurntableErrors, phi1, phi2):
    """The offset table's dR written out from the URDF text above and paper Table 3."""
    outer = _rpy(0.01, -0.02, 0.03)
    inner = _rpy(-0.02, 0.01, 0.2)
    mount = _rpy(0.3, 0.0, -0.1)
    sensor = _rpy(0.0, 0.2, 0.0)
    rt = (
        outer @ _rot("y", e.dphi_y1) @ _rot("y", phi1)
        @ inner @ _rot("z", e.dalpha_z1) @ _rot("x", e.dalpha_x1) @ _rot("y", e.deps_y)
        @ _rot("x", e.deps_x) @ _rot("z", phi2)
        @ mount @ _rot("y", e.dalpha_y2) @ _rot("z", e.dphi_z2) @ _rot("x", e.dalpha_x2)
        @ sensor
    )  # fmt: skip
    rd = outer @ _rot("y", phi1) @ inner @ _rot("z", phi2) @ mount @ sensor
    return rd.T @ rt


@pytest.fixture(scope="module")
def offset_urdf(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("urdf") / "offset_table.urdf"
    path.write_text(OFFSET_URDF)
    return path


def test_chain_links_follow_the_urdf(offset_urdf):
    chain = paper_table(offset_urdf).chain
    assert [link.name for link in chain.links] == [
        "outer_axis", "inner_axis", "payload_mount", "sensor_offset", "gyrowheel",
    ]  # fmt: skip
    assert chain.joint_names == ("outer_axis", "inner_axis")
    np.testing.assert_allclose(
        chain.link("payload_mount").nominal[:3, 3], [0.02, 0, 0.03], atol=1e-15
    )
    np.testing.assert_allclose(
        chain.link("sensor_offset").nominal[:3, 3], [0, 0.01, 0.02], atol=1e-15
    )
    np.testing.assert_allclose(chain.link("gyrowheel").nominal, np.eye(4), atol=1e-15)
    assert [f.error for f in chain.link("inner_axis").factors] == [
        f[2] for f in PLACEMENT_ERROR_FACTORS["inner_axis"]
    ]


@settings(max_examples=40, deadline=None)
@given(
    st.lists(st.floats(-1e-2, 1e-2), min_size=8, max_size=8),
    st.floats(-2 * np.pi, 2 * np.pi),
    st.floats(-2 * np.pi, 2 * np.pi),
)
def test_every_consumer_of_the_chain_equals_an_independent_numpy_chain(
    offset_urdf, chi, phi1, phi2
):
    path = offset_urdf
    errors = TurntableErrors.from_array([*chi, 0.0])
    expected = independent_dR(errors, phi1, phi2)
    table = paper_table(path)
    dR = table.orientation_error(errors.as_array(), (phi1, phi2)).dR
    np.testing.assert_allclose(dR, expected, atol=1e-12)
    field = OrientationErrorField.from_chain(table.chain, errors.as_array()[None])
    np.testing.assert_allclose(field.rotation(phi1, phi2)[0, 0], expected, atol=1e-12)
    fit_model = OrientationModel(
        PositionVariables.of(PositionSet(np.array([phi1]), np.array([phi2]))), (), table
    )
    np.testing.assert_allclose(
        fit_model.rotation_error(errors.angular_array_rad())[0], expected, atol=1e-12
    )


def test_sensitivities_on_the_offset_table_match_finite_differences(offset_urdf, rng):
    table, values = paper_table(offset_urdf), random_errors(rng, 200.0).as_array()
    for phi1, phi2 in rng.uniform(-np.pi, np.pi, size=(4, 2)):
        np.testing.assert_allclose(
            sensitivity_matrix(values, phi1, phi2, table),
            sensitivity_matrix_fd(table, values, phi1, phi2),
            atol=1e-8,
        )


def test_written_urdf_reproduces_the_chain_in_plain_pinocchio(offset_urdf, tmp_path, rng):
    errors = random_errors(rng, 50.0)
    table = paper_table(offset_urdf)
    written = table.write_urdf(errors.as_array(), tmp_path / "with_errors.urdf")
    plain = pin.buildModelFromUrdf(str(written))
    nominal = pin.buildModelFromUrdf(str(offset_urdf))
    frame = plain.getFrameId("gyrowheel")
    for phi1, phi2 in rng.uniform(-np.pi, np.pi, size=(5, 2)):
        q = table.chain.joint_vector(phi1, phi2)
        rotations = []
        for m in (plain, nominal):
            data = m.createData()
            pin.framesForwardKinematics(m, data, q)
            rotations.append(data.oMf[frame].rotation)
        np.testing.assert_allclose(
            rotations[1].T @ rotations[0], independent_dR(errors, phi1, phi2), atol=1e-12
        )


def test_error_transforms_of_many_sets_equal_one_by_one(rng):
    chain = paper_table().chain
    sets = np.stack([random_errors(rng).as_array() for _ in range(5)])
    many = chain.error_transforms(sets)
    for k in range(5):
        one = chain.error_transforms(sets[k])
        for name in one:
            np.testing.assert_array_equal(many[name][k], one[name])


def test_chain_refuses_factors_off_the_chain_and_unknown_frames():
    nominal = paper_table().nominal_pin_model
    with pytest.raises(ModelError, match="not on the chain"):
        ErrorChain.from_pinocchio(nominal, "gyrowheel", {"no_joint": ()}, ERROR_NAMES)
    with pytest.raises(ModelError, match="no frame 'nowhere'"):
        ErrorChain.from_pinocchio(nominal, "nowhere", PLACEMENT_ERROR_FACTORS, ERROR_NAMES)
    with pytest.raises(ModelError, match="unknown error"):
        ErrorChain.from_pinocchio(
            nominal, "gyrowheel", {"outer_axis": (("rot", "y", "bogus"),)}, ERROR_NAMES
        )
