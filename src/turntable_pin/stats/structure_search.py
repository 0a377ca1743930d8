"""A generic search for structure left in fit residuals: which shape is still missing.

As telescope pointing analysts search harmonic terms when their physical terms do not suffice,
the model family supplies *probes* (groups of columns, each a candidate shape, e.g. a 3/rev
harmonic of one parameter in one input), and a greedy forward search adds the probe that removes
most of the weighted rss *after* projecting out what the model absorbs, while it lowers BIC by at
least ``-BIC_THRESHOLD + 2 ln G`` for G probes: ``2 ln G`` is a Bonferroni correction on the
likelihood scale (432 clean observations, ~130 probes: the chance of any false term falls from
~1.5 % to ~0.01 %, while a 3-sigma term lowers chi2 by several hundred).

Each found term keeps what a plot of it needs: its fitted contribution and partial residual and,
when the probe factors record by record (:class:`ProbeFactors`), the residual projected onto its
direction against its variable (:meth:`FoundTerm.projection`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .least_squares import TALL_ROWS, tall_r_factor, tall_times

__all__ = [
    "orthonormal_columns",
    "BATCH_VALUES",
    "BIC_THRESHOLD",
    "NEW_FRACTION",
    "FoundTerm",
    "Probe",
    "ProbeFactors",
    "TermProjection",
    "delta_bic",
    "profiled_weight",
    "search_structure",
]

BIC_THRESHOLD = -6.0
"""A term is accepted when it lowers BIC by at least 6 (strong evidence, Kass-Raftery)."""

NEW_FRACTION = 1e-2
"""A probe direction is new only if more than this fraction of it (of the probe's largest singular
value) survives projecting out the model and the terms found: shapes the model spans to first
order leave second-order remainders (1e-5..1e-3), whose fits gave absurd amplitudes."""


@dataclass(frozen=True)
class ProbeFactors:
    """How a probe's columns factor record by record: a direction times functions of a variable,
    ``columns[i k + c, j] = direction[i, c] * functions(values)[i, j]`` for n records of k
    observations (record-major). Probes sharing one ``direction`` object are scored together
    (:func:`_scored_factored`).

    Attributes:
        variable: name of the variable the shape is a function of.
        values: (n,) that variable per record, in internal units.
        functions: maps values (p,) to the g basis functions (p, g) (any values, for a curve).
        direction: (n, k) weighted like the residuals, or a function returning it.
        value_scale, value_unit: user units per internal unit of ``values``, and that unit.
        observed: (n, k) which observations the data hold (``None``: all).
        basis: ``functions(values)`` (n, g) when already computed (shared by a shape's probes).
    """

    variable: str
    values: np.ndarray
    functions: Callable[[np.ndarray], np.ndarray]
    direction: np.ndarray | Callable[[], np.ndarray]
    value_scale: float = 1.0
    value_unit: str = ""
    observed: np.ndarray | None = field(default=None, repr=False)
    basis: np.ndarray | None = field(default=None, repr=False, compare=False)

    def direction_matrix(self) -> np.ndarray:
        """The (n, k) direction."""
        d = self.direction() if callable(self.direction) else self.direction
        return np.asarray(d, dtype=float)

    def basis_matrix(self) -> np.ndarray:
        """``functions(values)`` as an (n, g) matrix."""
        b = self.basis if self.basis is not None else self.functions(np.asarray(self.values))
        b = np.asarray(b, dtype=float)
        return b.reshape(b.shape[0], -1)


@dataclass(frozen=True)
class Probe:
    """One candidate shape: weighted columns (m, g) and how to describe them.

    Attributes:
        name: short id (``a 3/rev in x``); description: for people.
        columns: (m, g) weighted like the residuals, or a function returning them (the search
            then holds one probe's columns at a time).
        unit_scale, unit: user units per internal unit of the coefficients, and that unit.
        factors: how the columns factor per record (optional: a plot against the variable, and
            scoring without forming the columns).
        effect_spec: how the family's users add this shape to their model, or ``None``.
    """

    name: str
    description: str
    columns: np.ndarray | Callable[[], np.ndarray]
    unit_scale: float = 1.0
    unit: str = ""
    factors: ProbeFactors | None = None
    effect_spec: str | None = None

    def matrix(self) -> np.ndarray:
        """The (m, g) columns."""
        return np.asarray(self.columns() if callable(self.columns) else self.columns, dtype=float)


@dataclass(frozen=True)
class TermProjection:
    """A found term seen record by record, in user units.

    Attributes:
        variable: the variable the term is a function of; values: (n,) it per record, in
            ``value_unit``.
        projected: (n,) the partial residual (with every found term, plus this one's fit)
            projected at each record onto the term's direction: a noisy sample of the term.
        noise: (n,) 1-sigma noise of ``projected``; fitted: (n,) the fitted term.
        unit: the user unit of ``projected``, ``noise`` and ``fitted``.
    """

    variable: str
    values: np.ndarray
    value_unit: str
    projected: np.ndarray
    noise: np.ndarray
    fitted: np.ndarray
    unit: str


@dataclass(frozen=True)
class FoundTerm:
    """A probe accepted by the search, with its fitted size.

    Kept for plots, not in :meth:`to_dict`: ``fitted_weighted`` (m,) the term's contribution to
    the weighted observations; ``residual_weighted`` its partial residual (the residual with
    every found term, plus ``fitted_weighted``); ``explained_weighted`` what its columns explain
    beyond the model and the terms found before; ``noise_std_weighted`` one weighted
    observation's noise (1 with sigmas).
    """

    name: str
    description: str
    delta_bic: float
    amplitude: float
    unit: str
    coefficients: tuple[float, ...]
    unit_scale: float = 1.0
    factors: ProbeFactors | None = field(default=None, repr=False, compare=False)
    fitted_weighted: np.ndarray | None = field(default=None, repr=False, compare=False)
    residual_weighted: np.ndarray | None = field(default=None, repr=False, compare=False)
    explained_weighted: np.ndarray | None = field(default=None, repr=False, compare=False)
    noise_std_weighted: float = 1.0
    effect_spec: str | None = None

    def curve(self, values: np.ndarray) -> np.ndarray:
        """The fitted term at ``values`` of its variable (internal units), in user units
        (ValueError without ``factors``)."""
        if self.factors is None:
            raise ValueError(f"term '{self.name}' has no factors: it cannot be drawn as a curve")
        values = np.atleast_1d(np.asarray(values, dtype=float))
        basis = np.asarray(self.factors.functions(values), dtype=float)
        return basis.reshape(values.size, -1) @ np.asarray(self.coefficients)

    def projection(self) -> TermProjection:
        """The term record by record: at record i with direction d_i, ``d_i . p_i / |d_i|^2`` of
        the partial residual p_i (the size that record alone sees; noise
        ``noise_std_weighted / |d_i|``); NaN where d_i = 0.

        Raises:
            ValueError: the search kept no per-observation data or the probe had no factors.
        """
        f = self.factors
        if f is None or self.residual_weighted is None:
            raise ValueError(f"term '{self.name}' kept no data to project")
        d = f.direction_matrix()
        n, k = d.shape
        p = np.asarray(self.residual_weighted, dtype=float)
        if f.observed is not None:
            full = np.zeros(n * k)
            full[np.asarray(f.observed, bool).reshape(-1)] = p
            p = full
            d = np.where(f.observed, d, 0.0)
        p = p.reshape(n, k)
        norm2 = np.sum(d * d, axis=1)
        reach = norm2 > 0
        safe = np.where(reach, norm2, 1.0)
        projected = np.where(reach, np.sum(d * p, axis=1) / safe, np.nan) * self.unit_scale
        noise = np.where(reach, self.noise_std_weighted / np.sqrt(safe), np.nan) * self.unit_scale
        values = np.asarray(f.values, dtype=float)
        return TermProjection(
            variable=f.variable,
            values=values * f.value_scale,
            value_unit=f.value_unit,
            projected=projected,
            noise=noise,
            fitted=self.curve(values),
            unit=self.unit,
        )

    def to_dict(self) -> dict:
        """The term as a JSON-ready dictionary."""
        return {
            "term": self.name,
            "description": self.description,
            "delta_bic": self.delta_bic,
            "amplitude": self.amplitude,
            "unit": self.unit,
            "coefficients": list(self.coefficients),
            "effect_spec": self.effect_spec,
        }


def profiled_weight(m: int, rank_new: int, added: int) -> float:
    """The weight ``w = m - rank_new + added / 2 - 1`` of ``ln(rss_old / rss_new)`` that makes the
    profiled likelihood ratio of two nested models follow its chi2 reference on small samples.

    The textbook weight ``m`` overstates the evidence when ``m`` is a few times the parameters
    (m = 72, ten parameters, two added: an F-tail 1e-4 improvement scores 21.5, not 18.4). With
    the larger model's residual dof the ratio is the F test exactly for two added parameters; the
    ``added / 2 - 1`` (Bartlett-type) term keeps the tail within 10 % of the F test's for up to
    eight added once ``m - rank_new >= 60`` (tests check it against scipy).
    """
    return max(m - rank_new + added / 2.0 - 1.0, 1.0)


def delta_bic(
    rss_new: float, rss_old: float, added: int, m: int, noise_variance: float | None, rank_new: int
):
    """BIC change of a model adding ``added`` parameters: ``(rss_new - rss_old) / var + added
    ln m`` with a known noise variance, else ``w ln(rss_new / rss_old) + added ln m`` (the
    variance profiled out, ``w`` of :func:`profiled_weight`)."""
    if noise_variance is not None:
        return (rss_new - rss_old) / noise_variance + added * math.log(m)
    ratio = max(rss_new, 1e-300) / max(rss_old, 1e-300)
    return profiled_weight(m, rank_new, added) * math.log(ratio) + added * math.log(m)


def orthonormal_columns(matrix: np.ndarray) -> np.ndarray:
    """An orthonormal basis (m, k) of the span of ``matrix`` (m, n): its directions with
    singular values above 1e-9 of the largest."""
    if matrix.size == 0:
        return np.zeros((matrix.shape[0], 0))
    m, n = matrix.shape
    if m <= 2 * TALL_ROWS or m < 8 * n:
        u, s, _ = np.linalg.svd(matrix, full_matrices=False)
        return u[:, s > 1e-9 * (s[0] if s.size else 1.0)]
    # Long and thin: U = A V / s from the small R factor, made orthonormal once more against the
    # rounding of small s (in place, by blocks of rows).
    _, s, vt = np.linalg.svd(tall_r_factor(matrix))
    keep = s > 1e-9 * (s[0] if s.size else 1.0)
    u = tall_times(matrix, vt[keep].T / s[keep])
    values, vectors = np.linalg.eigh(u.T @ u)
    correction = (vectors / np.sqrt(values)) @ vectors.T
    for start in range(0, m, TALL_ROWS * 16):
        block = u[start : start + TALL_ROWS * 16]
        block[...] = block @ correction
    return u


BATCH_VALUES = 1 << 21
"""Probe columns scored together hold at most about this many values (16 MB)."""


def _probe_fit(gram: np.ndarray, qc: np.ndarray, cr: np.ndarray, qr_: np.ndarray):
    """What a probe's columns C (m, g) add beyond the span of ``q`` (m, k) to explain ``r``,
    from small matrices only: ``gram = C^T C``, ``qc = q^T C``, ``cr = C^T r``, ``qr_ = q^T r``.
    With ``t = C - q q^T C``, ``t^T t = gram - qc^T qc``, ``t^T r = cr - qc^T qr_``, and
    ``t^T t = V S^2 V^T`` (``U = t V / S`` for the kept directions).

    Returns:
        ``(reduction, V kept (g, k), S kept, S U^T r)`` or None when no direction is new.
    """
    if not gram.size:
        return None
    scale2 = float(np.linalg.eigvalsh(gram)[-1])
    tt = gram - qc.T @ qc
    tr = cr - qc.T @ qr_
    values, vectors = np.linalg.eigh((tt + tt.T) / 2.0)
    keep = values > NEW_FRACTION**2 * scale2
    if not keep.any():
        return None
    v, s2 = vectors[:, keep], values[keep]
    along = v.T @ tr  # s * (U^T r)
    return float(np.sum(along**2 / s2)), v, np.sqrt(s2), along


def _scored(probes: Sequence[Probe], q: np.ndarray, r: np.ndarray):
    """``(probe, _probe_fit result)`` for each probe, in order: from their factors when they
    have them, else from their columns in batches."""
    m = r.size
    qr_ = q.T @ r
    factored = [p for p in probes if _factorable(p, m)]
    results = dict(_scored_factored(factored, q, r, qr_))
    rest = [p for p in probes if id(p) not in results]
    if rest:
        qr_full = np.concatenate([q, r[:, None]], axis=1).T.copy()  # (k + 1, m)
        results.update((id(p), fit) for p, fit in _scored_columns(rest, qr_full, qr_))
    for probe in probes:
        yield probe, results[id(probe)]


def _factorable(probe: Probe, m: int) -> bool:
    """Whether ``probe`` says how its m columns factor (direction times functions)."""
    f = probe.factors
    if f is None:
        return False
    n = np.shape(f.values)[0]
    if f.observed is not None:
        return np.shape(f.observed)[0] == n and int(np.count_nonzero(f.observed)) == m
    return n > 0 and m % n == 0


def _by_observation(q: np.ndarray, r: np.ndarray, n: int, k: int, observed) -> np.ndarray:
    """``[q r]`` laid out as (k, K + 1, n) by observation of a record (zero where not observed)."""
    out = np.zeros((k, q.shape[1] + 1, n))
    if observed is None:
        for c in range(k):
            out[c, :-1] = q[c::k].T
            out[c, -1] = r[c::k]
        return out
    index = np.flatnonzero(np.asarray(observed, dtype=bool).reshape(-1))
    record, channel = np.divmod(index, k)
    for c in range(k):
        rows = np.flatnonzero(channel == c)
        out[c, :-1, record[rows]] = q[rows]
        out[c, -1, record[rows]] = r[rows]
    return out


def _scored_factored(probes: Sequence[Probe], q: np.ndarray, r: np.ndarray, qr_: np.ndarray):
    """``(id(probe), _probe_fit result)`` of factored probes without forming their columns:
    with ``[q r]`` laid out by observation, ``Q[c, :, i]``, ``[q r]^T C = (sum_c Q[c]
    direction[:, c]) @ basis`` and the Gram matrix is ``basis^T (|direction|^2 basis)``; the
    contraction is done once per shared direction object."""
    by_direction: dict[int, list[Probe]] = {}
    for probe in probes:
        by_direction.setdefault(id(probe.factors.direction), []).append(probe)
    layouts: dict[int, np.ndarray] = {}
    for group in by_direction.values():
        f = group[0].factors
        d = f.direction_matrix()
        n, k = d.shape
        observed = None if f.observed is None else np.asarray(f.observed, dtype=bool)
        if observed is not None and observed.all():
            observed = None
        if observed is not None:
            d = np.where(observed, d, 0.0)
        key = -1 if observed is None else id(f.observed)
        if key not in layouts:
            layouts[key] = _by_observation(q, r, n, k, observed)
        layout = layouts[key]
        contracted = layout[0] * d[:, 0]  # (K + 1, n)
        for c in range(1, k):
            contracted += layout[c] * d[:, c]
        norm2 = np.einsum("ic,ic->i", d, d)
        for probe in group:
            basis = probe.factors.basis_matrix()
            products = contracted @ basis
            gram = basis.T @ (basis * norm2[:, None])
            yield id(probe), _probe_fit(gram, products[:-1], products[-1], qr_)


def _scored_columns(probes: Sequence[Probe], qr_full: np.ndarray, qr_: np.ndarray):
    """``(probe, _probe_fit result)`` for each probe from its columns, taken in batches."""
    m = qr_full.shape[1]
    budget = max(BATCH_VALUES // max(m, 1), 1)
    buffer = np.empty((m, budget))  # the batch's columns, side by side
    batch: list[tuple[Probe, slice]] = []

    def flush(width):
        columns = buffer[:, :width]
        products = qr_full @ columns  # (k + 1, G): q^T C and r^T C of every probe
        gram = columns.T @ columns
        for probe, sl in batch:
            yield probe, _probe_fit(gram[sl, sl], products[:-1, sl], products[-1, sl], qr_)

    width = 0
    for probe in probes:
        columns = probe.matrix()
        g = columns.shape[1]
        if batch and width + g > budget:
            yield from flush(width)
            batch, width = [], 0
        if g > budget:  # a probe wider than a batch is scored alone
            buffer = np.empty((m, g))
            budget = g
        buffer[:, width : width + g] = columns
        batch.append((probe, slice(width, width + g)))
        width += g
        del columns
    if batch:
        yield from flush(width)


def search_structure(
    weighted_residuals: np.ndarray,
    model_jacobian_weighted: np.ndarray,
    probes: Sequence[Probe],
    *,
    noise_variance: float | None,
    max_terms: int = 5,
) -> list[FoundTerm]:
    """Greedy forward search of probes that explain residual structure, each scored from small
    matrices (:func:`_probe_fit`); only an accepted probe's new directions are formed.

    Args:
        weighted_residuals: (m,) residuals divided by sigma (unit weights if sigma unknown).
        model_jacobian_weighted: (m, n) the fitted model's weighted Jacobian (its span, what the
            model absorbs, is projected out of every probe).
        probes: candidate shapes.
        noise_variance: 1 when sigmas are known; ``None`` to profile the variance out.
        max_terms: most terms to add.
    """
    r = np.asarray(weighted_residuals, dtype=float).copy()
    m = r.size
    q = orthonormal_columns(model_jacobian_weighted)
    del model_jacobian_weighted  # (m, n): its span is all the search needs
    found: list[tuple] = []
    remaining = list(probes)
    threshold = BIC_THRESHOLD - 2.0 * math.log(max(len(remaining), 1))
    for _ in range(max_terms):
        rss = float(r @ r)
        best = None
        for probe, scored in _scored(remaining, q, r):
            if scored is not None and (best is None or scored[0] > best[0]):
                best = (scored[0], probe, *scored[1:])
        if best is None:
            break
        reduction, probe, v, s, along = best
        added = v.shape[1]
        dbic = delta_bic(rss - reduction, rss, added, m, noise_variance, q.shape[1] + added)
        if dbic > threshold:
            break
        # coefficients: V S^-1 U^T r = V S^-2 (V^T t^T r)
        coef_internal = v @ (along / s**2)
        coef = coef_internal * probe.unit_scale
        columns = probe.matrix()
        basis = tall_times(columns - tall_times(q, q.T @ columns), v / s)
        explained = basis @ (basis.T @ r)
        term = FoundTerm(
            name=probe.name,
            description=probe.description,
            delta_bic=float(dbic),
            amplitude=float(np.linalg.norm(coef)),
            unit=probe.unit,
            coefficients=tuple(float(c) for c in coef),
            unit_scale=probe.unit_scale,
            factors=probe.factors,
            effect_spec=probe.effect_spec,
        )
        found.append((term, columns @ coef_internal, explained))
        r = r - explained
        q = np.concatenate([q, basis], axis=1)
        remaining.remove(probe)
    return _with_plot_data(found, r, q.shape[1], noise_variance)


def _with_plot_data(found: list[tuple], residual: np.ndarray, rank: int, noise_variance):
    """The found terms with their per-observation data (see :class:`FoundTerm`)."""
    if not found:
        return []
    m = residual.size
    if noise_variance is None:
        noise_variance = float(residual @ residual) / max(m - rank, 1)
    std = math.sqrt(noise_variance)
    return [
        replace(
            term,
            fitted_weighted=fitted,
            residual_weighted=residual + fitted,
            explained_weighted=explained,
            noise_std_weighted=std,
        )
        for term, fitted, explained in found
    ]
