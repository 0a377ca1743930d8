"""The test site: the latitude used when none is given (kept free of heavy imports, so the
command line can show it in its help without loading the model)."""

from __future__ import annotations

__all__ = ["DEFAULT_LATITUDE_DEG", "MAX_LATITUDE_DEG"]

DEFAULT_LATITUDE_DEG = 45.75
"""Latitude of the test site when none is given: Harbin, the paper's authors' city (an
assumption: the paper does not state its latitude), degrees."""

MAX_LATITUDE_DEG = 90.0
"""Largest ``|latitude|`` of a test site, degrees (the poles)."""
