"""URDF files with the turntable errors written into their joint ``<origin>``s, via yourdfpy.

yourdfpy is also a second, independent forward-kinematics library: :class:`YourdfpyTurntable`
evaluates the same orientation error from a URDF without Pinocchio, for cross-checks.
"""

# yourdfpy is imported inside functions: import turntable_pin stays light
from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.files import check_input_file, write_atomic
from ..core.resources import default_urdf_path
from ..core.sizes import MAX_URDF_FILE_BYTES
from .chain import ErrorChain

__all__ = ["YourdfpyTurntable", "write_error_urdf"]


def _load_yourdfpy(path: str | Path):
    import yourdfpy

    check_input_file(path, "URDF", MAX_URDF_FILE_BYTES)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return yourdfpy.URDF.load(
                str(path),
                load_meshes=False,
                build_collision_scene_graph=False,
                load_collision_meshes=False,
            )
    except Exception as exc:  # yourdfpy raises many kinds on a bad file
        raise ModelError(f"{path}: yourdfpy cannot read this URDF: {exc}") from None


def write_error_urdf(
    urdf_path: str | Path, chain: ErrorChain, error_values: np.ndarray, path: str | Path
) -> Path:
    """Write the nominal URDF ``urdf_path`` (never overwritten) to ``path`` (atomically) with the
    error transforms of ``chain`` (read off it) for ``error_values`` in its joint origins."""
    path, urdf_path = Path(path), Path(urdf_path)
    if path.exists() and path.resolve() == urdf_path.resolve():
        raise InputError("refusing to overwrite the input URDF", path=path)
    urdf = _load_yourdfpy(urdf_path)
    transforms = chain.error_transforms(np.asarray(error_values, dtype=float))
    for joint_name in transforms:
        joint = urdf.joint_map[joint_name]
        nominal = np.eye(4) if joint.origin is None else np.asarray(joint.origin, dtype=float)
        joint.origin = nominal @ transforms[joint_name]
    return write_atomic(path, lambda tmp: urdf.write_xml_file(str(tmp)))


class YourdfpyTurntable:
    """Orientation error of ``urdf_path`` (errors in its placements) against
    ``nominal_urdf_path`` (default the bundled table) with yourdfpy, independent of Pinocchio;
    ``joints`` from the base and ``payload_frame`` default to the paper's."""

    def __init__(
        self,
        urdf_path: str | Path,
        nominal_urdf_path: str | Path | None = None,
        joints: tuple[str, ...] = ("outer_axis", "inner_axis"),
        payload_frame: str = "gyrowheel",
    ) -> None:
        self.joints, self.payload_frame = tuple(joints), payload_frame
        self.actual = _load_yourdfpy(urdf_path)
        self.nominal = _load_yourdfpy(nominal_urdf_path or default_urdf_path())
        for urdf in (self.actual, self.nominal):
            for joint in self.joints:
                if joint not in urdf.joint_map:
                    raise ModelError(f"URDF has no joint '{joint}'")

    def _pose(self, urdf, angles_rad) -> np.ndarray:
        urdf.update_cfg(dict(zip(self.joints, angles_rad, strict=True)))
        return urdf.get_transform(self.payload_frame, urdf.base_link)

    def orientation_error_matrix(self, *angles_rad: float) -> np.ndarray:
        """``dR = Rd^T Rt`` at joint angles (from the base), radians."""
        rt = self._pose(self.actual, angles_rad)[:3, :3]
        rd = self._pose(self.nominal, angles_rad)[:3, :3]
        return rd.T @ rt

    def payload_origin_m(self, *angles_rad: float) -> np.ndarray:
        """Actual payload origin in the base frame, metres."""
        return self._pose(self.actual, angles_rad)[:3, 3].copy()
