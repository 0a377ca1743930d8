"""What to measure next: test positions that identify, separate and calibrate.

From a table's URDF, the effects to identify and the joints' limits, a design chooses the
positions of the next measurement run:

- :mod:`.space`: the joints' limits, the candidate positions within them and the 30-degree grid;
- :mod:`.identify`: D-optimal positions for the identifiable combinations of the base errors and
  the chosen effects (greedy start and Fedorov exchange, :mod:`turntable_pin.stats.design`);
- :mod:`.separate`: T-optimal positions that tell two effects apart, with the chance that the
  diagnosis names the right one (:mod:`turntable_pin.stats.discrimination`), or why none do;
- :mod:`.calibrate`: GyroWheel calibration positions with the loosest orientation requirement
  (the largest box that holds) at the precision of the grid of the same number of positions;
- :mod:`.schedule`: the order, times and approach directions of the chosen positions (repeats
  for time-driven effects, both sides for backlash) and the CSV that the simulation and the
  test crew read.

Called, the package is the flat API's design: ``turntable_pin.design(table, n_positions, ...)`` is
:func:`turntable_pin.api.design` (its docstring gives the arguments).
"""

from ..core.lazy import lazy_exports

_EXPORTS = {
    "CalibrationDesign": "calibrate",
    "DesignSpace": "space",
    "IdentifyDesign": "identify",
    "MeasurementPlan": "schedule",
    "SeparationDesign": "separate",
    "design_calibration": "calibrate",
    "design_identify": "identify",
    "design_separate": "separate",
    "design_space": "space",
    "parse_limits_deg": "space",
    "plan_measurements": "schedule",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
