"""The 3-D scene of any table (1 to 3 joints, from its URDF), errors magnified, in meshcat.

The same picture as :class:`~turntable_pin.viewer.scene.SetupScene` draws for the paper's table:
the URDF's visuals on a Pinocchio model whose joint placements carry the magnified errors
(:meth:`GenericTable.pinocchio_model`), the ideal payload frame (dark triad) and the actual one
(red/green/blue triad), and the ideal (dark) and actual (magenta) axis of the *last* joint.

Magnification (:func:`table_exaggeration`): the angular errors by K, which makes the largest one
:data:`~turntable_pin.viewer.scene.DEFAULT_DISPLAY_ANGLE_RAD` (3 degrees) unless given; the
offsets by the same K but no more than shows the largest as
:data:`~turntable_pin.viewer.scene.DEFAULT_DISPLAY_OFFSET_M` (30 mm).

A ``<mesh>`` visual whose file cannot be found is drawn as a 5 cm box (:func:`primitive_urdf`);
:attr:`TableScene.warnings` says which, for the command line to print in one line.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.interrupts import temporary_folder
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD, M_PER_MM
from ..model.angles import ANGLE_ENTRIES, ANGLE_NAMES
from .scene import (
    DEFAULT_DISPLAY_ANGLE_RAD,
    DEFAULT_DISPLAY_OFFSET_M,
    ROOT,
    Exaggeration,
    ScenePoses,
    SetupScene,
)

__all__ = [
    "FALLBACK_BOX_M",
    "TableScene",
    "missing_meshes",
    "primitive_urdf",
    "table_exaggeration",
]

FALLBACK_BOX_M = 0.05
"""Edge of the box drawn in place of a mesh whose file is missing, metres."""


def _mesh_file(filename: str, urdf_dir: Path) -> Path | None:
    """The file a URDF mesh ``filename`` names, if it exists (relative to the URDF's folder;
    ``package://PKG/REST`` looked up as ``PKG/REST`` or ``REST`` in the URDF's folder and its
    parents; ``file://`` stripped)."""
    text = filename.strip()
    if text.startswith("file://"):
        text = text[len("file://") :]
    candidates: list[Path] = []
    if text.startswith("package://"):
        rest = text[len("package://") :]
        tail = rest.split("/", 1)[1] if "/" in rest else rest
        for folder in (urdf_dir, *urdf_dir.parents):
            candidates += [folder / rest, folder / tail]
    else:
        path = Path(text)
        candidates.append(path if path.is_absolute() else urdf_dir / path)
    return next((c for c in candidates if c.is_file()), None)


def missing_meshes(urdf_path: str | Path) -> list[str]:
    """The ``<mesh filename>``s of the URDF's visuals whose files cannot be found."""
    path = Path(urdf_path)
    root = ET.parse(path).getroot()
    out = []
    for visual in root.iter("visual"):
        for mesh in visual.iter("mesh"):
            name = mesh.get("filename", "")
            if _mesh_file(name, path.parent) is None:
                out.append(name)
    return out


def primitive_urdf(urdf_path: str | Path, output: str | Path) -> Path:
    """Write the URDF with every visual mesh whose file is missing replaced by a box of edge
    :data:`FALLBACK_BOX_M`; other meshes get their absolute path. Returns ``output``."""
    path = Path(urdf_path)
    tree = ET.parse(path)
    for visual in tree.getroot().iter("visual"):
        geometry = visual.find("geometry")
        if geometry is None:
            continue
        for mesh in list(geometry.iter("mesh")):
            found = _mesh_file(mesh.get("filename", ""), path.parent)
            if found is not None:
                mesh.set("filename", str(found.resolve()))
                continue
            geometry.remove(mesh)
            ET.SubElement(geometry, "box", size=" ".join([f"{FALLBACK_BOX_M:g}"] * 3))
    output = Path(output)
    tree.write(output, encoding="unicode")
    return output


def table_exaggeration(
    table,
    error_values,
    angle_factor: float | None = None,
    length_factor: float | None = None,
) -> Exaggeration:
    """The default magnification of a table's errors (see the module docstring); either factor
    given is used as is. A perfect table is shown at true size."""
    values = np.asarray(error_values, dtype=float)
    is_length = np.array([n in table.length_names for n in table.parameter_names])
    largest = float(np.max(np.abs(values[~is_length]), initial=0.0))
    offset = float(np.max(np.abs(values[is_length]), initial=0.0))
    angle_given = angle_factor is not None
    if angle_factor is None:
        angle_factor = DEFAULT_DISPLAY_ANGLE_RAD / largest if largest > 0.0 else 1.0
    if length_factor is None:
        length_factor = angle_factor
        if offset > 0.0:
            to_display = DEFAULT_DISPLAY_OFFSET_M / offset
            own = angle_given or largest > 0.0
            length_factor = min(angle_factor, to_display) if own else to_display
    return Exaggeration(angle_factor, length_factor)


def _y_onto(axis) -> np.ndarray:
    """A 4x4 rotation taking the y axis (a meshcat cylinder's) onto the unit ``axis``."""
    from ..model.generic_table import perpendicular_directions

    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    u, _ = perpendicular_directions(a)
    out = np.eye(4)
    out[:3, :3] = np.column_stack([u, a, np.cross(u, a)])
    return out


class TableScene(SetupScene):
    """Any table with magnified errors, ready to be drawn into a meshcat visualizer.

    Args:
        table: a :class:`~turntable_pin.model.generic_table.GenericTable`.
        error_values: its error vector (rad, m; default none).
        exaggeration: the magnification (default: :func:`table_exaggeration`).

    The angles of :meth:`poses`, :meth:`legend` and :meth:`set_position` are the joint angles in
    chain order, radians, one per joint.
    """

    def __init__(self, table, error_values=None, *, exaggeration: Exaggeration | None = None):
        import pinocchio as pin

        self.table = table
        n = len(table.parameter_names)
        self.error_values = np.zeros(n) if error_values is None else np.asarray(error_values, float)
        if self.error_values.shape != (n,):
            raise InputError(f"expected {n} error values, got shape {self.error_values.shape}")
        self.exaggeration = exaggeration or table_exaggeration(table, self.error_values)
        is_length = np.array([p in table.length_names for p in table.parameter_names])
        k = self.exaggeration
        self.display_values = self.error_values * np.where(
            is_length, k.length_factor, k.angle_factor
        )
        pin_model = table.pinocchio_model(self.display_values)
        self.model = SimpleNamespace(pin_model=pin_model, urdf_path=table.urdf_path)
        self.warnings: list[str] = []
        missing = missing_meshes(table.urdf_path)
        try:
            if missing:
                self.warnings.append(
                    f"{table.urdf_path}: mesh file(s) not found, drawn as "
                    f"{FALLBACK_BOX_M * 100:g} cm boxes: {', '.join(missing)}"
                )
                with temporary_folder("turntable-pin-urdf-") as tmp:
                    urdf = primitive_urdf(table.urdf_path, tmp / table.urdf_path.name)
                    self.visual_model = pin.buildGeomFromUrdf(
                        pin_model, str(urdf), pin.GeometryType.VISUAL
                    )
            else:
                self.visual_model = pin.buildGeomFromUrdf(
                    pin_model, str(table.urdf_path), pin.GeometryType.VISUAL
                )
        except (RuntimeError, ValueError) as exc:
            message = re.sub(r"\s+", " ", str(exc)).strip()
            raise ModelError(
                f"{table.urdf_path}: its visuals cannot be loaded: {message}"
            ) from None
        self.camera_target_m, self.camera_offset_m = _camera(table, self.visual_model)
        self._viz = None
        self._vis = None

    def _q(self, angles_rad) -> np.ndarray:
        if len(angles_rad) != len(self.table.joint_names):
            raise InputError(
                f"expected {len(self.table.joint_names)} joint angle(s) "
                f"({', '.join(self.table.joint_names)}), got {len(angles_rad)}"
            )
        return self.table.chain.joint_vector(*[float(a) for a in angles_rad])

    def poses(self, *angles_rad: float) -> ScenePoses:
        """Poses of the triads and the last joint's axis rods at the joint angles, radians
        (the rod poses turn a meshcat cylinder's z, as drawn, onto the joint axis)."""
        import pinocchio as pin

        q = self._q(angles_rad)
        last = self.table.chain.joints[-1]
        onto_axis = _y_onto(last.axis) @ np.linalg.inv(_rod_frame())
        out = []
        for model in (self.model.pin_model, self.table.nominal_pin_model):
            data = model.createData()
            pin.framesForwardKinematics(model, data, q)
            payload = data.oMf[model.getFrameId(self.table.payload_frame)].homogeneous
            joint = data.oMi[model.getJointId(last.name)].homogeneous
            out.append((payload, joint @ onto_axis))
        return ScenePoses(out[0][0], out[1][0], out[0][1], out[1][1])

    def legend(self, *angles_rad: float) -> list[str]:
        """Lines saying what the picture shows: position, magnification, true error angles."""
        d_r = self.table.rotation_error(self.error_values, list(angles_rad))
        true = {
            n: float(d_r[i, j]) * ARCSEC_PER_RAD
            for n, (i, j) in zip(ANGLE_NAMES, ANGLE_ENTRIES, strict=True)
        }
        where = ", ".join(
            f"{j} = {a * DEG_PER_RAD:g} deg"
            for j, a in zip(self.table.joint_names, angles_rad, strict=True)
        )
        k = self.exaggeration
        lengths = [self.error_values[self.table.parameter_names.index(n)]
                   for n in self.table.length_names]  # fmt: skip
        largest_mm = max((abs(v) for v in lengths), default=0.0) / M_PER_MM
        last = self.table.joint_names[-1]
        return [
            where,
            f"errors magnified x{k.angle_factor:.4g} (angles), x{k.length_factor:.4g} (offsets, "
            f"largest {largest_mm:g} mm)",
            f'true dpsi = {true["dpsi"]:.2f}", dtheta = {true["dtheta"]:.2f}", dgamma = '
            f'{true["dgamma"]:.2f}"',
            "colour triad: actual payload frame (x red, y green, z blue); dark: ideal",
            f"magenta rod: actual {last} axis; dark rod: ideal {last} axis",
        ]

    def to_dict(self) -> dict:
        """True errors (arcsec, mm; the non-zero ones), magnification and table, JSON-ready."""
        return {
            "errors": {
                k: v for k, v in self.table.to_user_units(self.error_values).items() if v != 0.0
            },
            "exaggeration": self.exaggeration.to_dict(),
            "urdf": str(self.table.urdf_path),
            "payload_frame": self.table.payload_frame,
            "joints": list(self.table.joint_names),
        }

    def set_position(self, *angles_rad: float) -> ScenePoses:
        """Move the drawn scene to the joint angles, radians (chain order)."""
        if self._viz is None:
            raise RuntimeError("draw() the scene into a visualizer first")
        self._viz.display(self._q(angles_rad))
        poses = self.poses(*angles_rad)
        self._vis[f"{ROOT}/actual_triad"].set_transform(poses.actual_payload)
        self._vis[f"{ROOT}/ideal_triad"].set_transform(poses.ideal_payload)
        self._vis[f"{ROOT}/actual_inner_axis"].set_transform(poses.actual_inner_axis)
        self._vis[f"{ROOT}/ideal_inner_axis"].set_transform(poses.ideal_inner_axis)
        return poses


def _camera(table, visual_model) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Camera target and eye offset (base frame, metres) framing the whole table: the paper's
    view direction, aimed at the centre of the visuals' bounding box at zero angles, from a
    distance proportional to its diagonal (the paper's view: offset length = its diagonal)."""
    import pinocchio as pin

    from .scene import CAMERA_OFFSET_M

    model = table.nominal_pin_model
    data, geometry_data = model.createData(), pin.GeometryData(visual_model)
    q = table.chain.joint_vector(*[0.0] * len(table.joint_names))
    pin.updateGeometryPlacements(model, data, visual_model, geometry_data, q)
    points = [np.zeros(3)]
    for index, item in enumerate(visual_model.geometryObjects):
        placement = geometry_data.oMg[index]
        try:
            item.geometry.computeLocalAABB()
            box = item.geometry.aabb_local
            corners = np.array(np.meshgrid(*zip(box.min_, box.max_, strict=True))).reshape(3, -1).T
        except (AttributeError, RuntimeError):  # a geometry without a box: its origin
            corners = np.zeros((1, 3))
        points += [placement.act(np.asarray(c, dtype=float)) for c in corners]
    points = np.array(points)
    low, high = points.min(axis=0), points.max(axis=0)
    offset = np.asarray(CAMERA_OFFSET_M, dtype=float)
    scale = max(float(np.linalg.norm(high - low)), 0.1) / float(np.linalg.norm(offset))
    return tuple(float(v) for v in 0.5 * (low + high)), tuple(float(v) for v in offset * scale)


def _rod_frame() -> np.ndarray:
    """The transform :meth:`SetupScene.draw` gives a rod inside its node: y onto z."""
    from .scene import _Y_ONTO

    return _Y_ONTO[2]
