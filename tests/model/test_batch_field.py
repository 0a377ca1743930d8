"""The batch path equals per-call Pinocchio forward kinematics and the chain composed at each
angle to 1e-12 rad, on one-, two- and three-axis tables, anywhere and over full grids."""

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import REPO_DIR, random_errors
from turntable_pin import OrientationErrorField
from turntable_pin.model import batch_field
from turntable_pin.model.angles import ANGLE_ENTRIES
from turntable_pin.model.batch_field import (
    ChainExpansion,
    joint_dependence,
    max_abs_on_grid,
    trig_basis,
)
from turntable_pin.model.paper_table import paper_table


def test_batch_equals_per_call_pinocchio(rng):
    for scale in (10.0, 3000.0):
        table, values = paper_table(), random_errors(rng, scale_arcsec=scale).as_array()
        field = OrientationErrorField.from_chain(table.chain, values[None])
        phi1, phi2 = rng.uniform(-20, 20, size=(2, 500))
        per_call = np.array(
            [table.orientation_error(values, (a, b)).dR for a, b in zip(phi1, phi2, strict=True)]
        )
        np.testing.assert_allclose(field.rotation(phi1, phi2)[0], per_call, atol=1e-12, rtol=0)
        angles = field.angles(phi1, phi2)[0]
        np.testing.assert_allclose(angles, per_call[:, [0, 1, 2], [2, 0, 1]], atol=1e-12, rtol=0)


def test_many_error_sets_equal_their_own_models(rng):
    sets = [random_errors(rng, scale_arcsec=100.0) for _ in range(6)]
    values = np.array([e.as_array() for e in sets])
    table = paper_table()
    field = OrientationErrorField.from_chain(table.chain, values)
    phi1, phi2 = rng.uniform(-7, 7, size=(2, 40))
    angles = field.angles(phi1, phi2)
    grid = np.linspace(0, 2 * np.pi, 17)
    on_grid = field.angles(0.7, grid).transpose(0, 2, 1)
    for k in range(len(sets)):
        np.testing.assert_allclose(
            field.coefficients[k],
            OrientationErrorField.from_chain(table.chain, values[k : k + 1]).coefficients[0],
            atol=1e-15,
        )
        for n in range(phi1.size):
            r = table.orientation_error(values[k], (phi1[n], phi2[n]))
            np.testing.assert_allclose(
                angles[k, n], [r.dpsi_rad, r.dtheta_rad, r.dgamma_rad], atol=1e-12, rtol=0
            )
        r = table.orientation_error(values[k], (0.7, grid[5]))
        np.testing.assert_allclose(
            on_grid[k, :, 5], [r.dpsi_rad, r.dtheta_rad, r.dgamma_rad], atol=1e-12
        )


def test_trig_basis_matches_numpy(rng):
    a = np.concatenate([rng.uniform(-100, 100, 1000), [0.0, np.pi, -np.pi, np.pi / 2, 2 * np.pi]])
    u = trig_basis(a)
    expected = np.stack([np.ones_like(a), np.cos(a), np.sin(a), np.cos(2 * a), np.sin(2 * a)], -1)
    np.testing.assert_allclose(u, expected, atol=2e-15, rtol=0)
    assert trig_basis(0.5).shape == (5,)


def test_broadcast_and_shapes(rng):
    field = OrientationErrorField.from_chain(
        paper_table().chain, random_errors(rng).as_array()[None]
    )
    out = field.angles(0.3, np.linspace(0, 1, 7))
    assert out.shape == (1, 7, 3)
    with pytest.raises(ValueError):
        field.angles(np.zeros(3), np.zeros(4))


# ---- the Rodrigues expansion on any table -------------------------------------------------------

# Two joints with unaligned axes and tilted origins: no factor or joint about a coordinate axis.
UNALIGNED = """<?xml version="1.0"?>
<robot name="unaligned">
  <link name="base"/><link name="a"/><link name="b"/><link name="payload"/>
  <joint name="j1" type="continuous">
    <parent link="base"/><child link="a"/><origin xyz="0 0 0.2" rpy="0.1 -0.2 0.3"/>
    <axis xyz="0.6 0 0.8"/>
  </joint>
  <joint name="j2" type="revolute">
    <parent link="a"/><child link="b"/><origin xyz="0.05 0 0.1" rpy="-0.3 0.1 0.2"/>
    <axis xyz="0.2 0.9 -0.3"/><limit lower="-9" upper="9" effort="1" velocity="1"/>
  </joint>
  <joint name="mount" type="fixed">
    <parent link="b"/><child link="payload"/><origin xyz="0 0 0.02" rpy="0.4 0.5 0.6"/>
  </joint>
</robot>
"""
BUNDLED = (
    "single_axis_rate_table.urdf",
    "turntable.urdf",
    "two_axis_vertical_outer.urdf",
    "german_equatorial_mount.urdf",
    "three_axis_imu_table.urdf",
)


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    from turntable_pin.model.generic_table import GenericTable

    path = tmp_path_factory.mktemp("urdf") / "unaligned.urdf"
    path.write_text(UNALIGNED)
    out = {name: GenericTable(REPO_DIR / "models" / name) for name in BUNDLED}
    out["unaligned"] = GenericTable(path)
    return out


def _angle_entries(d_r: np.ndarray) -> np.ndarray:
    return np.stack([d_r[..., i, j] for i, j in ANGLE_ENTRIES], axis=-1)


@settings(max_examples=30, deadline=None)
@given(
    name=st.sampled_from([*BUNDLED, "unaligned"]),
    scale_rad=st.sampled_from([1e-6, 1e-4, 1e-2, 0.3]),
    seed=st.integers(0, 2**32 - 1),
)
def test_expansion_equals_the_exact_chain_on_one_two_and_three_axes(tables, name, scale_rad, seed):
    """Coefficients from per-table 3x3 products and the nominal operator, evaluated anywhere,
    equal the chain composed at each angle (``compose_rotation``) to 1e-12."""
    table = tables[name]
    rng = np.random.default_rng(seed)
    sets = rng.uniform(-scale_rad, scale_rad, (4, len(table.parameter_names)))
    angles = [rng.uniform(-7.0, 7.0, 60) for _ in table.joint_names]
    field = OrientationErrorField.from_chain(table.chain, sets)
    exact = np.stack([table.rotation_error(values, angles) for values in sets])
    np.testing.assert_allclose(field.rotation(*angles), exact, atol=1e-12, rtol=0)
    np.testing.assert_allclose(field.angles(*angles), _angle_entries(exact), atol=1e-12, rtol=0)
    selected = ChainExpansion(table.chain).coefficients(sets)  # dpsi, dtheta, dgamma only
    np.testing.assert_array_equal(selected, field._angle_coefficients.reshape(selected.shape))


@pytest.mark.parametrize("name", ["single_axis_rate_table.urdf", "three_axis_imu_table.urdf"])
def test_expansion_equals_pinocchio_forward_kinematics(tables, name, rng):
    table = tables[name]
    values = rng.uniform(-1e-3, 1e-3, len(table.parameter_names))
    model, nominal = table.pinocchio_model(values), table.nominal_pin_model
    data, nominal_data = model.createData(), nominal.createData()
    frame = model.getFrameId(table.payload_frame)
    field = OrientationErrorField.from_chain(table.chain, values[None])
    for _ in range(20):
        angles = rng.uniform(-4.0, 4.0, len(table.joint_names))
        q = table.chain.joint_vector(*angles)
        pin.framesForwardKinematics(model, data, q)
        pin.framesForwardKinematics(nominal, nominal_data, q)
        expected = nominal_data.oMf[frame].rotation.T @ data.oMf[frame].rotation
        np.testing.assert_allclose(field.rotation(*angles)[0, 0], expected, atol=1e-12, rtol=0)


@pytest.mark.parametrize("name", [*BUNDLED, "unaligned"])
@pytest.mark.parametrize("block_bytes", [1, 1 << 30])
def test_largest_angles_over_a_grid_equal_the_exact_chain_at_every_point(
    tables, name, block_bytes, rng, monkeypatch
):
    """One joint at a time, in blocks of one set or all of them; a joint given one angle is
    folded in; grids of different, odd sizes."""
    monkeypatch.setattr(batch_field, "_GRID_BLOCK_BYTES", block_bytes)
    table = tables[name]
    sets = rng.uniform(-2e-3, 2e-3, (5, len(table.parameter_names)))
    steps = (40.0, 45.0, 72.0)[: len(table.joint_names)]
    grids = [np.radians(np.arange(0.0, 360.0, s)) + 0.1 * i for i, s in enumerate(steps)]
    for chosen in (grids, [np.array([0.7]), *grids[1:]]):
        mesh = [m.ravel() for m in np.meshgrid(*chosen, indexing="ij")]
        exact = np.stack([table.rotation_error(values, mesh) for values in sets])
        expected = np.abs(_angle_entries(exact)).max(axis=1)
        largest = max_abs_on_grid(ChainExpansion(table.chain).coefficients(sets), chosen)
        np.testing.assert_allclose(largest, expected, atol=1e-12, rtol=0)


def test_the_paper_tables_outer_angle_drops_out_and_no_generic_joint_does(tables, rng):
    """With the errors of Table 2 dR does not depend on phi1: its harmonics are zero."""
    paper = paper_table().chain
    values = np.append(rng.uniform(-1e-3, 1e-3, (50, 8)), np.zeros((50, 1)), axis=1)
    dependence = joint_dependence(ChainExpansion(paper).coefficients(values), 2)
    assert dependence[0] < 1e-15
    assert dependence[1] > 1e-6
    table = tables["three_axis_imu_table.urdf"]
    values = rng.uniform(-1e-3, 1e-3, (50, len(table.parameter_names)))
    assert np.all(joint_dependence(ChainExpansion(table.chain).coefficients(values), 3) > 1e-6)
