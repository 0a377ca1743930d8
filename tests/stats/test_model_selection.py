"""The model-selection helpers against independent constructions."""

from __future__ import annotations

import numpy as np
import pytest

from turntable_pin.stats.model_selection import _projected_rss, acceptance_threshold


def test_acceptance_threshold_is_the_look_elsewhere_penalty():
    assert acceptance_threshold(1) == -6.0
    assert acceptance_threshold(9) == pytest.approx(-6.0 - 2.0 * np.log(9.0))


def test_projected_rss_equals_a_qr_projection_and_counts_the_rank():
    rng = np.random.default_rng(3)
    a = rng.normal(size=(300, 4)) * [1e-3, 1.0, 50.0, 2.0]  # columns of any scale
    b = np.concatenate([a[:, :1] + a[:, 1:2], rng.normal(size=(300, 2))], axis=1)  # one dependent
    r = rng.normal(size=(300, 3))
    q, _ = np.linalg.qr(np.concatenate([a, b[:, 1:]], axis=1))
    left = r - q @ (q.T @ r)
    rss, rank = _projected_rss(r, [a, b])
    assert rank == 6
    assert rss == pytest.approx(float(np.sum(left**2)), rel=1e-9)
    assert _projected_rss(r[:, 0], [a, b])[0] == pytest.approx(float(left[:, 0] @ left[:, 0]))
