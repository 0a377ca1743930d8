"""Generic statistics: weighted least squares with identifiability, model selection by BIC and the
structure search over candidate terms.

Free of the names and units of any application: callers pass names, scales and unit labels in.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {"Diagnosis": "model_selection", "FitResult": "least_squares"}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
