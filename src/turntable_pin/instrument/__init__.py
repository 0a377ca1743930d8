"""Is it the table or the instrument? The diagnosis of a GyroWheel calibration run.

The measurement layer's loop (see where the model fails, name the missing physical effect, add
it, watch the error fall) brought to the instrument's own outputs. The base model is the
calibration of paper eq. 1: 2 x 7 drift coefficients, the outputs the earth rate plus the drift
at the ideal orientation. The candidates are plug-ins on both sides:

- :mod:`.effects`: the table's errors and effects propagated through eqs. 7-14 (any table, from
  its URDF), and the instrument's own: its mounting misalignment on the payload, a bias drift
  with time, a temperature coefficient, a scale factor on the earth-rate term, the g-squared
  terms eq. 1 leaves out;
- :mod:`.sensitivity`: how the two outputs change with the payload's orientation error
  (eqs. 8-13 to first order) and the drift regressor of both axes;
- :mod:`.model`: the run's model (the 14 coefficients plus effects), its fit and residuals;
- :mod:`.diagnosis`: the model family the generic diagnosis (:mod:`turntable_pin.stats`) runs
  on (outliers, noise per output channel, the structure search over the joint angles, time and
  extra columns), and :func:`~.diagnosis.diagnose_run`;
- :mod:`.table_errors`: which combinations of the table's errors the run's outputs determine,
  and which it cannot tell from the instrument's coefficients;
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
    "temperature_profile": "simulate",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
