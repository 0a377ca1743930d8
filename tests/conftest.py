"""Shared fixtures: seeded random error sets of realistic and of large magnitude."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin import TurntableErrors
from turntable_pin.core.units import arcsec_to_rad


def random_errors(rng: np.random.Generator, scale_arcsec: float = 10.0) -> TurntableErrors:
    """Eight angular errors uniform in +-scale_arcsec and deta uniform in +-0.5 mm."""
    angles = arcsec_to_rad(rng.uniform(-scale_arcsec, scale_arcsec, 8))
    return TurntableErrors.from_array(np.append(angles, rng.uniform(-5e-4, 5e-4)))


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)
