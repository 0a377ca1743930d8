"""URDF files with the turntable errors written into their joint ``<origin>``s, via yourdfpy.

yourdfpy is also a second, independent forward-kinematics library: :class:`YourdfpyTurntable`
evaluates the same orientation error from a URDF without Pinocchio, for cross-checks.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError, ModelError
from ..core.files import write_atomic
from .chain import ErrorChain
from .paper_table import INNER_JOINT, OUTER_JOINT, PAYLOAD_FRAME, PAYLOAD_MOUNT

__all__ = ["YourdfpyTurntable", "write_error_urdf"]


def _load_yourdfpy(path: str | Path):
    import yourdfpy

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
    """Write the nominal URDF ``urdf_path`` with ``chain``'s error transforms in its joint origins.

    Args:
        urdf_path: the nominal URDF (never overwritten).
        chain: the error chain read off that URDF.
        error_values: the errors in ``chain.error_names`` order (rad, m).
        path: the output file, written atomically.
    """
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
    """Orientation error of a URDF turntable computed with yourdfpy (independent of Pinocchio).

    Args:
        urdf_path: the URDF with errors in its placements.
        nominal_urdf_path: the URDF giving the ideal orientation (default: the same joints with
            identity error, i.e. ``urdf_path`` is compared with the bundled nominal file).
    """

    def __init__(self, urdf_path: str | Path, nominal_urdf_path: str | Path | None = None) -> None:
        from ..core.resources import default_urdf_path

        self.actual = _load_yourdfpy(urdf_path)
        self.nominal = _load_yourdfpy(nominal_urdf_path or default_urdf_path())
        for urdf in (self.actual, self.nominal):
            for joint in (OUTER_JOINT, INNER_JOINT, PAYLOAD_MOUNT):
                if joint not in urdf.joint_map:
                    raise ModelError(f"URDF has no joint '{joint}'")

    def _pose(self, urdf, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        urdf.update_cfg({OUTER_JOINT: phi1_rad, INNER_JOINT: phi2_rad})
        return urdf.get_transform(PAYLOAD_FRAME, urdf.base_link)

    def orientation_error_matrix(self, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        """``dR = Rd^T Rt`` at (phi1, phi2), radians."""
        rt = self._pose(self.actual, phi1_rad, phi2_rad)[:3, :3]
        rd = self._pose(self.nominal, phi1_rad, phi2_rad)[:3, :3]
        return rd.T @ rt

    def payload_origin_m(self, phi1_rad: float, phi2_rad: float) -> np.ndarray:
        """Actual payload origin in the base frame, metres."""
        return self._pose(self.actual, phi1_rad, phi2_rad)[:3, 3].copy()
