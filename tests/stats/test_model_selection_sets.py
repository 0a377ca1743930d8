"""The engine's parsimony over sets and plausible amplitudes, on a toy family of one column of
readings against one angle: a constant as the base model; three one-parameter shapes (``cos x``,
``sin 2x``, ``cos 3x``) and one six-parameter harmonic series spanning all three (and three more)
as the candidates. Over seeds: two simple causes are named as such, not as the series that
absorbs them; a series that truly is the cause is still named; clean readings name nothing; an
effect whose fitted amplitude is beyond its plausible scale is never named."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from turntable_pin.stats.candidate_effect import Plausibility
from turntable_pin.stats.diagnosis_engine import DataFamily, SeparationWords, diagnose_data
from turntable_pin.stats.least_squares import FitResult, fit_least_squares, zero_point
from turntable_pin.stats.model_selection import SET_MAX_SIZE, SetComparison

N = 240
X = np.linspace(0.0, 2 * np.pi, N, endpoint=False)
MACHINE = "bench"


class Shapes:
    """A candidate effect: one coefficient per shape ``(name, function of x)``."""

    def __init__(self, name: str, shapes, plausibility=()) -> None:
        self.name, self.shapes, self.plausibility = name, tuple(shapes), tuple(plausibility)
        self.title = self.definition = self.explanation = self.confirm = name
        self.required_columns = ()

    def missing_columns(self, data):
        return ()

    def describe(self):
        return {"effect": self.name, "title": self.name, "definition": "", "explanation": "",
                "confirm": ""}  # fmt: skip

    def implausibility(self, values, machine):
        from turntable_pin.stats.candidate_effect import CandidateEffect

        return CandidateEffect.implausibility(self, values, machine)

    def amount_words(self, value, unit):
        return f"{value:.3g} {unit}"


SERIES_SHAPES = (
    ("c1", np.cos), ("s1", np.sin), ("c2", lambda x: np.cos(2 * x)),
    ("s2", lambda x: np.sin(2 * x)), ("c3", lambda x: np.cos(3 * x)),
    ("s3", lambda x: np.sin(3 * x)),
)  # fmt: skip


def catalogue(series_scale: float | None = None):
    """The toy catalogue; ``series_scale``: the series' plausible amplitude on the bench."""
    scale = () if series_scale is None else (
        Plausibility((), {MACHINE: series_scale}, "a series of {amplitude}", "u"),
    )  # fmt: skip
    return (
        Shapes("series", SERIES_SHAPES, scale),
        Shapes("cos1", [("k", np.cos)]),
        Shapes("sin2", [("k", lambda x: np.sin(2 * x))]),
        Shapes("cos3", [("k", lambda x: np.cos(3 * x))]),
    )


class Model:
    user_unit_scale = 1.0
    observation_unit = "u"

    def __init__(self, family, effects) -> None:
        self.effects = tuple(effects)
        blocks, names = [np.ones((N, 1))], ["offset.k"]
        for e in self.effects:
            blocks += [f(X)[:, None] for _, f in e.shapes]
            names += [f"{e.name}.{p}" for p, _ in e.shapes]
        self.columns = np.concatenate(blocks, axis=1)
        self.parameter_names = tuple(names)
        self.parameter_units = ("u",) * len(names)
        self.per_user_unit = np.ones(len(names))
        self.observed = family.y
        self.sigma = np.ones(N)
        self.sigma_relative = False

    def predict(self, params):
        return self.columns @ params

    def jacobian(self, params):
        return self.columns.copy()


@dataclasses.dataclass(frozen=True)
class Fit:
    model: Model
    result: FitResult


class Toy(DataFamily):
    columns = ("y",)
    record_label = "samples"
    observation_unit = "u"
    unit_words = "u"
    machine_kind = MACHINE

    def __init__(self, y, effects) -> None:
        self.y = y
        super().__init__(effects, np.ones((N, 1), bool), sigma_scale=1.0)

    def fit_model(self, effects, zero_point_):
        model = Model(self, effects)
        return Fit(model, fit_least_squares(model, zero_point=zero_point_))

    def zero_point_of(self, effects):
        model = Model(self, effects)
        w = np.ones(N)
        return zero_point(model.parameter_names, [(model.columns, model.observed, w)])

    def residual_table(self, fit):
        return fit.result.residuals[:, None]

    def full_residuals(self, fit):
        return self.residual_table(fit)

    sigma_given = True
    rows = np.arange(N) + 2

    @property
    def data_columns(self):
        return self

    def column(self, name):
        return None

    def probes(self, fit):
        return []

    def without(self, cells):
        assert not cells.any()  # diagnosed without the outlier screen
        return self

    def dense_misfit(self, fit_a, effect_b):
        return 100.0

    def separation_words(self):
        return SeparationWords("grid", "grid", "grid", "x", "look", "more x")

    def design_warnings(self, base_fit):
        return []


def readings(seed: int, **amplitudes) -> np.ndarray:
    """Unit-noise readings with ``amplitudes`` of the series' shapes (``c1=5``...)."""
    rng = np.random.default_rng(seed)
    shapes = dict(SERIES_SHAPES)
    signal = sum(a * shapes[name](X) for name, a in amplitudes.items())
    return 2.0 + signal + rng.normal(size=N)


def diagnosed(y, series_scale=None):
    return diagnose_data(Toy(y, catalogue(series_scale)), outliers=False)


SEEDS = range(50)


def test_two_simple_causes_are_named_as_such_not_as_the_series_that_absorbs_them():
    """Over 50 seeds: cos x and sin 2x (the series fits exactly as well) name the two singles,
    and the comparison with the series is in the result, its words and its numbers."""
    named = 0
    for seed in SEEDS:
        d = diagnosed(readings(seed, c1=1.0, s2=1.0))
        named += set(d.missing_effects) == {"cos1", "sin2"}
    assert named >= 0.95 * len(SEEDS)
    d = diagnosed(readings(0, c1=1.0, s2=1.0))
    (comparison,) = d.set_comparisons
    assert comparison.effect == "series" and comparison.chosen
    assert set(comparison.simpler) == {"cos1", "sin2"} and comparison.set_added_rank == 2
    assert comparison.added_rank == 6 and comparison.set_delta_bic < comparison.delta_bic
    verdict = d.to_dict()["verdict"]
    assert verdict["missing_effects"] == d.missing_effects and not verdict["also_significant"]
    (entry,) = verdict["simpler_sets"]
    assert entry["set_named"] and entry["effect"] == "series" and entry["step"] == 1


def test_without_the_set_search_the_series_would_be_named():
    """The set search is what names the singles: forward selection alone takes the series."""
    d = diagnosed(readings(0, c1=1.0, s2=1.0))
    first_round = {c.effect: c for c in d.candidates}
    assert first_round["series"].delta_bic < first_round["cos1"].delta_bic
    assert d.candidates[0].effect == "series"


def test_a_true_many_parameter_effect_is_still_named_and_its_comparison_recorded():
    named = 0
    for seed in SEEDS:
        y = readings(seed, c1=1.0, s1=1.0, c2=1.0, s2=1.0, c3=1.0, s3=1.0)
        d = diagnosed(y)
        named += d.missing_effects == ["series"]
    assert named >= 0.95 * len(SEEDS)
    (comparison,) = d.set_comparisons
    assert isinstance(comparison, SetComparison) and not comparison.chosen
    assert 2 <= len(comparison.simpler) <= SET_MAX_SIZE
    assert comparison.set_delta_bic > comparison.delta_bic


def test_clean_readings_name_nothing():
    assert all(not diagnosed(readings(seed)).steps for seed in range(20))


def test_an_implausible_amplitude_is_marked_and_never_named():
    """The series truly makes the readings but beyond its plausible scale: marked implausible
    with what one would have to believe, and not named over any seed."""
    for seed in range(20):
        y = readings(seed, c1=3.0, s1=3.0, c2=3.0, s2=3.0, c3=3.0, s3=3.0)
        d = diagnosed(y, series_scale=2.0)
        assert "series" not in d.missing_effects
        assert "series" not in [s.added for s in d.steps]
    series = next(c for c in d.to_dict()["candidates"] if c["effect"] == "series")
    assert series["significant"]
    assert series["implausible"].startswith("a series of 7.")
    assert series["implausible"].endswith("(where a bench reaches about 2 u)")
    (entry,) = d.to_dict()["verdict"]["implausible"]
    assert entry["effect"] == "series" and entry["belief"] == series["implausible"]


def test_a_plausible_amplitude_is_named_as_before():
    y = readings(1, c1=1.0, s1=1.0, c2=1.0, s2=1.0, c3=1.0, s3=1.0)
    d = diagnosed(y, series_scale=100.0)
    assert d.missing_effects == ["series"]
    assert all(c.implausible is None for c in d.candidates)
    assert d.to_dict()["verdict"]["implausible"] == []


@pytest.mark.parametrize("scale", [None, 2.0])
def test_every_candidate_entry_says_whether_it_is_implausible(scale):
    d = diagnosed(readings(2, c1=3.0), series_scale=scale)
    entries = d.to_dict()["candidates"]
    assert all("implausible" in c for c in entries)
