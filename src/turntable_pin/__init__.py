"""turntable-pin: error analysis, error allocation and measurement diagnosis of two-axis turntables.

The turntable is a URDF whose joint placements carry its errors; Pinocchio computes the payload
orientation and the orientation error ``dR = Rd^T Rt``. Angles are radians and lengths metres inside
the package; names carry the unit where it is not radians.
"""

from .batch_evaluation import OrientationErrorField, trig_basis
from .browser import (
    BrowserError,
    BrowserNotFoundError,
    ImageLoadReport,
    check_page_images,
    chromium_available,
)
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
from .meshcat_server import MeshcatMissingError, MeshcatServer, MeshcatServerError
from .scene import Exaggeration, SetupScene
from .small_angle import small_angle_matrix, small_angle_orientation_error, small_angle_rotation
from .snapshot import SnapshotResult, render_snapshot
from .turntable_model import OrientationError, TurntableModel, default_urdf_path, error_placements
from .urdf_io import YourdfpyTurntable, write_error_urdf

__all__ = [
    "ANGULAR_ERROR_NAMES",
    "BrowserError",
    "BrowserNotFoundError",
    "ERROR_DESCRIPTIONS",
    "ERROR_NAMES",
    "Exaggeration",
    "IdentifiabilityError",
    "ImageLoadReport",
    "InfeasibleError",
    "InputError",
    "MeshcatMissingError",
    "MeshcatServer",
    "MeshcatServerError",
    "ModelError",
    "OrientationError",
    "OrientationErrorField",
    "SetupScene",
    "SnapshotResult",
    "TurntableErrors",
    "TurntableModel",
    "TurntablePinError",
    "YourdfpyTurntable",
    "check_page_images",
    "chromium_available",
    "default_urdf_path",
    "error_placements",
    "render_snapshot",
    "small_angle_matrix",
    "small_angle_orientation_error",
    "small_angle_rotation",
    "trig_basis",
    "write_error_urdf",
]

__version__ = "0.1.0"
