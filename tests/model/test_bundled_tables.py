"""The bundled example tables besides the paper's (models/*.urdf): each one read by plain Pinocchio
and by yourdfpy independently, against the chain typed below from the URDF text.

Each table is a serial chain from the root link ``base`` to one payload link; the payload pose at
random joint angles must agree between Pinocchio, yourdfpy and a small numpy product of the
origins (``rpy -> Rz(yaw) Ry(pitch) Rx(roll)``) and the joint rotations (Rodrigues).
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections import Counter
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

from conftest import REPO_DIR

MODELS_DIR = REPO_DIR / "models"
HALF_PI = np.pi / 2
PRIMITIVES = {"box", "cylinder", "sphere"}


@dataclass(frozen=True)
class Link:
    """One joint of the chain as written in the URDF: name, origin and axis (None when fixed)."""

    joint: str
    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    axis: tuple[float, float, float] | None = None
    continuous: bool = False


@dataclass(frozen=True)
class Table:
    file: str
    chain: tuple[Link, ...]
    payload: str
    root: str = "base"

    @property
    def path(self):
        return MODELS_DIR / self.file

    @property
    def moving(self) -> tuple[Link, ...]:
        return tuple(link for link in self.chain if link.axis is not None)


# Typed from the URDF files, not read from them.
TABLES = {
    "two_axis_vertical_outer": Table(
        "two_axis_vertical_outer.urdf",
        (
            Link("azimuth_axis", (0, 0, 0.10), (0, 0, 0), (0, 0, 1)),
            Link("tilt_axis", (0, 0, 0.30), (0, 0, 0), (0, -1, 0)),
            Link("imu_mount", (0, 0, 0.02), (0, 0, HALF_PI)),
        ),
        "imu",
    ),
    "three_axis_imu_table": Table(
        "three_axis_imu_table.urdf",
        (
            Link("outer_gimbal", (0, 0, 0.80), (0, 0, 0), (0, 0, 1)),
            Link("middle_gimbal", (0, 0, 0), (0, 0, 0), (0, 1, 0)),
            Link("inner_gimbal", (0, 0, 0), (0, 0, 0), (1, 0, 0)),
            Link("imu_mount", (0, 0, 0), (np.pi, 0, 0)),
        ),
        "imu",
    ),
    "single_axis_rate_table": Table(
        "single_axis_rate_table.urdf",
        (
            Link("spindle", (0, 0, 0.25), (0, 0, 0), (0, 0, 1), continuous=True),
            Link("gyro_mount", (0, 0, 0.02), (0, 0, 0)),
        ),
        "gyro",
    ),
}
N_DOF = {"two_axis_vertical_outer": 2, "three_axis_imu_table": 3, "single_axis_rate_table": 1}


# --- the independent numpy chain -----------------------------------------------------------------
def _elementary(i: int, a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    j, k = (i + 1) % 3, (i + 2) % 3
    r = np.eye(3)
    r[j, j] = r[k, k] = c
    r[j, k], r[k, j] = -s, s
    return r


def _rpy(r: float, p: float, y: float) -> np.ndarray:
    return _elementary(2, y) @ _elementary(1, p) @ _elementary(0, r)


def _about(axis, a: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * kx + (1 - np.cos(a)) * kx @ kx


def numpy_payload_pose(table: Table, angles) -> np.ndarray:
    """4x4 pose of the payload in the root frame: prod(origin, joint rotation)."""
    pose = np.eye(4)
    values = iter(angles)
    for link in table.chain:
        step = np.eye(4)
        step[:3, :3] = _rpy(*link.rpy)
        step[:3, 3] = link.xyz
        pose = pose @ step
        if link.axis is not None:
            turn = np.eye(4)
            turn[:3, :3] = _about(link.axis, next(values))
            pose = pose @ turn
    return pose


def test_numpy_rpy_convention():
    """The helper's rpy is the URDF one: rotations about the fixed x, then y, then z axes."""
    r, p, y = 0.3, -0.2, 1.1
    assert np.allclose(_rpy(r, p, y), pin.rpy.rpyToMatrix(r, p, y), atol=1e-15)
    assert np.allclose(_about((0, -1, 0), 0.4), _elementary(1, -0.4), atol=1e-15)


# --- loaded once per table -----------------------------------------------------------------------
@pytest.fixture(scope="module", params=sorted(TABLES))
def loaded(request):
    table = TABLES[request.param]
    model = pin.buildModelFromUrdf(str(table.path))
    urdf = yourdfpy.URDF.load(str(table.path), build_scene_graph=True, load_meshes=False)
    return request.param, table, model, urdf


def _pin_q(model, table: Table, angles) -> np.ndarray:
    """Pinocchio's configuration: the angle, or (cos, sin) for a continuous joint."""
    parts = []
    for link, a in zip(table.moving, angles, strict=True):
        parts.append([np.cos(a), np.sin(a)] if link.continuous else [a])
    q = np.concatenate(parts)
    assert q.shape == (model.nq,)
    return q


def _pin_axis(model, joint_id: int) -> np.ndarray:
    """Rotation axis from the joint's motion subspace (angular part), in the joint frame."""
    joint = model.joints[joint_id]
    data = joint.createData()
    joint.calc(data, pin.neutral(model))
    motion = np.asarray(data.S).reshape(6)
    assert np.allclose(motion[:3], 0.0)  # a pure rotation about the joint origin
    return motion[3:]


# --- Pinocchio -----------------------------------------------------------------------------------
def test_pinocchio_joints(loaded):
    name, table, model, _ = loaded
    n = N_DOF[name]
    assert model.nv == n and model.njoints == n + 1  # universe + the revolute joints
    assert model.nq == n + sum(link.continuous for link in table.moving)
    assert list(model.names)[1:] == [link.joint for link in table.moving]
    for jid, link in enumerate(table.moving, start=1):
        short = model.joints[jid].shortname()
        assert short.startswith(("JointModelR", "JointModelRevolute")), short
        assert ("RUB" in short or "Unbounded" in short) == link.continuous
        assert np.array_equal(_pin_axis(model, jid), link.axis)
        assert model.parents[jid] == jid - 1  # a serial chain
    for jid, link in enumerate(table.moving, start=1):
        if not link.continuous:
            idx = model.joints[jid].idx_q
            assert model.lowerPositionLimit[idx] < model.upperPositionLimit[idx]
        assert model.velocityLimit[model.joints[jid].idx_v] > 0


def test_pinocchio_payload_is_the_only_leaf(loaded):
    _, table, model, _ = loaded
    parents = {f.parentFrame for i, f in enumerate(model.frames) if f.parentFrame != i}
    leaves = [f.name for i, f in enumerate(model.frames) if i not in parents]
    assert leaves == [table.payload]
    payload = model.frames[model.getFrameId(table.payload)]
    assert payload.type == pin.FrameType.BODY and payload.parentJoint == model.njoints - 1
    mount = model.frames[payload.parentFrame]
    assert mount.type == pin.FrameType.FIXED_JOINT and mount.name == table.chain[-1].joint


# --- yourdfpy ------------------------------------------------------------------------------------
def test_yourdfpy_joints_and_leaf(loaded):
    name, table, _, urdf = loaded
    joints = {j.name: j for j in urdf.robot.joints}
    assert urdf.base_link == table.root
    assert list(urdf.actuated_joint_names) == [link.joint for link in table.moving]
    assert len(urdf.actuated_joint_names) == N_DOF[name]
    assert set(joints) == {link.joint for link in table.chain}
    for link in table.chain:
        joint = joints[link.joint]
        if link.axis is None:
            assert joint.type == "fixed"
            continue
        assert joint.type == ("continuous" if link.continuous else "revolute")
        assert np.array_equal(joint.axis, link.axis)
        assert joint.limit is not None and joint.limit.velocity > 0 and joint.limit.effort > 0
        if not link.continuous:
            assert joint.limit.lower < joint.limit.upper
    children = Counter(j.parent for j in urdf.robot.joints)
    assert max(children.values()) == 1  # no branching
    leaves = [lk.name for lk in urdf.robot.links if lk.name not in children]
    assert leaves == [table.payload]
    # walking parent links from the payload reaches the root through the whole chain
    by_child = {j.child: j for j in urdf.robot.joints}
    walk, link_name = [], table.payload
    while link_name in by_child:
        walk.append(by_child[link_name].name)
        link_name = by_child[link_name].parent
    assert link_name == table.root and walk[::-1] == [link.joint for link in table.chain]


def test_yourdfpy_visuals_are_coloured_primitives(loaded):
    _, _, _, urdf = loaded
    colours = {m.name: m.color for m in urdf.robot.materials}
    visuals = [v for lk in urdf.robot.links for v in lk.visuals]
    assert visuals
    for visual in visuals:
        geometry = visual.geometry
        assert geometry.mesh is None
        assert [k for k in PRIMITIVES if getattr(geometry, k) is not None]
        assert visual.material is not None and colours[visual.material.name] is not None
        rgba = colours[visual.material.name].rgba
        assert rgba.shape == (4,) and np.all((rgba >= 0) & (rgba <= 1))


# --- the three agree -----------------------------------------------------------------------------
def test_payload_pose_pinocchio_yourdfpy_numpy(loaded):
    name, table, model, urdf = loaded
    data = model.createData()
    frame_id = model.getFrameId(table.payload)
    rng = np.random.default_rng(sum(map(ord, name)))
    samples = [np.zeros(N_DOF[name])] + list(rng.uniform(-np.pi, np.pi, (25, N_DOF[name])))
    for angles in samples:
        pin.framesForwardKinematics(model, data, _pin_q(model, table, angles))
        pin_pose = data.oMf[frame_id].homogeneous
        urdf.update_cfg(angles)
        yd_pose = urdf.get_transform(table.payload, table.root)
        np_pose = numpy_payload_pose(table, angles)
        assert np.allclose(pin_pose[:3, :3], yd_pose[:3, :3], rtol=0, atol=1e-12)
        assert np.allclose(pin_pose[:3, :3], np_pose[:3, :3], rtol=0, atol=1e-12)
        assert np.allclose(pin_pose[:3, 3], yd_pose[:3, 3], rtol=0, atol=1e-12)
        assert np.allclose(pin_pose[:3, 3], np_pose[:3, 3], rtol=0, atol=1e-12)


def test_tilt_axis_sense():
    """The two-axis table's tilt axis is -y: positive tilt lifts the platform's +x edge."""
    table = TABLES["two_axis_vertical_outer"]
    model = pin.buildModelFromUrdf(str(table.path))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.array([0.0, 0.3]))
    platform_x = data.oMf[model.getFrameId("tilt_frame")].rotation[:, 0]
    assert platform_x[2] == pytest.approx(np.sin(0.3), abs=1e-15)


# --- visual geometry -----------------------------------------------------------------------------
def test_visual_geometry_one_object_per_visual(loaded):
    _, table, model, urdf = loaded
    root = ET.parse(table.path).getroot()
    per_link = {lk.get("name"): len(lk.findall("visual")) for lk in root.iter("link")}
    for visual in root.iter("visual"):
        (shape,) = list(visual.find("geometry"))
        assert shape.tag in PRIMITIVES
    geom = pin.buildGeomFromUrdf(model, str(table.path), pin.GeometryType.VISUAL)
    assert geom.ngeoms == sum(per_link.values()) == sum(len(lk.visuals) for lk in urdf.robot.links)
    attached = Counter(model.frames[o.parentFrame].name for o in geom.geometryObjects)
    assert attached == Counter({k: v for k, v in per_link.items() if v})
    kinds = {type(o.geometry).__name__.lower() for o in geom.geometryObjects}
    assert kinds <= PRIMITIVES
