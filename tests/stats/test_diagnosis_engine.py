"""The one diagnosis engine on a third family of data, a toy one: two columns of readings against
one variable, a constant per column as the base model, a slope and a wave as the candidates. The
family writes only its columns, model, candidates and words; the verdict, the outlier screen, the
noise per column, the two passes, the doubt and the separation rule come from the engine."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from turntable_pin.core.exceptions import InputError
from turntable_pin.stats.candidate_effect import CandidateEffect
from turntable_pin.stats.diagnosis_engine import (
    DOUBT_CHI2_REDUCED,
    DataFamily,
    SeparationWords,
    diagnose_data,
)
from turntable_pin.stats.least_squares import FitResult, fit_least_squares, zero_point

N = 160


class Shape(CandidateEffect):
    """A candidate effect of the one base class: one coefficient per column times ``shape(x)``."""

    def __init__(self, name: str, shape) -> None:
        self.name, self.shape, self.title = name, shape, f"a {name}"


CATALOGUE = (Shape("slope", lambda x: x / (2 * np.pi)), Shape("wave", np.sin))


class Model:
    """The readings (N, 2) from an offset per column plus each effect's shape (a FitProblem)."""

    user_unit_scale = 1.0
    observation_unit = "u"

    def __init__(self, family: ToyFamily, effects, column_sigma=None) -> None:
        self.effects = tuple(effects)
        x, mask = family.x, family.mask
        blocks = [np.eye(2)[None, :, :].repeat(x.size, axis=0)]
        names = ["offset.a", "offset.b"]
        for e in self.effects:
            blocks.append(np.eye(2)[None, :, :] * e.shape(x)[:, None, None])
            names += [f"{e.name}.a", f"{e.name}.b"]
        self.columns = np.concatenate(blocks, axis=2)  # (N, 2, n)
        self.parameter_names = tuple(names)
        self.parameter_units = ("u",) * len(names)
        self.per_user_unit = np.ones(len(names))
        flat = mask.reshape(-1)
        self._jacobian = self.columns.reshape(-1, len(names))[flat]
        self.observed = family.y.reshape(-1)[flat]
        sigma = None if family.sigma is None else np.repeat(family.sigma, 2)[flat]
        if column_sigma is not None:
            per = np.broadcast_to(column_sigma, mask.shape).reshape(-1)[flat]
            sigma = per if sigma is None else sigma * per
        self.sigma = sigma
        self.sigma_relative = column_sigma is not None

    def predict(self, params):
        return self._jacobian @ params

    def jacobian(self, params):
        return self._jacobian.copy()


@dataclasses.dataclass(frozen=True)
class Fit:
    model: Model
    result: FitResult


class ToyFamily(DataFamily):
    columns = ("a", "b")
    column_key = "column"
    record_label = "samples"
    record_words = "samples"
    observations = "readings"
    observation_unit = "u"
    unit_words = "u"
    outlier_rule = "the engine's rule"
    noise_subject = "the two columns'"
    noise_column = "column"

    def __init__(self, x, y, sigma=None, mask=None, column_sigma=None) -> None:
        self.x, self.y, self.sigma = x, y, sigma
        self.mask = np.ones(y.shape, bool) if mask is None else mask
        self.column_sigma = column_sigma
        scale = float(np.median(sigma)) if sigma is not None else 1.0
        super().__init__(CATALOGUE, self.mask, sigma_scale=scale,
                         noise_per_column=column_sigma is not None)  # fmt: skip

    def fit_model(self, effects, zero_point_):
        model = Model(self, effects, self.column_sigma)
        return Fit(model, fit_least_squares(model, zero_point=zero_point_))

    def zero_point_of(self, effects):
        model = Model(self, effects, self.column_sigma)
        w = 1.0 / model.sigma if model.sigma is not None else np.ones(model.observed.size)
        return zero_point(model.parameter_names,
                          [(model.jacobian(None) * w[:, None], model.observed * w, w)])  # fmt: skip

    def refit(self, fit, column_sigma):
        model = Model(self, fit.model.effects, column_sigma)
        return Fit(model, fit_least_squares(model))

    def residual_table(self, fit):
        out = np.full(self.y.shape, np.nan)
        out[self.mask] = fit.result.residuals
        return out

    def full_residuals(self, fit):
        return self.y - np.einsum("ncp,p->nc", fit.model.columns, fit.result.params)

    def sigma_table(self):
        return None if self.sigma is None else np.repeat(self.sigma[:, None], 2, axis=1)

    @property
    def sigma_given(self):
        return self.sigma is not None

    @property
    def rows(self):
        return np.arange(self.x.size) + 2

    @property
    def data_columns(self):
        return self  # no column besides x: every effect is testable

    def column(self, name):
        return None

    def without(self, cells):
        return ToyFamily(self.x, self.y, self.sigma, self.mask & ~cells, self.column_sigma)

    def with_column_noise(self, column_sigma):
        return ToyFamily(self.x, self.y, self.sigma, self.mask, column_sigma)

    def screen_fit(self, cells, effects):
        return self.without(cells).fit_model(effects, None).result

    @property
    def doubt_words(self):
        return "is this the right toy?"

    def probes(self, fit):
        return []

    misfit: float | Exception = 100.0
    """What :meth:`dense_misfit` gives (or raises), set by a test."""

    def dense_misfit(self, fit_a, effect_b):
        if isinstance(self.misfit, Exception):
            raise self.misfit
        return self.misfit

    def separation_words(self):
        return SeparationWords("grid", "dense grid", "grid (9 positions)", "x", "look", "more x")

    def design_warnings(self, base_fit):
        return []


def _readings(seed, noise=(1.0, 1.0), wave=6.0):
    rng = np.random.default_rng(seed)
    x = np.linspace(0.0, 2 * np.pi, N, endpoint=False)
    y = np.stack([3.0 + wave * np.sin(x), -2.0 + 0.0 * x], axis=1)
    return x, y + rng.normal(size=(N, 2)) * np.array(noise)


def test_the_engine_names_the_effect_and_lists_the_outliers_in_the_familys_words():
    x, y = _readings(1)
    y[[10, 90], [0, 1]] += [40.0, -40.0]
    diagnosis = diagnose_data(ToyFamily(x, y, np.ones(N)))
    d = diagnosis.to_dict()
    assert d["verdict"]["missing_effect"] == "wave"
    assert d["n_samples"] == N and "sigma_u" in d
    assert d["outlier_rule"] == "the engine's rule"
    assert {(o["row"], o["column"]) for o in d["outliers"]} == {(12, "a"), (92, "b")}
    assert all(abs(o["residual_sigma"]) > 20 for o in d["outliers"])
    assert d["verdict"]["doubt"] is None and d["warnings"] == []
    kept = diagnose_data(ToyFamily(x, y, np.ones(N)), outliers=False).to_dict()
    assert kept["outliers"] == [] and kept["outlier_rule"] is None


def test_columns_with_different_noise_are_each_weighted_by_their_own():
    x, y = _readings(2, noise=(1.0, 4.0))
    diagnosis = diagnose_data(ToyFamily(x, y))
    assert diagnosis.missing_effect == "wave"
    (note,) = diagnosis.warnings
    assert note.startswith("sigma not given, and the two columns' noise differ (estimated a ")
    assert "every model was fitted and compared at its own per-column noise" in note
    assert np.sqrt(diagnosis.group_variance) == pytest.approx([1.0, 4.0], rel=0.2)
    same = diagnose_data(ToyFamily(*_readings(2)))
    assert same.warnings == [] and same.group_variance is None


def test_a_stated_sigma_far_too_small_puts_the_family_in_doubt():
    x, y = _readings(3)
    d = diagnose_data(ToyFamily(x, y, np.full(N, 0.25))).to_dict()
    chi2_reduced = d["best"]["chi2_reduced"]
    assert chi2_reduced > DOUBT_CHI2_REDUCED
    assert d["verdict"]["doubt"] == (
        f"with every accepted effect the residuals are still {chi2_reduced**0.5:.1f} times the "
        f"stated noise (chi2_reduced {chi2_reduced:.3g}): is this the right toy?"
    )


@pytest.mark.parametrize(
    "misfit, words",
    [
        (100.0, "slope mimics wave on these positions only: on a grid (9 positions) it would "
                "leave chi2 = 100 of misfit at the same noise, so more x separates them"),
        (1e-3, "slope reproduces the fitted wave at every x (noise-free misfit chi2 = 0.001 on a "
               "grid), so no set of positions separates them; an independent look does. For "
               "wave:  For slope: "),
        (InputError("infinite at x = 0"), "slope cannot be compared with wave on a dense grid "
         "(infinite at x = 0); an independent look tells them apart. For wave:  For slope: "),
    ],
)  # fmt: skip
def test_one_separation_rule_in_the_familys_words(misfit, words):
    family = ToyFamily(*_readings(4))
    family.misfit = misfit
    assert family.separation(family.fit([CATALOGUE[1]]), CATALOGUE[0]) == words
