"""Every joint type x axis: ``revolute`` and ``continuous`` joints about +-x, +-y, +-z and an
oblique axis, alone and in chains mixing them (Pinocchio 4 makes a continuous joint about a
non-coordinate axis a ``JointModelRevoluteUnboundedUnaligned`` without ``.axis``, which crashed
every command). For each: the axis read (``model.chain.joint_axis``) is the URDF's, normalised;
``GenericTable.rotation_error`` equals an independent numpy chain (nominal origins, the error
factors of ``model.generic_table``'s stated rule, the joint rotation) and Pinocchio's forward
kinematics on ``GenericTable.pinocchio_model``; the CLI runs on such a table."""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import cli, write_file
from turntable_pin.model.chain import joint_axis
from turntable_pin.model.generic_table import GenericTable

OBLIQUE = (0.36, -0.48, 0.8)
"""A unit axis that is no coordinate axis (written normalised in the URDF)."""
OBLIQUE_UNNORMALISED = (1.0, -2.0, 0.5)
"""An axis written unnormalised: the URDF's axis is a direction."""
AXES = {"+x": (1, 0, 0), "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0),
        "+z": (0, 0, 1), "-z": (0, 0, -1), "oblique": OBLIQUE,
        "oblique_unnormalised": OBLIQUE_UNNORMALISED}  # fmt: skip
TYPES = ("revolute", "continuous")
MOUNT_RPY = (0.1, -0.2, 0.3)


# ---- the independent chain ----------------------------------------------------------------------
def _unit(v) -> np.ndarray:
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _rot(axis, angle: float) -> np.ndarray:
    """Rodrigues: rotation by ``angle`` (rad) about the unit ``axis``."""
    a = _unit(axis)
    k = np.array([[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k)


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    """URDF's ``rpy``: fixed axes x, y, z, i.e. ``Rz(y) Ry(p) Rx(r)``."""
    return _rot((0, 0, 1), y) @ _rot((0, 1, 0), p) @ _rot((1, 0, 0), r)


def _u_v(axis) -> tuple[np.ndarray, np.ndarray]:
    """The rule of ``model.generic_table`` written again: u the coordinate axis least aligned
    with a (x before y before z on a tie) made perpendicular to it, v = a x u."""
    a = _unit(axis)
    magnitudes = [abs(c) for c in a]
    k = magnitudes.index(min(magnitudes))
    e = np.eye(3)[k]
    u = _unit(e - (e @ a) * a)
    return u, np.cross(a, u)


def independent_dR(joints, mount_rpy, errors: dict, angles) -> np.ndarray:
    """``Rd^T Rt`` of a chain of ``joints`` ``[(name, type, axis, rpy, xyz), ...]`` then the
    mount ``mount_rpy``, with ``errors`` (rad) by name, at ``angles`` (rad)."""
    g = lambda n: errors.get(n, 0.0)  # noqa: E731
    rt, rd = np.eye(3), np.eye(3)
    for (name, _, axis, rpy, _), q in zip(joints, angles, strict=True):
        u, v = _u_v(axis)
        nominal = _rpy(*rpy)
        error = (
            _rot(axis, g(f"{name}.position"))
            @ _rot(u, g(f"{name}.tilt_a"))
            @ _rot(v, g(f"{name}.tilt_b"))
        )
        rt = rt @ nominal @ error @ _rot(axis, q)
        rd = rd @ nominal @ _rot(axis, q)
    m = _rpy(*mount_rpy)
    rt = rt @ m @ _rot((1, 0, 0), g("mount.rot_x")) @ _rot((0, 1, 0), g("mount.rot_y"))
    rt = rt @ _rot((0, 0, 1), g("mount.rot_z"))
    rd = rd @ m
    return rd.T @ rt


# ---- URDFs --------------------------------------------------------------------------------------
def urdf_text(joints, mount_rpy=MOUNT_RPY) -> str:
    """A chain ``base -> l1 -> ... -> payload`` with ``joints`` and the fixed ``mount``."""
    links = ["base"] + [f"l{i}" for i in range(1, len(joints) + 1)] + ["payload"]
    out = ['<?xml version="1.0"?>', '<robot name="chain">']
    out += [f'  <link name="{name}"/>' for name in links]
    for i, (name, kind, axis, rpy, xyz) in enumerate(joints):
        limit = ('<limit lower="-7" upper="7" effort="1" velocity="1"/>'
                 if kind == "revolute" else "")  # fmt: skip
        out.append(
            f'  <joint name="{name}" type="{kind}"><parent link="{links[i]}"/>'
            f'<child link="{links[i + 1]}"/>'
            f'<origin xyz="{" ".join(repr(float(c)) for c in xyz)}" '
            f'rpy="{" ".join(repr(float(c)) for c in rpy)}"/>'
            f'<axis xyz="{" ".join(repr(float(c)) for c in axis)}"/>{limit}</joint>'
        )
    out.append(
        f'  <joint name="mount" type="fixed"><parent link="{links[-2]}"/><child link="payload"/>'
        f'<origin xyz="0 0 0.05" rpy="{" ".join(repr(float(c)) for c in mount_rpy)}"/></joint>'
    )
    out.append("</robot>")
    return "\n".join(out) + "\n"


def _table(folder, joints, mount_rpy=MOUNT_RPY, name="chain.urdf") -> GenericTable:
    return GenericTable(write_file(folder, urdf_text(joints, mount_rpy), name))


def _random_errors(table: GenericTable, rng, scale_rad: float = 2e-3) -> dict:
    """Random values of every error (offsets in metres, irrelevant to the orientation)."""
    return {n: float(rng.uniform(-scale_rad, scale_rad)) for n in table.parameter_names}


def _pinocchio_dR(table: GenericTable, values, angles) -> np.ndarray:
    q = table.chain.joint_vector(*angles)
    rotations = []
    for model in (table.pinocchio_model(values), table.nominal_pin_model):
        data = model.createData()
        pin.framesForwardKinematics(model, data, q)
        rotations.append(data.oMf[model.getFrameId(table.payload_frame)].rotation)
    return rotations[1].T @ rotations[0]


def _check_table(table: GenericTable, joints, mount_rpy, errors: dict, angles) -> None:
    """(a) axes, (b) the independent chain, (c) Pinocchio, to 1e-12."""
    model = table.nominal_pin_model
    for (name, _, axis, _, _), link in zip(joints, table.chain.joints, strict=True):
        np.testing.assert_allclose(link.axis, _unit(axis), atol=1e-12, err_msg=name)
        np.testing.assert_allclose(
            joint_axis(model, model.getJointId(name)), _unit(axis), atol=1e-12, err_msg=name
        )
    values = table.values(errors)
    expected = independent_dR(joints, mount_rpy, errors, angles)
    np.testing.assert_allclose(table.rotation_error(values, angles), expected, atol=1e-12)
    np.testing.assert_allclose(_pinocchio_dR(table, values, angles), expected, atol=1e-12)


# ---- every type x axis, alone and in two-joint chains ------------------------------------------
CASES = [(kind, axis) for kind in TYPES for axis in AXES]


@pytest.mark.parametrize("kind, axis", CASES)
def test_one_joint_of_each_type_and_axis(tmp_path, kind, axis):
    joints = [("j1", kind, AXES[axis], (0.05, -0.1, 0.2), (0.01, 0.02, 0.3))]
    table = _table(tmp_path, joints)
    assert table.joint_names == ("j1",) and table.mount == "mount"
    rng = np.random.default_rng(1)
    for angle in (0.0, 1.0, -2.5, 4.0):
        _check_table(table, joints, MOUNT_RPY, _random_errors(table, rng), [angle])


@pytest.mark.parametrize("kind, axis", CASES)
def test_two_joint_chains_mixing_types_and_axes(tmp_path, kind, axis):
    """Each type x axis as the outer joint with the other type inside (about the oblique axis,
    or +y when the outer one is oblique), and as the inner joint under the other type about z."""
    other = "continuous" if kind == "revolute" else "revolute"
    inner_axis = AXES["+y"] if axis.startswith("oblique") else OBLIQUE
    chains = [
        [("outer", kind, AXES[axis], (0.0, 0.3, 0.0), (0, 0, 0.2)),
         ("inner", other, inner_axis, (0.1, 0.0, -0.2), (0.05, 0, 0.1))],
        [("outer", other, AXES["+z"], (0.0, 0.0, 0.4), (0, 0, 0.2)),
         ("inner", kind, AXES[axis], (-0.3, 0.2, 0.1), (0, 0.05, 0.1))],
    ]  # fmt: skip
    rng = np.random.default_rng(2)
    for k, joints in enumerate(chains):
        table = _table(tmp_path, joints, name=f"chain{k}.urdf")
        assert table.joint_names == ("outer", "inner")
        for _ in range(3):
            angles = rng.uniform(-np.pi, np.pi, 2)
            _check_table(table, joints, MOUNT_RPY, _random_errors(table, rng), angles)


def test_a_continuous_joint_is_unbounded_and_a_revolute_one_is_not(tmp_path):
    joints = [("outer", "continuous", OBLIQUE, (0, 0, 0), (0, 0, 0)),
              ("inner", "revolute", OBLIQUE, (0, 0, 0), (0, 0, 0))]  # fmt: skip
    table = _table(tmp_path, joints)
    outer, inner = table.chain.joints
    assert outer.unbounded and not inner.unbounded
    assert table.nominal_pin_model.joints[1].shortname() == "JointModelRevoluteUnboundedUnaligned"
    assert table.nominal_pin_model.joints[2].shortname() == "JointModelRevoluteUnaligned"


# ---- random mounts ------------------------------------------------------------------------------
# Axis components in steps of 1e-3: the written axis and the one Pinocchio reads (it snaps an
# axis within ~1e-12 of a coordinate axis onto it, and normalises) then have the same ties, so
# the rule's choice of u (first on a tie) is the same for both.
_unit_axes = (
    st.lists(st.integers(-1000, 1000), min_size=3, max_size=3)
    .map(lambda v: [c / 1000.0 for c in v])
    .filter(lambda v: np.linalg.norm(v) > 0.1)
)
_rpys = st.lists(st.floats(-np.pi, np.pi), min_size=3, max_size=3)
_xyzs = st.lists(st.floats(-0.5, 0.5), min_size=3, max_size=3)
_joint = st.tuples(st.sampled_from(TYPES), _unit_axes, _rpys, _xyzs)


@settings(max_examples=60, deadline=None)
@given(
    st.lists(_joint, min_size=1, max_size=3), _rpys, st.integers(0, 2**32 - 1),
)  # fmt: skip
def test_random_mounts_equal_the_independent_chain_and_pinocchio(
    tmp_path_factory, specs, mount_rpy, seed
):
    joints = [(f"j{i}", kind, tuple(_unit(axis)), tuple(rpy), tuple(xyz))
              for i, (kind, axis, rpy, xyz) in enumerate(specs, start=1)]  # fmt: skip
    table = _table(tmp_path_factory.mktemp("mount"), joints, mount_rpy)
    rng = np.random.default_rng(seed)
    angles = rng.uniform(-2 * np.pi, 2 * np.pi, len(joints))
    _check_table(table, joints, mount_rpy, _random_errors(table, rng, 1e-2), angles)


# ---- the commands on a continuous / oblique table ----------------------------------------------
CLI_JOINTS = [
    ("azimuth", "continuous", AXES["-z"], (0.0, 0.0, 0.0), (0, 0, 0.3)),
    ("tilt", "continuous", OBLIQUE, (0.0, 0.2, 0.0), (0, 0, 0.2)),
]


@pytest.fixture(scope="module")
def oblique_urdf(tmp_path_factory):
    return write_file(tmp_path_factory.mktemp("cli"), urdf_text(CLI_JOINTS), "oblique.urdf")


def test_orientation_on_a_continuous_oblique_table(oblique_urdf):
    proc = cli("orientation", "--urdf", str(oblique_urdf), "--angles-deg", "30,-40",
               "--error", "tilt.tilt_a=20", "--error", "azimuth.position=-5", "--json")  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    table = GenericTable(oblique_urdf)
    values = table.errors_from_user_units({"tilt.tilt_a": 20, "azimuth.position": -5})
    expected = table.rotation_error(values, np.radians([30.0, -40.0]))
    np.testing.assert_allclose(out["dR"], expected, atol=1e-15)
    errors = {
        n: values[table.parameter_names.index(n)] for n in ("tilt.tilt_a", "azimuth.position")
    }
    np.testing.assert_allclose(
        out["dR"], independent_dR(CLI_JOINTS, MOUNT_RPY, errors, np.radians([30.0, -40.0])),
        atol=1e-12,
    )  # fmt: skip


def test_simulate_fit_and_diagnose_on_a_continuous_oblique_table(oblique_urdf, tmp_path):
    data = tmp_path / "x.csv"
    proc = cli("simulate", "--urdf", str(oblique_urdf), "--error", "tilt.tilt_a=20",
               "--error", "azimuth.tilt_b=-8", "--error", "mount.rot_y=5", "--seed", "3",
               "--phi1-step-deg", "30", "--phi2-step-deg", "30", "-o", str(data))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    for command in ("fit", "diagnose"):
        proc = cli(command, "--urdf", str(oblique_urdf), "--json", str(data))
        assert proc.returncode == 0, (command, proc.stderr)
        assert "Traceback" not in proc.stderr
        json.loads(proc.stdout)
    out = json.loads(cli("fit", "--urdf", str(oblique_urdf), "--json", str(data)).stdout)
    assert out["chi2_reduced"] == pytest.approx(1.0, abs=0.3)
