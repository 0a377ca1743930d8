"""turntable-pin: error analysis, error allocation and measurement diagnosis of two-axis turntables.

The turntable is a URDF whose joint placements carry its errors; Pinocchio computes the payload
orientation and the orientation error ``dR = Rd^T Rt``. Angles are radians and lengths metres inside
the package; names carry the unit where it is not radians.
"""

from .allocation import (
    Allocation,
    OrientationLimits,
    allocate_tolerances,
    default_orientation_limits,
    paper_eq16_limits,
    worst_case_full_circle,
)
from .batch_evaluation import OrientationErrorField, trig_basis
from .browser import (
    BrowserError,
    BrowserNotFoundError,
    ImageLoadReport,
    check_page_images,
    chromium_available,
)
from .calibration import AxisCalibration, CalibrationResult, calibrate, calibrate_run
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
from .gyrowheel_model import DriftCoefficients, GyroWheelModel, regressor_matrix
from .least_squares_fit import FitResult, fit_least_squares
from .manufacturing_capability import ManufacturingCapability
from .measurements import OrientationMeasurements, read_measurements
from .meshcat_server import MeshcatMissingError, MeshcatServer, MeshcatServerError
from .monte_carlo import MonteCarloResult, plot_monte_carlo, run_monte_carlo
from .orientation_diagnosis import OrientationFamily, diagnose_measurements
from .orientation_fit import OrientationFit, fit_orientation
from .orientation_model import OrientationModel
from .orientation_requirement import OrientationRequirement, orientation_requirement
from .rate_error import RateErrorResult, orientation_error_rotation, rate_error, rate_errors_dph
from .report_html import write_report
from .residual_analysis import analyse_residuals, orientation_residuals
from .scene import Exaggeration, SetupScene
from .sensitivity import (
    AverageSensitivities,
    average_sensitivities,
    plot_sensitivities,
    sensitivity_matrix,
    sensitivity_matrix_fd,
)
from .simulation import Schedule, SimulatedMeasurements, simulate_measurements
from .small_angle import small_angle_matrix, small_angle_orientation_error, small_angle_rotation
from .snapshot import SnapshotResult, render_snapshot
from .test_positions import EARTH_RATE_DPH, PositionInputs, PositionSet, position_inputs
from .turntable_model import OrientationError, TurntableModel, default_urdf_path, error_placements
from .urdf_io import YourdfpyTurntable, write_error_urdf

__all__ = [
    "ANGULAR_ERROR_NAMES",
    "Allocation",
    "AverageSensitivities",
    "AxisCalibration",
    "BrowserError",
    "BrowserNotFoundError",
    "CalibrationResult",
    "Diagnosis",
    "DriftCoefficients",
    "EARTH_RATE_DPH",
    "EFFECTS",
    "EFFECT_NAMES",
    "ERROR_DESCRIPTIONS",
    "ERROR_NAMES",
    "Effect",
    "Exaggeration",
    "FitResult",
    "GyroWheelModel",
    "IdentifiabilityError",
    "ImageLoadReport",
    "InfeasibleError",
    "InputError",
    "ManufacturingCapability",
    "MeshcatMissingError",
    "MeshcatServer",
    "MeshcatServerError",
    "ModelError",
    "MonteCarloResult",
    "OrientationError",
    "OrientationErrorField",
    "OrientationFamily",
    "OrientationFit",
    "OrientationLimits",
    "OrientationMeasurements",
    "OrientationModel",
    "OrientationRequirement",
    "PositionInputs",
    "PositionSet",
    "RateErrorResult",
    "Schedule",
    "SetupScene",
    "SimulatedMeasurements",
    "SnapshotResult",
    "TurntableErrors",
    "TurntableModel",
    "TurntablePinError",
    "YourdfpyTurntable",
    "allocate_tolerances",
    "analyse_residuals",
    "average_sensitivities",
    "calibrate",
    "calibrate_run",
    "check_page_images",
    "chromium_available",
    "default_orientation_limits",
    "default_urdf_path",
    "diagnose",
    "diagnose_measurements",
    "error_placements",
    "fit_least_squares",
    "fit_orientation",
    "get_effect",
    "orientation_error_rotation",
    "orientation_requirement",
    "orientation_residuals",
    "paper_eq16_limits",
    "plot_monte_carlo",
    "plot_sensitivities",
    "position_inputs",
    "rate_error",
    "rate_errors_dph",
    "read_measurements",
    "regressor_matrix",
    "render_snapshot",
    "run_monte_carlo",
    "sensitivity_matrix",
    "sensitivity_matrix_fd",
    "simulate_measurements",
    "small_angle_matrix",
    "small_angle_orientation_error",
    "small_angle_rotation",
    "trig_basis",
    "worst_case_full_circle",
    "write_error_urdf",
    "write_report",
]

__version__ = "0.1.0"
