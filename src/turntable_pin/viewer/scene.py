"""The 3-D scene of the setup: the turntable URDF's primitives, errors magnified, in meshcat.

Arc-second errors are invisible at true size, so the scene is built from the errors magnified
(angles by K, ``deta`` by its own factor, see :class:`Exaggeration`): a :class:`TurntableModel`
whose joint placements carry the magnified errors, drawn by Pinocchio's ``MeshcatVisualizer``
from the URDF's visual primitives. Default magnification: K makes the largest angular error
:data:`DEFAULT_DISPLAY_ANGLE_RAD` (3 degrees; 2700 for 4 arcsec); ``deta`` gets the same factor
but no more than shows it as :data:`DEFAULT_DISPLAY_OFFSET_M` (30 mm, a sixth of the table's
radius) -- a 0.2 mm offset times 2700 would put the inner axis half a metre off the table.

Besides the machine the scene shows the ideal payload frame ``Rd`` (thin dark triad) and the actual
one ``Rt`` (red/green/blue triad, x/y/z), and the ideal (dark) and actual (magenta) inner rotation
axis, so wobble and orthogonality errors (the axis tilts), the intersection error (the axis moves)
and the mount errors (the triads part) can be told apart.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

from ..core.exceptions import InputError
from ..core.rotations import rot_x, rot_z
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD, M_PER_MM
from ..model.errors import ANGULAR_ERROR_NAMES, TurntableErrors
from ..model.turntable import INNER_JOINT, TurntableModel

__all__ = [
    "ACTUAL_AXIS_COLOR",
    "ACTUAL_TRIAD_COLORS",
    "AXIS_LENGTH_M",
    "CAMERA_OFFSET_M",
    "CAMERA_TARGET_M",
    "DEFAULT_DISPLAY_ANGLE_RAD",
    "DEFAULT_DISPLAY_OFFSET_M",
    "IDEAL_COLOR",
    "ROOT",
    "TRIAD_LENGTH_M",
    "Exaggeration",
    "ScenePoses",
    "SetupScene",
    "animation_frames_rad",
    "default_positions_deg",
]

DEFAULT_DISPLAY_ANGLE_RAD = math.radians(3.0)
"""The largest angular error is magnified to this angle by default."""
DEFAULT_DISPLAY_OFFSET_M = 0.03
"""The intersection error is magnified to at most this length by default."""

ROOT = "turntable_pin"
"""The meshcat path under which the scene draws everything."""
TRIAD_LENGTH_M = 0.3
"""Length of the payload-frame triads, metres."""
AXIS_LENGTH_M = 0.7
"""Length of the inner-axis rods, metres."""
ACTUAL_TRIAD_COLORS = (0xD62728, 0x2CA02C, 0x1F77B4)  # x, y, z
"""Colours (RGB) of the actual triad's x, y, z axes: red, green, blue."""
IDEAL_COLOR = 0x303030
"""Colour (RGB) of the ideal triad and the ideal inner axis: dark grey."""
ACTUAL_AXIS_COLOR = 0xC000C0
"""Colour (RGB) of the actual inner axis: magenta."""
# Camera: look at the table centre from north-east and above (base frame x north, y west, z up).
CAMERA_TARGET_M = (0.0, 0.0, -0.2)
CAMERA_OFFSET_M = (0.84, -0.64, 0.34)


@dataclass(frozen=True)
class Exaggeration:
    """How the scene magnifies errors: angles by ``angle_factor``, deta by ``length_factor``."""

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
        errors: TurntableErrors,
        angle_factor: float | None = None,
        length_factor: float | None = None,
        display_angle_rad: float = DEFAULT_DISPLAY_ANGLE_RAD,
        display_offset_m: float = DEFAULT_DISPLAY_OFFSET_M,
    ) -> Exaggeration:
        """The default magnification of ``errors`` (see the module docstring); either factor given
        is used as is. A perfect table is shown at true size; a table whose only error is deta
        shows it as ``display_offset_m``."""
        largest = float(np.max(np.abs(errors.angular_array_rad())))
        angle_given = angle_factor is not None
        if angle_factor is None:
            angle_factor = display_angle_rad / largest if largest > 0.0 else 1.0
        if length_factor is None:
            length_factor = angle_factor
            if errors.deta != 0.0:
                to_display = display_offset_m / abs(errors.deta)
                # With no angular error to take the factor from, deta alone sets it.
                own = angle_given or largest > 0.0
                length_factor = min(angle_factor, to_display) if own else to_display
        return cls(angle_factor, length_factor)

    def apply(self, errors: TurntableErrors) -> TurntableErrors:
        """The magnified error set the scene's model carries."""
        values = errors.as_array()
        values[: len(ANGULAR_ERROR_NAMES)] *= self.angle_factor
        values[len(ANGULAR_ERROR_NAMES) :] *= self.length_factor
        return TurntableErrors.from_array(values)

    def to_dict(self) -> dict:
        """Both factors as a dict."""
        return {"angle_factor": self.angle_factor, "length_factor": self.length_factor}


@dataclass(frozen=True)
class ScenePoses:
    """Base-frame poses (4x4) of the scene's markers at one position of the magnified model.

    The inner-axis poses are the inner joint's frame (after its rotation phi2): the rod is drawn
    along its z axis, the inner rotation axis.
    """

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


class SetupScene:
    """The turntable with magnified errors, ready to be drawn into a meshcat visualizer.

    Args:
        errors: the true error set (default: none).
        urdf_path: the nominal URDF (default: the bundled one).
        exaggeration: the magnification (default: :meth:`Exaggeration.for_errors`).
        camera_target_m, camera_offset_m: where the camera looks (base frame, metres) and its
            eye's offset from there (default: the whole machine from north-east and above).
    """

    def __init__(
        self,
        errors: TurntableErrors | None = None,
        *,
        urdf_path: str | Path | None = None,
        exaggeration: Exaggeration | None = None,
        camera_target_m=CAMERA_TARGET_M,
        camera_offset_m=CAMERA_OFFSET_M,
    ) -> None:
        self.camera_target_m = tuple(float(v) for v in camera_target_m)
        self.camera_offset_m = tuple(float(v) for v in camera_offset_m)
        self.errors = errors if errors is not None else TurntableErrors.zero()
        self.exaggeration = exaggeration or Exaggeration.for_errors(self.errors)
        self.display_errors = self.exaggeration.apply(self.errors)
        self.model = TurntableModel(self.display_errors, urdf_path)
        # Built against the magnified model: the payload's visuals hang on the fixed mount, and
        # Pinocchio folds that mount's (magnified) error into their placements.
        self.visual_model = pin.buildGeomFromUrdf(
            self.model.pin_model, str(self.model.urdf_path), pin.GeometryType.VISUAL
        )
        self._true_model = TurntableModel(self.errors, self.model.urdf_path)
        self._viz = None
        self._vis = None

    # ---- geometry (no meshcat needed) ---------------------------------------------------------
    def poses(self, phi1_rad: float, phi2_rad: float) -> ScenePoses:
        """Poses of the triads and inner-axis rods at commanded angles (phi1, phi2), radians."""
        actual = self.model.payload_pose(phi1_rad, phi2_rad).homogeneous
        ideal = self.model.ideal_pose(phi1_rad, phi2_rad).homogeneous
        q = self.model.joint_vector(phi1_rad, phi2_rad)
        axes = []
        for model in (self.model.pin_model, self.model.nominal_pin_model):
            data = model.createData()
            pin.forwardKinematics(model, data, q)
            axes.append(data.oMi[model.getJointId(INNER_JOINT)].homogeneous)
        return ScenePoses(actual, ideal, axes[0], axes[1])

    def legend(self, phi1_rad: float, phi2_rad: float) -> list[str]:
        """Lines saying what the picture shows: position, magnification, true error angles."""
        true = self._true_model.orientation_error(phi1_rad, phi2_rad)
        k = self.exaggeration
        return [
            f"phi1 = {phi1_rad * DEG_PER_RAD:g} deg, phi2 = {phi2_rad * DEG_PER_RAD:g} deg",
            f"errors magnified x{k.angle_factor:.4g} (angles), x{k.length_factor:.4g} (deta "
            f"{self.errors.deta / M_PER_MM:g} mm)",
            f'true dpsi = {true.dpsi_rad * ARCSEC_PER_RAD:.2f}", dtheta = '
            f'{true.dtheta_rad * ARCSEC_PER_RAD:.2f}", dgamma = '
            f'{true.dgamma_rad * ARCSEC_PER_RAD:.2f}"',
            "colour triad: actual payload frame (x red, y green, z blue); dark: ideal",
            "magenta rod: actual inner axis; dark rod: ideal inner axis",
        ]

    def to_dict(self) -> dict:
        """True errors (arcsec, mm), magnification and URDF path, as a JSON-ready dict."""
        return {
            "errors": self.errors.to_user_units(),
            "exaggeration": self.exaggeration.to_dict(),
            "urdf": str(self.model.urdf_path),
        }

    # ---- meshcat ------------------------------------------------------------------------------
    def draw(self, visualizer) -> None:
        """Load the machine, the triads and the axis rods into a ``meshcat.Visualizer``."""
        import meshcat.geometry as g
        from pinocchio.visualize import MeshcatVisualizer

        self._vis = visualizer
        viz = MeshcatVisualizer(self.model.pin_model, None, self.visual_model)
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

    def set_position(self, phi1_rad: float, phi2_rad: float) -> ScenePoses:
        """Move the drawn scene to commanded angles (phi1, phi2), radians."""
        if self._viz is None:
            raise RuntimeError("draw() the scene into a visualizer first")
        self._viz.display(self.model.joint_vector(phi1_rad, phi2_rad))
        poses = self.poses(phi1_rad, phi2_rad)
        self._vis[f"{ROOT}/actual_triad"].set_transform(poses.actual_payload)
        self._vis[f"{ROOT}/ideal_triad"].set_transform(poses.ideal_payload)
        self._vis[f"{ROOT}/actual_inner_axis"].set_transform(poses.actual_inner_axis)
        self._vis[f"{ROOT}/ideal_inner_axis"].set_transform(poses.ideal_inner_axis)
        return poses

    def set_camera(self, target_m=None, offset_m=None) -> None:
        """Aim the camera at ``target_m`` from ``target_m + offset_m`` (base frame, metres;
        default: the scene's ``camera_target_m``, ``camera_offset_m``).

        pinocchio's ``setCameraPosition`` fails with meshcat 0.3.2; the camera is a node whose
        transform is the orbit target and whose child's ``position`` is the eye offset, in the
        viewer's y-up frame: ``[dx, dz, -dy]``.
        """
        target_m = self.camera_target_m if target_m is None else target_m
        dx, dy, dz = self.camera_offset_m if offset_m is None else offset_m
        self._vis["/Cameras/default"].set_transform(_translation(target_m))
        self._vis["/Cameras/default/rotated/<object>"].set_property("position", [dx, dz, -dy])


def default_positions_deg() -> np.ndarray:
    """A 16-position tumble (phi1, phi2 in 0/90/180/270 deg, inner axis serpentine), (16, 2)."""
    rows = []
    for i, phi1 in enumerate((0.0, 90.0, 180.0, 270.0)):
        inner = (0.0, 90.0, 180.0, 270.0)
        for phi2 in inner if i % 2 == 0 else inner[::-1]:
            rows.append((phi1, phi2))
    return np.array(rows)


def animation_frames_rad(positions_deg, frames_per_move: int = 12) -> np.ndarray:
    """Frames (phi1, phi2) in radians moving linearly through ``positions_deg`` (N, 2) and back
    to the first, ``frames_per_move`` frames per move: shape (N * frames_per_move, 2). Any table:
    ``positions_deg`` (N, J) of J joint angles gives frames (N * frames_per_move, J)."""
    positions = np.asarray(positions_deg, dtype=float)
    width = positions.shape[1] if positions.ndim == 2 else 2
    positions = np.radians(positions.reshape(-1, width))
    if frames_per_move < 1:
        raise InputError(f"frames per move must be >= 1, got {frames_per_move}")
    targets = np.roll(positions, -1, axis=0)
    t = np.arange(frames_per_move)[:, None] / frames_per_move
    frames = positions[:, None, :] + t[None] * (targets - positions)[:, None, :]
    return frames.reshape(-1, width)
