"""The GyroWheel mounted askew on the payload: a constant rotation between their axes.

Two effects, because the runs see them very differently: the tilt about the payload x and y
axes (``instrument_tilt``) shows through the earth rate and the az*ax, az*ay terms, while the
heading about z (``instrument_heading``) shows only through the earth rate's north component
(on a 30-degree grid of the paper's table its correlation with the coefficients is 0.97, so it
would make a three-angle mounting effect undetermined whenever only a tilt is there)."""

from __future__ import annotations

import numpy as np

from ...measurement.effects.base import ARCSEC
from ...model.errors import MAX_ANGULAR_ERROR_DEG
from .base import INSTRUMENT, ParameterSpec, RunContext, RunEffect, Sensed, plausible

__all__ = ["InstrumentHeading", "InstrumentTilt", "Mount"]


class Mount(RunEffect):
    """A constant rotation of the GyroWheel's axes against the payload's about some of the
    payload axes (``axes``), small angles in arcsec. A simulated run turns what the GyroWheel
    senses by it (``M = exp([m]x)``, m = (mx, my, mz) of every mount effect), adding nothing
    else."""

    axes: tuple[str, ...] = ()
    side = INSTRUMENT
    limit = MAX_ANGULAR_ERROR_DEG * 3600.0

    @property
    def plausibility(self):
        """Its rotation, mounted at most 2 deg askew (``docs/plausibility.md``)."""
        names = tuple(f"m{axis}" for axis in self.axes)
        return (plausible(names, "a GyroWheel mounted {amplitude} askew", any_machine=7200),)

    def parameters(self, run) -> tuple[ParameterSpec, ...]:
        """This effect's parameters on ``run`` (their user units and scales)."""
        return tuple(
            ParameterSpec(f"m{axis}", "arcsec", ARCSEC, f"mounting rotation about payload {axis}")
            for axis in self.axes
        )

    def columns(self, context: RunContext) -> np.ndarray:
        """``d(out_x, out_y)/d(parameter)`` at each position, (N, 2, p), deg/h per internal unit."""
        # The sensitivity's columns are (dpsi, dtheta, dgamma) = rotations about (y, z, x).
        order = {"x": 2, "y": 0, "z": 1}
        return np.ascontiguousarray(context.sensitivity[:, :, [order[a] for a in self.axes]])

    def planted_dph(self, values: dict[str, float], sensed: Sensed) -> np.ndarray:
        """Nothing besides the turn of what is sensed (class docstring): zeros (N, 2)."""
        return np.zeros((sensed.time_s.size, 2))


class InstrumentTilt(Mount):
    """``a -> a Ry(my) Rx(mx)`` and the same for the earth rate: the instrument's axes are
    tilted from the payload's about the payload x and y axes."""

    name = "instrument_tilt"
    axes = ("x", "y")
    title = "the GyroWheel mounted tilted on the payload"
    definition = (
        "the sensed a and w are turned by Ry(my) Rx(mx) (arcsec) at every position: the same "
        "tilt in the instrument's frame wherever the table is"
    )
    explanation = (
        "The GyroWheel's sensing axes are not parallel to the payload frame the positions are "
        "computed in (a tilted mounting face, a shim, a burr under a foot). Its gravity part "
        "mostly moves the outputs like the g-coefficients themselves, which the calibration "
        "absorbs; what stays is the earth rate seen along the tilted axes and the cross terms "
        "az*ax, az*ay that the squared terms make of a tilted gravity vector."
    )
    confirm = (
        "Measure the instrument's reference faces against the payload's with an autocollimator "
        "or an electronic level, or remount it turned by 180 degrees about its z axis and "
        "calibrate again: a mounting tilt changes sign in the payload frame, a table error "
        "does not."
    )


class InstrumentHeading(Mount):
    """``a -> a Rz(mz)`` and the same for the earth rate: the instrument is turned about the
    payload z axis (its heading on the mounting face)."""

    name = "instrument_heading"
    axes = ("z",)
    title = "the GyroWheel turned on its mounting face (heading)"
    definition = "the sensed a and w are turned by Rz(mz) (arcsec) at every position"
    explanation = (
        "The GyroWheel sits turned about the payload's z axis: the dowel pins or the flange "
        "holes leave it a small heading error. Gravity's part is absorbed by the coefficients "
        "(it only mixes the x and y terms); only the north component of the earth rate seen "
        "along the turned x and y axes shows it, so it needs many positions to be seen."
    )
    confirm = (
        "Measure the heading of the instrument's reference face on the payload (theodolite "
        "or autocollimator against a mirror cube), or remount it turned by 90 degrees about z."
    )
