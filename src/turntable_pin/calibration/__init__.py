"""The GyroWheel calibration layer (paper section 2): drift model (eq. 1), test positions,
multi-position least-squares calibration, rate error from an orientation error (eqs. 8-13), and
the orientation requirement (eq. 16).
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "JointPositions": "positions",
    "CalibrationResult": "drift_fit",
    "GyroWheelModel": "gyrowheel",
    "OrientationRequirement": "requirement",
    "PositionSet": "positions",
    "RateErrorResult": "rate_error",
    "calibrate": "drift_fit",
    "calibrate_run": "drift_fit",
    "orientation_requirement": "requirement",
    "position_inputs": "positions",
    "rate_error": "rate_error",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
