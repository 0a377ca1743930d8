"""The GyroWheel calibration layer (paper section 2): drift model (eq. 1), test positions,
multi-position least-squares calibration, rate error from an orientation error (eqs. 8-13), and
the orientation requirement (eq. 16: the paper's planes, and the largest box that holds).
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "CalibrationResult": "drift_fit",
    "GyroWheelModel": "gyrowheel",
    "OrientationRequirement": "requirement",
    "PositionSet": "positions",
    "RateErrorResult": "rate_error",
    "RequirementBox": "requirement",
    "calibrate": "drift_fit",
    "calibrate_run": "drift_fit",
    "orientation_requirement": "requirement",
    "position_inputs": "positions",
    "rate_error": "rate_error",
    "requirement_box": "requirement",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
