"""The command line's words for the library's texts (:mod:`turntable_pin.core.words`): its
program name, and each Python argument whose flag is not ``--`` + its name with ``-`` for ``_``."""

from __future__ import annotations

from ..core.words import CommandLineWords

__all__ = ["CLI_WORDS"]

CLI_WORDS = CommandLineWords(
    "turntable-pin",
    {
        "amplitudes": "--amplitude",
        "from_data": "--from",
        "n": "-n",
        "n_positions": "-n",
        "outliers=False": "--keep-outliers",
        "temperature_c": "--temperature",
        "turntable": "--urdf",
    },
)
