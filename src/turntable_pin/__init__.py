"""turntable-pin: error analysis, error allocation and measurement diagnosis of two-axis turntables.

The turntable is a URDF whose joint placements carry its errors; Pinocchio computes the payload
orientation and the orientation error ``dR = Rd^T Rt``. Angles are radians and lengths metres inside
the package; names carry the unit where it is not radians.
"""

from .batch_evaluation import OrientationErrorField, trig_basis
from .diagnosis import Diagnosis, diagnose
from .effects import EFFECT_NAMES, EFFECTS, Effect, get_effect
from .error_parameters import (
    ANGULAR_ERROR_NAMES,
    ERROR_DESCRIPTIONS,
    ERROR_NAMES,
    TurntableErrors,
)
from .exceptions import (
    IdentifiabilityError,
    InfeasibleError,
    InputError,
    ModelError,
    TurntablePinError,
)
from .least_squares_fit import FitResult, fit_least_squares
from .measurements import OrientationMeasurements, read_measurements
from .orientation_diagnosis import OrientationFamily, diagnose_measurements
from .orientation_fit import OrientationFit, fit_orientation
from .orientation_model import OrientationModel
from .report_html import write_report
from .residual_analysis import analyse_residuals, orientation_residuals
from .simulation import Schedule, SimulatedMeasurements, simulate_measurements
from .small_angle import small_angle_matrix, small_angle_orientation_error, small_angle_rotation
from .turntable_model import OrientationError, TurntableModel, default_urdf_path, error_placements
from .urdf_io import YourdfpyTurntable, write_error_urdf

__all__ = [
    "ANGULAR_ERROR_NAMES",
    "EFFECT_NAMES",
    "EFFECTS",
    "ERROR_DESCRIPTIONS",
    "ERROR_NAMES",
    "analyse_residuals",
    "default_urdf_path",
    "diagnose",
    "diagnose_measurements",
    "Diagnosis",
    "Effect",
    "error_placements",
    "fit_least_squares",
    "fit_orientation",
    "FitResult",
    "get_effect",
    "IdentifiabilityError",
    "InfeasibleError",
    "InputError",
    "ModelError",
    "orientation_residuals",
    "OrientationError",
    "OrientationErrorField",
    "OrientationFamily",
    "OrientationFit",
    "OrientationMeasurements",
    "OrientationModel",
    "read_measurements",
    "Schedule",
    "simulate_measurements",
    "SimulatedMeasurements",
    "small_angle_matrix",
    "small_angle_orientation_error",
    "small_angle_rotation",
    "trig_basis",
    "TurntableErrors",
    "TurntableModel",
    "TurntablePinError",
    "write_error_urdf",
    "write_report",
    "YourdfpyTurntable",
]

__version__ = "0.1.0"
