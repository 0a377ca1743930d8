"""The measurement layer: the orientation-measurement CSV, the simulator, the effect catalogue,
the fit of the error model with effects, residual analysis and the diagnosis of missing effects.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "EFFECTS": "effects",
    "EFFECT_NAMES": "effects",
    "Effect": "effects",
    "OrientationFit": "fit",
    "OrientationMeasurements": "data",
    "OrientationModel": "effect_model",
    "SimulatedMeasurements": "simulation",
    "diagnose_measurements": "diagnosis",
    "fit_orientation": "fit",
    "read_measurements": "data",
    "simulate_measurements": "simulation",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
