"""Foundations every layer uses: units, rotations, exceptions, file and CSV I/O, progress, lazy
names.

Nothing here knows turntables; nothing here imports another layer of the package.
"""

from .lazy import lazy_exports

_EXPORTS = {
    "IdentifiabilityError": "exceptions",
    "InfeasibleError": "exceptions",
    "InputError": "exceptions",
    "ModelError": "exceptions",
    "TurntablePinError": "exceptions",
}

__all__ = sorted(_EXPORTS)
__getattr__, __dir__ = lazy_exports(__name__, _EXPORTS)
