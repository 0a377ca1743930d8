"""turntable-pin: error analysis, error allocation and measurement diagnosis of two-axis turntables.

The turntable is a URDF whose joint placements carry its errors; Pinocchio computes the orientation
error ``dR = Rd^T Rt``. Inside, angles are radians and lengths metres; names carry other units.
The flat API (:mod:`turntable_pin.api`) is the way in: ``tp.load_table``, ``tp.read_measurements``,
``tp.simulate``, ``tp.fit``, ``tp.diagnose``, ``tp.design``, ``tp.allocate``, ``tp.calibrate``,
``tp.import_tpoint``; below it, the public classes and functions a user scripts with, layer by
layer (the CLI makes the same calls); everything else lives in its module.
"""

import types
from typing import TYPE_CHECKING

from . import design as _design_package  # light: its names are lazy
from .core.lazy import lazy_exports

_EXPORTS = {
    "allocate": "api",
    "calibrate": "api",
    "diagnose": "api",
    "fit": "api",
    "import_tpoint": "api",
    "load_table": "api",
    "read_measurements": "api",
    "simulate": "api",
    "ANGULAR_ERROR_NAMES": "model.errors",
    "Allocation": "allocation.solver",
    "CalibrationResult": "calibration.drift_fit",
    "Diagnosis": "stats.model_selection",
    "EFFECTS": "measurement.effects",
    "EFFECT_NAMES": "measurement.effects",
    "ERROR_NAMES": "model.errors",
    "Effect": "measurement.effects",
    "Exaggeration": "viewer.scene",
    "FitResult": "stats.least_squares",
    "GyroWheelModel": "calibration.gyrowheel",
    "IdentifiabilityError": "core.exceptions",
    "InfeasibleError": "core.exceptions",
    "InputError": "core.exceptions",
    "ManufacturingCapability": "allocation.capability",
    "ModelError": "core.exceptions",
    "MonteCarloResult": "allocation.monte_carlo",
    "OrientationError": "model.generic_table",
    "OrientationErrorField": "model.batch_field",
    "OrientationFit": "measurement.fit",
    "OrientationLimits": "allocation.solver",
    "OrientationMeasurements": "measurement.data",
    "OrientationModel": "measurement.effect_model",
    "OrientationRequirement": "calibration.requirement",
    "PositionSet": "calibration.positions",
    "RateErrorResult": "calibration.rate_error",
    "Schedule": "measurement.simulation",
    "Sensitivities": "allocation.sensitivity",
    "SetupScene": "viewer.scene",
    "SimulatedMeasurements": "measurement.simulation",
    "TurntableErrors": "model.errors",
    "TurntablePinError": "core.exceptions",
    "UserCodeError": "core.exceptions",
    "YourdfpyTurntable": "model.urdf_io",
    "average_sensitivities": "allocation.sensitivity",
    "default_orientation_limits": "allocation.solver",
    "default_urdf_path": "core.resources",
    "orientation_requirement": "calibration.requirement",
    "paper_eq16_limits": "allocation.solver",
    "plot_monte_carlo": "report.allocation_figures",
    "plot_sensitivities": "report.allocation_figures",
    "position_inputs": "calibration.positions",
    "rate_error": "calibration.rate_error",
    "render_snapshot": "viewer.snapshot",
    "run_monte_carlo": "allocation.monte_carlo",
    "sensitivity_matrix": "allocation.sensitivity",
    "small_angle_matrix": "model.small_angle",
    "small_angle_orientation_error": "model.small_angle",
    "write_report": "report.html_report",
}

__all__ = sorted([*_EXPORTS, "design"])
_export, __dir__ = lazy_exports(__name__, _EXPORTS)


class _DesignPackage(types.ModuleType):
    """The subpackage ``turntable_pin.design``, callable as the flat API's
    :func:`turntable_pin.api.design`: ``tp.design(table, 12, effects=...)`` (one name, whether
    or not the subpackage was imported before)."""

    def __call__(self, *args, **kwargs):
        from .api import design

        return design(*args, **kwargs)


_design_package.__class__ = _DesignPackage


def __getattr__(name: str):
    """A public name, imported on first use; ``__version__`` read from the metadata then."""
    if name == "__version__":
        return _version()
    return _export(name)


def _version() -> str:
    """The installed distribution's version (one version: ``pyproject.toml``'s, read from the
    metadata on use: importlib.metadata costs a few hundredths of a second at start-up)."""
    from importlib import metadata

    try:
        return metadata.version("turntable-pin")
    except metadata.PackageNotFoundError:  # a source tree on the path, not installed
        return "0+unknown"


if TYPE_CHECKING:  # names for static checkers; nothing is imported at run time
    from .allocation.capability import ManufacturingCapability  # noqa: F401
    from .allocation.monte_carlo import MonteCarloResult, run_monte_carlo  # noqa: F401
    from .allocation.sensitivity import (  # noqa: F401
        Sensitivities,
        average_sensitivities,
        sensitivity_matrix,
    )
    from .allocation.solver import (  # noqa: F401
        Allocation,
        OrientationLimits,
        default_orientation_limits,
        paper_eq16_limits,
    )
    from .api import (  # noqa: F401
        allocate,
        calibrate,
        diagnose,
        fit,
        import_tpoint,
        load_table,
        read_measurements,
        simulate,
    )
    from .calibration.drift_fit import CalibrationResult  # noqa: F401
    from .calibration.gyrowheel import GyroWheelModel  # noqa: F401
    from .calibration.positions import PositionSet, position_inputs  # noqa: F401
    from .calibration.rate_error import RateErrorResult, rate_error  # noqa: F401
    from .calibration.requirement import OrientationRequirement, orientation_requirement  # noqa: F401
    from .core.exceptions import (  # noqa: F401
        IdentifiabilityError,
        InfeasibleError,
        InputError,
        ModelError,
        TurntablePinError,
        UserCodeError,
    )
    from .core.resources import default_urdf_path  # noqa: F401
    from .measurement.data import OrientationMeasurements  # noqa: F401
    from .measurement.effect_model import OrientationModel  # noqa: F401
    from .measurement.effects import EFFECT_NAMES, EFFECTS, Effect  # noqa: F401
    from .measurement.fit import OrientationFit  # noqa: F401
    from .measurement.simulation import Schedule, SimulatedMeasurements  # noqa: F401
    from .model.batch_field import OrientationErrorField  # noqa: F401
    from .model.errors import ANGULAR_ERROR_NAMES, ERROR_NAMES, TurntableErrors  # noqa: F401
    from .model.generic_table import OrientationError  # noqa: F401
    from .model.small_angle import small_angle_matrix, small_angle_orientation_error  # noqa: F401
    from .model.urdf_io import YourdfpyTurntable  # noqa: F401
    from .report.allocation_figures import plot_monte_carlo, plot_sensitivities  # noqa: F401
    from .report.html_report import write_report  # noqa: F401
    from .stats.least_squares import FitResult  # noqa: F401
    from .stats.model_selection import Diagnosis  # noqa: F401
    from .viewer.scene import Exaggeration, SetupScene  # noqa: F401
    from .viewer.snapshot import render_snapshot  # noqa: F401
