"""The sensitivity and error-allocation layer (paper section 4): sensitivities (eq. 28),
manufacturing capability, the allocation optimisation (eqs. 31-34, Lemma 1) and the Monte Carlo
check.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "Sensitivities": "sensitivity",
    "Allocation": "solver",
    "ManufacturingCapability": "capability",
    "MonteCarloResult": "monte_carlo",
    "run_chain_monte_carlo": "monte_carlo",
    "OrientationLimits": "solver",
    "allocate_tolerances": "solver",
    "average_sensitivities": "sensitivity",
    "default_orientation_limits": "solver",
    "paper_eq16_limits": "solver",
    "run_monte_carlo": "monte_carlo",
    "sensitivity_matrix": "sensitivity",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
