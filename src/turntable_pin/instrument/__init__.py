"""Is it the table or the instrument? The diagnosis of a GyroWheel calibration run.

The measurement layer's loop (see where the model fails, name the missing effect, add it, watch
the error fall) on the instrument's outputs. The base model is eq. 1's 2 x 7 drift coefficients.

- :mod:`.effects`: the candidates: the table's errors and effects through eqs. 7-14, and the
  instrument's own (mounting, bias drift, temperature, earth-rate scale, g-squared terms);
- :mod:`.sensitivity`: the outputs' change with the payload's orientation error (eqs. 8-13);
- :mod:`.model`: the run's model (the 14 coefficients plus effects) and its fit;
- :mod:`.diagnosis`: the run's family of the one diagnosis, and ``diagnose_run``;
- :mod:`.table_errors`: which combinations of the table's errors the run determines;
- :mod:`.simulate`: calibration runs with hidden table errors and instrument effects.
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "RunEffect": "effects.base",
    "RunFamily": "diagnosis",
    "RunFit": "model",
    "RunModel": "model",
    "SimulatedRun": "simulate",
    "TemperatureProfile": "simulate",
    "TableFromRun": "table_errors",
    "diagnose_run": "diagnosis",
    "fit_run": "model",
    "rate_sensitivity_dph": "sensitivity",
    "run_catalogue": "effects",
    "simulate_calibration_run": "simulate",
    "table_from_run": "table_errors",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
