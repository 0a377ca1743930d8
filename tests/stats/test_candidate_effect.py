"""The plausible scale of a candidate effect's parameters (``Plausibility``): the amplitude of a
group, the scale per machine kind, the sentence of what one would have to believe."""

from __future__ import annotations

import math

import pytest

from turntable_pin.stats.candidate_effect import ANY_MACHINE, CandidateEffect, Plausibility


class Harmonic(CandidateEffect):
    name = "harmonic"
    plausibility = (
        Plausibility(("c1", "s1"), {"table": 10.0, "mount": 40.0}, "a 1/rev term of {amplitude}",
                     "u"),
        Plausibility(("c2", "s2"), {ANY_MACHINE: 5.0}, "a 2/rev term of {amplitude}", "u"),
    )  # fmt: skip


def test_the_amplitude_is_the_root_sum_square_of_the_groups_fitted_values():
    group = Harmonic.plausibility[0]
    assert group.amplitude({"c1": 3.0, "s1": -4.0, "c2": 100.0}) == pytest.approx(5.0)
    assert group.amplitude({"c2": 1.0}) is None  # none of its parameters fitted
    assert Plausibility((), {}, "").amplitude({"a": 1.0, "b": 1.0}) == pytest.approx(math.sqrt(2))


def test_the_scale_is_per_machine_kind_with_a_default_for_any():
    one, two = Harmonic.plausibility
    assert one.limit("table") == 10.0 and one.limit("mount") == 40.0 and one.limit("bench") is None
    assert two.limit("bench") == 5.0


def test_beyond_its_scale_the_effect_says_what_one_would_have_to_believe():
    effect = Harmonic()
    assert effect.implausibility({"c1": 6.0, "s1": 8.0}, "table") is None  # 10 is not beyond 10
    assert effect.implausibility({"c1": 30.0, "s1": 0.0}, "mount") is None
    assert effect.implausibility({"c1": 30.0}, "table") == (
        "a 1/rev term of 30 u (where a table reaches about 10 u)"
    )
    # the group furthest beyond its scale is the one said
    worst = effect.implausibility({"c1": 20.0, "c2": 50.0}, "table")
    assert worst == "a 2/rev term of 50 u (where a table reaches about 5 u)"
    assert effect.implausibility({"c1": 1e9}, "bench") is None  # no scale for c1 on a bench


def test_an_effect_without_scales_is_never_judged():
    assert CandidateEffect().implausibility({"a": 1e12}, "table") is None
