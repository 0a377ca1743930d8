"""Python effect modules as a user might write them, good or broken: the text of a module of one
orientation effect (``Lobes``, an ``Effect``) or one run effect (``CableDrag``, a ``RunEffect``)
with the method bodies given. Shared by the contract tests, the command-line tests and the fuzz
tests of user effects."""

ORIENTATION_MODULE = """\
import numpy as np

from turntable_pin.measurement.effects.base import ARCSEC, ChainTerm, Effect, ParameterSpec


class Lobes(Effect):
    name = "{name}"
    title = "three-lobed inner encoder"

    def parameters(self, variables):
        {parameters}

    def chain_terms(self, variables):
        a = variables.angle(2)
        {terms}
"""
ORIENTATION_PARAMETERS = (
    'return (ParameterSpec("c3", "arcsec", ARCSEC, "c"), ParameterSpec("s3", "arcsec", ARCSEC, '
    '"s"))'
)
"""``Lobes.parameters``: two parameters, c3 and s3 (arcsec)."""
ORIENTATION_TERMS = (
    'return (ChainTerm("dphi_z2", None, {"c3": np.cos(3 * a), "s3": np.sin(3 * a)}),)'
)
"""``Lobes.chain_terms``: a 3/rev harmonic of dphi_z2 in phi2."""


def orientation_module(
    parameters: str = ORIENTATION_PARAMETERS, terms: str = ORIENTATION_TERMS, name: str = "lobes"
) -> str:
    """A module of one orientation effect, ``Lobes``, with these method bodies (one line each,
    or lines indented by 8 spaces after the first)."""
    return ORIENTATION_MODULE.format(name=name, parameters=parameters, terms=terms)


RUN_MODULE = """\
import numpy as np

from turntable_pin.instrument.effects import RunEffect
from turntable_pin.instrument.effects.base import ParameterSpec


class CableDrag(RunEffect):
    name = "{name}"
    side = "{side}"
    title = "the slip-ring cable drags the inner frame"

    def parameters(self, run):
        {parameters}

    def columns(self, context):
        n = context.run.n_positions
        {columns}
"""
RUN_PARAMETERS = 'return (ParameterSpec("b", "deg/h", 1.0, "drag"),)'
"""``CableDrag.parameters``: one parameter, b (deg/h)."""
RUN_COLUMNS = (
    "out = np.zeros((n, 2, 1)); out[:, 0, 0] = np.sin(context.run.joint_rad[:, 1]); return out"
)
"""``CableDrag.columns``: out_x += b sin(phi2)."""


def run_module(
    parameters: str = RUN_PARAMETERS,
    columns: str = RUN_COLUMNS,
    name: str = "cable_drag",
    side: str = "table",
) -> str:
    """A module of one run effect, ``CableDrag``, with these method bodies."""
    return RUN_MODULE.format(name=name, side=side, parameters=parameters, columns=columns)
