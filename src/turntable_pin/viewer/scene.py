"""The 3-D scene of a table (the paper's or any URDF's, 1 to 3 joints), errors magnified, meshcat.

Arc-second errors are invisible at true size, so the scene is the table's Pinocchio model with
the errors magnified (:class:`Exaggeration`) in its placements, drawn by Pinocchio's
``MeshcatVisualizer`` from the URDF's visuals. By default K makes the largest angular error
:data:`DEFAULT_DISPLAY_ANGLE_RAD` (3 degrees; 2700 for 4 arcsec); lengths get the same factor but
at most :data:`DEFAULT_DISPLAY_OFFSET_M` (30 mm): 0.2 mm times 2700 would put the inner axis half
a metre off the table.

The scene also shows the ideal payload frame ``Rd`` (thin dark triad) and the actual one ``Rt``
(red/green/blue, x/y/z), and the ideal (dark) and actual (magenta) axis of the last joint, so axis
tilts, axis offsets and mount errors (the triads part) can be told apart. A ``<mesh>`` whose file
is missing is drawn as a 5 cm box (:func:`primitive_urdf`), said in :attr:`SetupScene.warnings`.
"""

# pinocchio and meshcat are imported inside functions: import turntable_pin stays light
from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.interrupts import temporary_folder
from ..core.rotations import rot_x, rot_z
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD, M_PER_MM
from ..model.errors import TurntableErrors
from ..model.generic_table import perpendicular_directions
from ..model.paper_table import resolve_table

__all__ = [
    "ACTUAL_AXIS_COLOR",
    "ACTUAL_TRIAD_COLORS",
    "AXIS_LENGTH_M",
    "CAMERA_OFFSET_M",
    "DEFAULT_DISPLAY_ANGLE_RAD",
    "DEFAULT_DISPLAY_OFFSET_M",
    "FALLBACK_BOX_M",
    "IDEAL_COLOR",
    "ROOT",
    "TRIAD_LENGTH_M",
    "Exaggeration",
    "ScenePoses",
    "SetupScene",
    "animation_frames_rad",
    "default_positions_deg",
    "missing_meshes",
    "primitive_urdf",
]

DEFAULT_DISPLAY_ANGLE_RAD = math.radians(3.0)
"""The largest angular error is magnified to this angle by default."""
DEFAULT_DISPLAY_OFFSET_M = 0.03
"""The largest length error is magnified to at most this length by default."""

ROOT = "turntable_pin"
"""The meshcat path under which the scene draws everything."""
TRIAD_LENGTH_M = 0.3
"""Length of the payload-frame triads, metres."""
AXIS_LENGTH_M = 0.7
"""Length of the axis rods, metres."""
ACTUAL_TRIAD_COLORS = (0xD62728, 0x2CA02C, 0x1F77B4)  # x, y, z
"""Colours (RGB) of the actual triad's x, y, z axes: red, green, blue."""
IDEAL_COLOR = 0x303030
"""Colour (RGB) of the ideal triad and the ideal axis: dark grey."""
ACTUAL_AXIS_COLOR = 0xC000C0
"""Colour (RGB) of the actual axis: magenta."""
# The camera looks from north-east and above (base frame x north, y west, z up); its distance is
# the diagonal of the table's bounding box (the paper's table: this offset, 1.11 m).
CAMERA_OFFSET_M = (0.84, -0.64, 0.34)
"""The eye's offset from the table's centre for the paper's table, metres (base frame)."""
FALLBACK_BOX_M = 0.05
"""Edge of the box drawn in place of a mesh whose file is missing, metres."""


def _error_vector(table, errors) -> np.ndarray:
    """``errors`` (a :class:`TurntableErrors`, a vector in the table's order, or None) as the
    table's error vector (rad, m)."""
    n = len(table.parameter_names)
    if errors is None:
        return np.zeros(n)
    values = errors.as_array() if isinstance(errors, TurntableErrors) else errors
    values = np.array(values, dtype=float)
    if values.shape != (n,):
        raise InputError(f"expected {n} error values, got shape {values.shape}")
    return values


@dataclass(frozen=True)
class Exaggeration:
    """How the scene magnifies errors: angles by ``angle_factor``, lengths by ``length_factor``."""

    angle_factor: float
    length_factor: float

    def __post_init__(self) -> None:
        for name in ("angle_factor", "length_factor"):
            value = float(getattr(self, name))
            if not (math.isfinite(value) and value > 0.0):
                raise InputError(f"exaggeration {name} must be a finite number > 0, got {value!r}")
            object.__setattr__(self, name, value)

    @classmethod
    def for_errors(
        cls,
        errors,
        angle_factor: float | None = None,
        length_factor: float | None = None,
        display_angle_rad: float = DEFAULT_DISPLAY_ANGLE_RAD,
        display_offset_m: float = DEFAULT_DISPLAY_OFFSET_M,
        *,
        table=None,
    ) -> Exaggeration:
        """The default magnification of ``errors`` (module docstring); a factor given is used
        as is. A perfect table is shown at true size; with lengths only, the largest is shown as
        ``display_offset_m``."""
        table = resolve_table(table)
        values = np.abs(_error_vector(table, errors))
        is_length = _is_length(table)
        largest = float(np.max(values[~is_length], initial=0.0))
        offset = float(np.max(values[is_length], initial=0.0))
        angle_given = angle_factor is not None
        if angle_factor is None:
            angle_factor = display_angle_rad / largest if largest > 0.0 else 1.0
        if length_factor is None:
            length_factor = angle_factor
            if offset > 0.0:
                to_display = display_offset_m / offset
                # With no angular error to take the factor from, the lengths alone set it.
                own = angle_given or largest > 0.0
                length_factor = min(angle_factor, to_display) if own else to_display
        return cls(angle_factor, length_factor)

    def factors(self, table) -> np.ndarray:
        """The factor of each error of ``table``, in its order."""
        return np.where(_is_length(table), self.length_factor, self.angle_factor)

    def apply(self, errors, table=None):
        """The magnified errors: a :class:`TurntableErrors` for one, else the vector of
        ``table`` (default the paper's)."""
        if isinstance(errors, TurntableErrors):
            return TurntableErrors.from_array(self.apply(errors.as_array()))
        table = resolve_table(table)
        return _error_vector(table, errors) * self.factors(table)

    def to_dict(self) -> dict:
        """Both factors as a dict."""
        return {"angle_factor": self.angle_factor, "length_factor": self.length_factor}


def _is_length(table) -> np.ndarray:
    return np.array([n in table.length_names for n in table.parameter_names], dtype=bool)


@dataclass(frozen=True)
class ScenePoses:
    """Base-frame poses (4x4) of the scene's markers at one position of the magnified model; an
    axis pose is the last joint's frame turned so that its z axis (the rod) is the joint's axis."""

    actual_payload: np.ndarray
    ideal_payload: np.ndarray
    actual_inner_axis: np.ndarray
    ideal_inner_axis: np.ndarray


def _translation(offset) -> np.ndarray:
    out = np.eye(4)
    out[:3, 3] = offset
    return out


def _rotation(matrix: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = matrix
    return out


# meshcat cylinders lie along their y axis: these turn y onto x, y and z.
_Y_ONTO = (_rotation(rot_z(-math.pi / 2)), np.eye(4), _rotation(rot_x(math.pi / 2)))


def _z_onto(axis) -> np.ndarray:
    """A 4x4 rotation taking z onto the unit ``axis`` (z itself for the z axis)."""
    a = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    u, _ = perpendicular_directions(a)
    y_onto_axis = _rotation(np.column_stack([u, a, np.cross(u, a)]))
    return y_onto_axis @ _Y_ONTO[2].T


# ---- visuals of a URDF ---------------------------------------------------------------------------
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


def _visual_model(table, pin_model, warnings: list[str]):
    """The URDF's visual geometry on ``pin_model``, a missing mesh drawn as a box (and said in
    ``warnings``)."""
    import pinocchio as pin

    missing = missing_meshes(table.urdf_path)
    try:
        if not missing:
            return pin.buildGeomFromUrdf(pin_model, str(table.urdf_path), pin.GeometryType.VISUAL)
        warnings.append(
            f"{table.urdf_path}: mesh file(s) not found, drawn as {FALLBACK_BOX_M * 100:g} cm "
            f"boxes: {', '.join(missing)}"
        )
        with temporary_folder("turntable-pin-urdf-") as tmp:
            urdf = primitive_urdf(table.urdf_path, tmp / table.urdf_path.name)
            return pin.buildGeomFromUrdf(pin_model, str(urdf), pin.GeometryType.VISUAL)
    except (RuntimeError, ValueError) as exc:
        message = re.sub(r"\s+", " ", str(exc)).strip()
        raise ModelError(f"{table.urdf_path}: its visuals cannot be loaded: {message}") from None


def _camera(table, visual_model) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """Camera target and eye offset (base frame, metres) framing the whole table: the direction
    of :data:`CAMERA_OFFSET_M`, aimed at the centre of the visuals' bounding box at zero angles,
    from a distance equal to its diagonal (the paper's table: 5 mm from its hand-set view)."""
    import pinocchio as pin

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


# ---- the scene -----------------------------------------------------------------------------------
class SetupScene:
    """A table with magnified errors, ready to be drawn into a meshcat visualizer.

    Args:
        errors: a :class:`TurntableErrors` (the paper's table) or the table's error vector
            (rad, m); default none.
        table: a ``GenericTable`` (default: the paper's).
        exaggeration: the magnification (default: :meth:`Exaggeration.for_errors`).
        camera_target_m, camera_offset_m: where the camera looks and the eye's offset from there
            (base frame, metres; default: the whole table from north-east and above).

    Angles (:meth:`poses`, :meth:`legend`, :meth:`set_position`) are joint angles, chain order,
    radians. Attributes: table, error_values, exaggeration, display_values (magnified),
    pin_model (with them), visual_model, warnings (missing meshes).
    """

    def __init__(
        self,
        errors=None,
        *,
        table=None,
        exaggeration: Exaggeration | None = None,
        camera_target_m=None,
        camera_offset_m=None,
    ) -> None:
        self.table = resolve_table(table)
        self.error_values = _error_vector(self.table, errors)
        self.exaggeration = exaggeration or Exaggeration.for_errors(
            self.error_values, table=self.table
        )
        self.display_values = self.exaggeration.apply(self.error_values, self.table)
        # The visuals are built against the magnified model: the payload's visuals hang on the
        # fixed mount, and Pinocchio folds that mount's (magnified) error into their placements.
        self.pin_model = self.table.pinocchio_model(self.display_values)
        self.warnings: list[str] = []
        self.visual_model = _visual_model(self.table, self.pin_model, self.warnings)
        target, offset = _camera(self.table, self.visual_model)
        target = target if camera_target_m is None else camera_target_m
        offset = offset if camera_offset_m is None else camera_offset_m
        self.camera_target_m = tuple(float(v) for v in target)
        self.camera_offset_m = tuple(float(v) for v in offset)
        self._viz = None
        self._vis = None

    # ---- geometry (no meshcat needed) ---------------------------------------------------------
    def _q(self, angles_rad) -> np.ndarray:
        joints = self.table.joint_names
        if len(angles_rad) != len(joints):
            raise InputError(
                f"expected {len(joints)} joint angle(s) ({', '.join(joints)}), "
                f"got {len(angles_rad)}"
            )
        return self.table.chain.joint_vector(*[float(a) for a in angles_rad])

    def poses(self, *angles_rad: float) -> ScenePoses:
        """Poses of the triads and the last joint's axis rods at the joint angles, radians."""
        import pinocchio as pin

        q = self._q(angles_rad)
        last = self.table.chain.joints[-1]
        onto_axis = _z_onto(last.axis)
        out = []
        for model in (self.pin_model, self.table.nominal_pin_model):
            data = model.createData()
            pin.framesForwardKinematics(model, data, q)
            payload = data.oMf[model.getFrameId(self.table.payload_frame)].homogeneous
            joint = data.oMi[model.getJointId(last.name)].homogeneous
            out.append((payload, joint @ onto_axis))
        return ScenePoses(out[0][0], out[1][0], out[0][1], out[1][1])

    @property
    def length_label(self) -> str:
        """What the magnified lengths are called: the one length's name (the paper's ``deta``)
        or ``offsets``."""
        lengths = self.table.length_names
        return lengths[0] if len(lengths) == 1 else "offsets"

    def legend(self, *angles_rad: float) -> list[str]:
        """Lines saying what the picture shows: position, magnification, true error angles."""
        true = self.table.orientation_error(self.error_values, [float(a) for a in angles_rad])
        table, k = self.table, self.exaggeration
        where = ", ".join(
            f"phi{i} = {a * DEG_PER_RAD:g} deg ({j})"
            for i, (j, a) in enumerate(zip(table.joint_names, angles_rad, strict=True), start=1)
        )
        lengths = self.error_values[_is_length(table)] / M_PER_MM
        if len(lengths) == 1:
            shown = f"{self.length_label} {lengths[0]:g} mm"
        else:
            shown = f"offsets, largest {np.max(np.abs(lengths), initial=0.0):g} mm"
        last = table.joint_names[-1]
        axis = last if last.endswith("axis") else f"{last} axis"
        return [
            where,
            f"errors magnified x{k.angle_factor:.4g} (angles), x{k.length_factor:.4g} ({shown})",
            f'true dpsi = {true.dpsi_rad * ARCSEC_PER_RAD:.2f}", dtheta = '
            f'{true.dtheta_rad * ARCSEC_PER_RAD:.2f}", dgamma = '
            f'{true.dgamma_rad * ARCSEC_PER_RAD:.2f}"',
            "colour triad: actual payload frame (x red, y green, z blue); dark: ideal",
            f"magenta rod: actual {axis}; dark rod: ideal {axis}",
        ]

    def to_dict(self) -> dict:
        """True errors (arcsec, mm), magnification and table, as a JSON-ready dict."""
        return {
            "errors": self.table.to_user_units(self.error_values),
            "exaggeration": self.exaggeration.to_dict(),
            "urdf": str(self.table.urdf_path),
            "payload_frame": self.table.payload_frame,
            "joints": list(self.table.joint_names),
        }

    # ---- meshcat ------------------------------------------------------------------------------
    def draw(self, visualizer) -> None:
        """Load the machine, the triads and the axis rods into a ``meshcat.Visualizer``."""
        import meshcat.geometry as g
        from pinocchio.visualize import MeshcatVisualizer

        self._vis = visualizer
        viz = MeshcatVisualizer(self.pin_model, None, self.visual_model)
        viz.initViewer(viewer=visualizer)
        viz.loadViewerModel(rootNodeName=f"{ROOT}/machine")
        self._viz = viz
        for name, length, radius, colors, opacity in (
            ("actual_triad", TRIAD_LENGTH_M, 0.0045, ACTUAL_TRIAD_COLORS, 1.0),
            ("ideal_triad", TRIAD_LENGTH_M * 1.08, 0.003, (IDEAL_COLOR,) * 3, 0.9),
        ):
            for axis, color in enumerate(colors):
                node = visualizer[f"{ROOT}/{name}/{'xyz'[axis]}"]
                material = g.MeshLambertMaterial(color=color, opacity=opacity, transparent=True)
                node.set_object(g.Cylinder(length, radius), material)
                offset = np.zeros(3)
                offset[axis] = length / 2
                node.set_transform(_translation(offset) @ _Y_ONTO[axis])
        for name, radius, color in (
            ("actual_inner_axis", 0.004, ACTUAL_AXIS_COLOR),
            ("ideal_inner_axis", 0.002, IDEAL_COLOR),
        ):
            node = visualizer[f"{ROOT}/{name}/rod"]
            node.set_object(g.Cylinder(AXIS_LENGTH_M, radius), g.MeshLambertMaterial(color=color))
            node.set_transform(_Y_ONTO[2])
        visualizer["/Grid"].set_property("visible", False)
        visualizer["/Axes"].set_property("visible", False)
        # A light background: the default blue gradient hides the blue outer frame.
        visualizer["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
        visualizer["/Background"].set_property("bottom_color", [0.74, 0.76, 0.80])
        self.set_camera()

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

    def set_camera(self, target_m=None, offset_m=None) -> None:
        """Aim the camera at ``target_m`` from ``target_m + offset_m`` (base frame, metres;
        default the scene's). pinocchio's ``setCameraPosition`` fails with meshcat 0.3.2: the
        camera node's transform is the target, its child's ``position`` the eye offset in the
        viewer's y-up frame, ``[dx, dz, -dy]``."""
        target_m = self.camera_target_m if target_m is None else target_m
        dx, dy, dz = self.camera_offset_m if offset_m is None else offset_m
        self._vis["/Cameras/default"].set_transform(_translation(target_m))
        self._vis["/Cameras/default/rotated/<object>"].set_property("position", [dx, dz, -dy])


# ---- animation -----------------------------------------------------------------------------------
def default_positions_deg(n_joints: int = 2) -> np.ndarray:
    """A tumble of every joint through 0, 90, 180 and 270 deg, each joint serpentine (reversed
    on every other pass of the joints before it, so no move turns more than one joint):
    (4**n_joints, n_joints); the paper's table: 16 positions (phi1, phi2)."""
    steps = (0.0, 90.0, 180.0, 270.0)
    rows: list[tuple[float, ...]] = [()]
    for _ in range(n_joints):
        rows = [
            (*row, a) for i, row in enumerate(rows) for a in (steps if i % 2 == 0 else steps[::-1])
        ]
    return np.array(rows)


def animation_frames_rad(positions_deg, frames_per_move: int = 12) -> np.ndarray:
    """Frames in radians moving linearly through ``positions_deg`` (N, J) of J joint angles and
    back to the first, ``frames_per_move`` frames per move: shape (N * frames_per_move, J)."""
    positions = np.asarray(positions_deg, dtype=float)
    width = positions.shape[1] if positions.ndim == 2 else 2
    positions = np.radians(positions.reshape(-1, width))
    if frames_per_move < 1:
        raise InputError(f"frames per move must be >= 1, got {frames_per_move}")
    targets = np.roll(positions, -1, axis=0)
    t = np.arange(frames_per_move)[:, None] / frames_per_move
    frames = positions[:, None, :] + t[None] * (targets - positions)[:, None, :]
    return frames.reshape(-1, width)
