"""turntable-pin: error analysis, error allocation and measurement diagnosis of two-axis turntables.

The turntable is a URDF whose joint placements carry its errors; Pinocchio computes the payload
orientation and the orientation error ``dR = Rd^T Rt``. Angles are radians and lengths metres inside
the package; names carry the unit where it is not radians.

The public API below is what a user scripts with, layer by layer (the CLI uses the same calls):
the error model (``TurntableErrors``, ``TurntableModel``, ``OrientationErrorField``), the GyroWheel
calibration layer (``GyroWheelModel``, ``PositionSet``, ``calibrate_run``, ``rate_error``,
``orientation_requirement``), the allocation layer (``allocate_tolerances``,
``average_sensitivities``, ``run_monte_carlo``), the measurement layer (``read_measurements``,
``simulate_measurements``, ``fit_orientation``, ``diagnose_measurements``, ``write_report``) and the
viewer (``SetupScene``, ``render_snapshot``). Everything else lives in its module.
"""

from .allocation import (
    Allocation,
    OrientationLimits,
    allocate_tolerances,
    default_orientation_limits,
    paper_eq16_limits,
)
from .batch_evaluation import OrientationErrorField
from .calibration import CalibrationResult, calibrate, calibrate_run
from .diagnosis import Diagnosis
from .effects import EFFECT_NAMES, EFFECTS, Effect
from .error_parameters import ANGULAR_ERROR_NAMES, ERROR_NAMES, TurntableErrors
from .exceptions import (
    IdentifiabilityError,
    InfeasibleError,
    InputError,
    ModelError,
    TurntablePinError,
)
from .gyrowheel_model import GyroWheelModel
from .least_squares_fit import FitResult
from .manufacturing_capability import ManufacturingCapability
from .measurements import OrientationMeasurements, read_measurements
from .monte_carlo import MonteCarloResult, plot_monte_carlo, run_monte_carlo
from .orientation_diagnosis import diagnose_measurements
from .orientation_fit import OrientationFit, fit_orientation
from .orientation_model import OrientationModel
from .orientation_requirement import OrientationRequirement, orientation_requirement
from .rate_error import RateErrorResult, rate_error
from .report_html import write_report
from .scene import Exaggeration, SetupScene
from .sensitivity import (
    AverageSensitivities,
    average_sensitivities,
    plot_sensitivities,
    sensitivity_matrix,
)
from .simulation import SimulatedMeasurements, simulate_measurements
from .small_angle import small_angle_matrix, small_angle_orientation_error
from .snapshot import render_snapshot
from .test_positions import PositionSet, position_inputs
from .turntable_model import OrientationError, TurntableModel, default_urdf_path
from .urdf_io import YourdfpyTurntable

__all__ = [
    "ANGULAR_ERROR_NAMES",
    "Allocation",
    "AverageSensitivities",
    "CalibrationResult",
    "Diagnosis",
    "EFFECTS",
    "EFFECT_NAMES",
    "ERROR_NAMES",
    "Effect",
    "Exaggeration",
    "FitResult",
    "GyroWheelModel",
    "IdentifiabilityError",
    "InfeasibleError",
    "InputError",
    "ManufacturingCapability",
    "ModelError",
    "MonteCarloResult",
    "OrientationError",
    "OrientationErrorField",
    "OrientationFit",
    "OrientationLimits",
    "OrientationMeasurements",
    "OrientationModel",
    "OrientationRequirement",
    "PositionSet",
    "RateErrorResult",
    "SetupScene",
    "SimulatedMeasurements",
    "TurntableErrors",
    "TurntableModel",
    "TurntablePinError",
    "YourdfpyTurntable",
    "allocate_tolerances",
    "average_sensitivities",
    "calibrate",
    "calibrate_run",
    "default_orientation_limits",
    "default_urdf_path",
    "diagnose_measurements",
    "fit_orientation",
    "orientation_requirement",
    "paper_eq16_limits",
    "plot_monte_carlo",
    "plot_sensitivities",
    "position_inputs",
    "rate_error",
    "read_measurements",
    "render_snapshot",
    "run_monte_carlo",
    "sensitivity_matrix",
    "simulate_measurements",
    "small_angle_matrix",
    "small_angle_orientation_error",
    "write_report",
]

__version__ = "0.1.0"
