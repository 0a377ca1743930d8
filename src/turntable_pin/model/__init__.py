"""The turntable error model: error parameters, the URDF, Pinocchio forward kinematics, the batch
trigonometric field and the small-angle model (eq. 26).

Data flows down from here: the calibration, allocation and measurement layers read this one.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "ANGULAR_ERROR_NAMES": "errors",
    "ERROR_NAMES": "errors",
    "OrientationError": "generic_table",
    "OrientationErrorField": "batch_field",
    "TurntableErrors": "errors",
    "YourdfpyTurntable": "urdf_io",
    "small_angle_matrix": "small_angle",
    "small_angle_orientation_error": "small_angle",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
