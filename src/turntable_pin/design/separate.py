"""Positions that tell two effects apart (``design(separate='A,B')``; issue 19, item 2).

When the diagnosis says that effect B reproduces effect A on the positions measured, which
positions would tell them apart, and how many? Each effect is taken at its amplitude (given, or
fitted with the base errors on the data measured). If A is true, fitting the base errors and B
to A's prediction leaves the noise-free misfit

    lambda_AB = || (I - P_B) J_A a ||^2 / sigma^2,   P_B the projector on the base and B's columns

over the design's measured angles (J the linearised model: the Jacobian of
:class:`~turntable_pin.measurement.effect_model.OrientationModel` at zero), and ``lambda_BA`` the
other way round. The design maximises the smaller of the two (T-optimal, Atkinson and Fedorov
1975): a seeded exchange over the candidates within the joints' limits
(:func:`~turntable_pin.stats.discrimination.t_optimal_exchange`), after the positions measured.

The power is the diagnosis' own decision (sigma known). With A true, A is named when it is
accepted, ``chi2'(k_A, lambda_A0) > k_A ln m + 6 + 2 ln K`` (``lambda_A0`` what the base errors
leave of A, ``k_A`` the ranks A adds, ``m`` the measured angles, ``K`` the catalogue's size:
:func:`~turntable_pin.stats.model_selection.acceptance_threshold`), and then either put before B
in the first round, ``rss_B - rss_A > (k_A - k_B) ln m`` (a generalised chi-square,
:func:`~turntable_pin.stats.discrimination.rss_difference`; A traded off and B not: also ``gain_A
> 2 gain_B``), or, B first, accepted on top of B (``chi2'(k_A|B, lambda_AB)`` above the second
round's threshold) with B then dropped. A design's power is the smaller of the two chances (A
true, B true); a third effect that might take the name is not counted. The count for the target
power scales the design's misfits (replicating it is exact), checked by designing that many.

When B reproduces A at every candidate (misfit below
:data:`~turntable_pin.stats.discrimination.SAME_RTOL` of A's signal beyond the base) and A has no
fewer ranks than B, no positions separate them: the result says so, with the effects' ``confirm``
texts. When B contains A with more ranks, a true A is still named by the rule's parsimony.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ..core.blas_threads import one_blas_thread
from ..core.exceptions import IdentifiabilityError, InputError
from ..core.notebook import NotebookResult
from ..core.sizes import check_positions_count
from ..core.words import argument, command
from ..measurement.catalogue import catalogue
from ..measurement.effects.base import MOUNT, TURNTABLE, PositionVariables
from ..measurement.fit import fit_orientation
from ..stats.design import information_rows
from ..stats.discrimination import (
    SAME_RTOL,
    Direction,
    choice_margin,
    detection_power,
    generalized_chi2_sf,
    misfit,
    orthonormal_span,
    quadratic_form,
    residual,
    rss_difference,
    t_optimal_exchange,
    traded_off,
)
from ..stats.least_squares import tall_r_factor
from ..stats.model_selection import UNDETERMINED_GAIN_RATIO, acceptance_threshold
from .identify import CandidateRows, _evaluate, candidate_rows, grid_rows
from .schedule import MeasurementPlan, plan_measurements
from .space import DesignSpace

__all__ = [
    "POWER_TARGET",
    "Hypothesis",
    "SeparationDesign",
    "design_separate",
]

POWER_TARGET = 0.9
"""The chance of the right name the positions count is given for."""

MAX_POWER_POSITIONS = 5000
"""Most positions the count for the target power is searched up to."""


@dataclass(frozen=True)
class Hypothesis:
    """One of the two effects taken as the truth, against the other (chi2 are noise-free).

    Attributes:
        effect, rival: the names.  amplitude: its parameters (user units); unit: their unit(s).
        signal_chi2: what the base errors leave of its prediction on the design (and the data).
        misfit_chi2: what the base errors and the rival leave of it there (``lambda``);
            misfit_measured_chi2: on the positions measured alone (``None`` without);
            misfit_grid_chi2: on the 30-degree grid within the limits at the design's size.
        added_rank, rival_added_rank: the ranks each adds to the base on the design.
        determined, rival_determined: whether the design determines each one's parameters (the
            diagnosis' correlation rule: an undetermined effect goes first only when it explains
            twice what a determined one does).
        settled_by: ``misfit`` (the design separates it) or ``parsimony`` (the rival reproduces
            it everywhere with more ranks: the rule names it for its fewer ranks).
        power_detect: the chance that it is accepted at all; power_first: that it goes before
            the rival in the first round; power_on_top: that, the rival first, it is accepted on
            top and the rival dropped; power_choice: that it is named rather than the rival.
        power: ``power_detect * power_choice``, the chance of its name; power_measured,
            power_new_alone: on the positions measured alone, on the new ones alone (``None``
            without data measured).
    """

    effect: str
    rival: str
    amplitude: dict[str, float]
    unit: str
    signal_chi2: float
    misfit_chi2: float
    misfit_measured_chi2: float | None
    misfit_grid_chi2: float | None
    added_rank: int
    rival_added_rank: int
    determined: bool
    rival_determined: bool
    settled_by: str
    power_detect: float
    power_first: float
    power_on_top: float
    power_choice: float
    power: float
    power_measured: float | None
    power_new_alone: float | None

    def to_dict(self) -> dict:
        """The hypothesis as a JSON-ready dict."""
        return dict(vars(self))


@dataclass(frozen=True)
class SeparationDesign(NotebookResult):
    """The positions that tell two effects apart, or why none do.

    Attributes:
        space: the :class:`~.space.DesignSpace`.  pair: the two effects' names.
        positions_deg: the chosen positions (N, J), degrees, in the run's first order (empty
            when none separate them); plan: their run (``None`` then).
        hypotheses: each effect as the truth (:class:`Hypothesis`), A then B.
        misfit_by_position: (N, 2) each position's share of the misfit each effect's rival
            leaves (chi2; zero for a direction left to parsimony).
        measured_deg: the positions already measured (M, J), degrees; n_from: their number.
        noise_arcsec, noise_source: the noise of a measured angle and where it comes from.
        amplitude_source: where each effect's amplitude comes from (``{effect: text}``).
        power: the smaller chance of the right name at these positions.
        target: the power asked for.  positions_for_power, power_at_positions_for_power,
            positions_for_power_designed: the fewest positions with that power (``None``: more
            than :data:`MAX_POWER_POSITIONS`), their power, and whether that many were designed
            to check it (else this design's misfits scaled).
        power_curve: ``(positions, power)`` of this design scaled to other sizes.
        catalogue_size: K of the acceptance threshold.  n_swaps, n_passes: of the exchange.
        inseparable: why no positions within the limits separate them (one line), or ``None``.
        implausible: ``{effect: what one would have to believe}`` of each effect whose amplitude
            fitted on the data is beyond the physical scale of its kind on the machine
            (``docs/plausibility.md``): no positions are planned for such a hypothesis.
    """

    space: DesignSpace = field(repr=False)
    pair: tuple[str, str]
    positions_deg: np.ndarray = field(repr=False)
    measured_deg: np.ndarray = field(repr=False)
    noise_arcsec: float
    noise_source: str
    amplitude_source: dict[str, str]
    n_from: int
    target: float
    plan: MeasurementPlan | None = field(default=None, repr=False)
    hypotheses: tuple[Hypothesis, ...] = ()
    misfit_by_position: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)), repr=False)
    power: float | None = None
    positions_for_power: int | None = None
    power_at_positions_for_power: float | None = None
    positions_for_power_designed: bool = False
    power_curve: tuple[tuple[int, float], ...] = ()
    catalogue_size: int = 0
    n_swaps: int = 0
    n_passes: int = 0
    inseparable: str | None = None
    implausible: dict[str, str] = field(default_factory=dict)

    @property
    def n_positions(self) -> int:
        """Number of positions chosen N."""
        return int(self.positions_deg.shape[0])

    def comment(self) -> str:
        """The comment lines of the positions' CSV: what made it, with its seed."""
        a, b = self.pair
        return "\n".join(
            [
                f"designed by {command('design', separate=f'{a},{b}')} (T-optimal)",
                f"table: {self.space.table_name}",
                f"{self.space.seed_text(self.n_positions)} n_from={self.n_from}",
                self.space.limits_text,
                f"noise_arcsec={self.noise_arcsec:g} ({self.noise_source})",
                "amplitudes: "
                + "; ".join(
                    f"{h.effect}: {_values(h.amplitude)} {h.unit}" for h in self.hypotheses
                ),
                f"power (chance of the right name): {_percent(self.power)}",
                f"run: {self.plan.rule}" if self.plan is not None else "run: none",
            ]
        )

    def to_dict(self) -> dict:
        """The design as a JSON-ready dict."""
        return {
            "mode": "separate",
            "space": self.space.to_dict(),
            "effects": list(self.pair),
            "inseparable": self.inseparable,
            "implausible": dict(self.implausible),
            "n_positions": self.n_positions,
            "n_from": self.n_from,
            "noise_arcsec": self.noise_arcsec,
            "noise_source": self.noise_source,
            "amplitude_source": dict(self.amplitude_source),
            "hypotheses": [h.to_dict() for h in self.hypotheses],
            "power": self.power,
            "target": self.target,
            "positions_for_power": self.positions_for_power,
            "power_at_positions_for_power": self.power_at_positions_for_power,
            "positions_for_power_designed": self.positions_for_power_designed,
            "power_curve": [list(p) for p in self.power_curve],
            "catalogue_size": self.catalogue_size,
            "n_swaps": self.n_swaps,
            "n_passes": self.n_passes,
            "positions_deg": self.positions_deg.tolist(),
            "misfit_by_position": self.misfit_by_position.tolist(),
            "plan": self.plan.to_dict() if self.plan is not None else None,
        }

    def report(self) -> str:
        """The design as text: the amplitudes, what each effect leaves of the other, the power,
        how many positions the target needs, and the positions."""
        if self.inseparable:
            return self.inseparable
        if self.implausible:
            return "\n".join(
                f"not planned: {name}'s amplitude fitted on the data is implausible; to accept it "
                f"one would have to believe in {belief}; no positions are designed to separate "
                "a hypothesis no mechanism of its kind makes"
                for name, belief in self.implausible.items()
            )
        space = self.space
        a, b = self.pair
        lines = [
            f"design (separate {a} from {b}, T-optimal): {space.chosen_text(self.n_positions)}"
            + (f", after the {self.n_from} positions measured" if self.n_from else ""),
            space.limits_text,
            f"run: {self.plan.n_rows} measurements; {self.plan.rule}",
            f"noise: {self.noise_arcsec:.3g} arcsec per angle ({self.noise_source})",
        ]
        for h in self.hypotheses:
            lines.append(
                f"if {h.effect} is true ({_values(h.amplitude)} {h.unit}, "
                f"{self.amplitude_source[h.effect]}):"
            )
            if h.settled_by == "parsimony":
                lines.append(
                    f"  {h.rival} reproduces it at every position, with {h.rival_added_rank} "
                    f"ranks against its {h.added_rank}: the diagnosis names {h.effect} for its "
                    "fewer parameters unless the noise pays for the others"
                )
            else:
                where = [f"chi2 = {h.misfit_chi2:.3g} here"]
                if h.misfit_measured_chi2 is not None:
                    where.append(f"{h.misfit_measured_chi2:.3g} on the positions measured")
                if h.misfit_grid_chi2 is not None:
                    where.append(f"{h.misfit_grid_chi2:.3g} on a 30-degree grid of this size")
                lines.append(f"  fitting {h.rival} instead leaves {'; '.join(where)}")
            if not h.determined:
                lines.append(
                    f"  its parameters are not all determined here (traded off): the diagnosis "
                    f"puts it first only when it explains twice what {h.rival} does"
                )
            also = []
            if h.power_measured is not None:
                also.append(f"on the positions measured alone {_percent(h.power_measured)}")
            if h.power_new_alone is not None:
                also.append(f"on the new ones alone {_percent(h.power_new_alone)}")
            lines.append(
                f"  chance that the diagnosis names {h.effect}: {_percent(h.power)}"
                + (f" ({'; '.join(also)})" if also else "")
            )
        lines.append(f"power (the smaller chance of the right name): {_percent(self.power)}")
        lines.append(self._count_line())
        if self.n_from:
            lines.append(
                "measure these positions and diagnose them together with the data measured "
                "(append their rows): the chances above are for both"
            )
        lines += space.positions_lines(self.positions_deg)
        return "\n".join(lines)

    def _count_line(self) -> str:
        """How many positions the target needs, in words."""
        a, b = self.pair
        if self.positions_for_power is None:
            return (
                f"{self.target:.0%} needs more than {MAX_POWER_POSITIONS} positions of this kind: "
                "no practical set of positions separates them at these amplitudes and noise; "
                f"an independent measurement does. For {a}: {self.space.effects[0].confirm} "
                f"For {b}: {self.space.effects[1].confirm}"
            )
        count = self.positions_for_power
        besides = " besides those measured" if self.n_from else ""
        if self.positions_for_power_designed:
            return (
                f"{self.target:.0%} needs {count} position{'s' if count > 1 else ''}{besides}: "
                f"design {argument('separate')} {a},{b} {argument('n_positions')} {count} gives "
                f"{_percent(self.power_at_positions_for_power)}"
            )
        return (
            f"{self.target:.0%} needs about {count} positions{besides} (this design repeated "
            f"in proportion: {_percent(self.power_at_positions_for_power)})"
        )


def _percent(value: float | None) -> str:
    return "-" if value is None else f"{100.0 * value:.1f} %"


def _columns(model, effect) -> tuple[np.ndarray, list[str]]:
    """The parameter indices of ``effect`` in ``model`` and their names within the effect."""
    prefix = f"{effect.name}."
    columns = np.array([i for i, n in enumerate(model.parameter_names) if n.startswith(prefix)])
    return columns, [model.parameter_names[i].split(".", 1)[1] for i in columns]


def _in_user_units(model, effect, vector) -> dict[str, float]:
    """``effect``'s parameters ``vector`` (internal units, the model's order) by name, user
    units."""
    columns, names = _columns(model, effect)
    return {
        n: float(v / model.per_user_unit[i]) for n, i, v in zip(names, columns, vector, strict=True)
    }


def _amplitude_vector(model, effect, values: Mapping[str, float]) -> np.ndarray:
    """``values`` (user units) of ``effect``'s parameters as a vector in internal units, in the
    model's order (parameters not given are zero).

    Raises:
        InputError: a name that is not one of the effect's parameters.
    """
    columns, names = _columns(model, effect)
    unknown = [k for k in values if k not in names]
    if unknown:
        raise InputError(
            f"effect '{effect.name}' has no parameter '{unknown[0]}'; its parameters: "
            + ", ".join(names)
        )
    return np.array(
        [float(values.get(n, 0.0)) * model.per_user_unit[i] for n, i in zip(names, columns,
                                                                              strict=True)]
    )  # fmt: skip


def _fitted_amplitude(data, effect, table) -> dict[str, float]:
    """``effect``'s parameters fitted with the base errors on ``data``, user units."""
    where = data.source or "the data"
    try:
        fit = fit_orientation(data, [effect], turntable=table)
    except (InputError, IdentifiabilityError) as exc:
        raise InputError(
            f"{argument('from_data')} {where}: {effect.name} cannot be fitted there ({exc})"
        ) from None
    return _in_user_units(fit.model, effect, fit.result.params[_columns(fit.model, effect)[0]])


class _Rows:
    """Whitened rows (m', n) of the base errors and ``problem``'s two effects (the measured data
    as the square root of their information: only the Gram matrix matters), standing for
    ``observations`` measured angles, and what the diagnosis would make of them
    (:meth:`numbers`). ``leader``: the effect the diagnosis lists first (catalogue order), first
    when the two fit exactly alike with the same determination."""

    def __init__(self, problem: _Problem, rows, observations: int, leader: int) -> None:
        self.rows, self.observations, self.leader = rows, int(observations), int(leader)
        self.base, self.own, self.amplitude = problem.base, problem.own, problem.vectors
        self.candidates = int(problem.size)  # K, the catalogued effects tried at once

    def signal(self, x: int) -> np.ndarray:
        """Effect ``x``'s noise-free prediction (in noise sigmas)."""
        return self.rows[:, self.own[x]] @ self.amplitude[x]

    def fitted(self, x: int) -> np.ndarray:
        """The columns fitted when effect ``x`` is the rival: the base and its own."""
        return self.rows[:, np.concatenate([self.base, self.own[x]])]

    def residual(self, x: int) -> np.ndarray:
        """What the base errors and the other effect leave of effect ``x``'s prediction, per
        row (in noise sigmas)."""
        return residual(self.fitted(1 - x), self.signal(x))

    def numbers(self, x: int) -> dict:
        """Effect ``x`` as the truth against the other (module docstring): its signal beyond
        the base and the rival's misfit (chi2), the ranks each adds, whether the data determine
        each one's parameters, and the chances that the diagnosis accepts it, puts it first,
        or takes it on top of the rival and drops the rival."""
        y = 1 - x
        m = self.observations
        first_round = acceptance_threshold(self.candidates)
        second_round = acceptance_threshold(self.candidates - 1)
        signal = self.signal(x)
        base = self.rows[:, self.base]
        own_x, own_y = self.rows[:, self.own[x]], self.rows[:, self.own[y]]
        weights, nc, k_x, k_y = rss_difference(base, own_x, own_y, signal)
        alone = misfit(base, signal)
        left = misfit(self.fitted(y), signal)
        detect = detection_power(alone, k_x, m, first_round) if k_x else 0.0
        # First round: the effect put first (determined ones first, then by delta_bic) ...
        first = generalized_chi2_sf(choice_margin(k_x, k_y, m), weights, nc)
        determined = (not traded_off(base, own_x), not traded_off(base, own_y))
        if not weights.size:  # the same span: the same fit, whatever the noise
            first = float(determined[0] > determined[1] or (
                determined[0] == determined[1] and self.leader == x))  # fmt: skip
        elif determined == (False, True):
            # ... an undetermined one only when it explains more than twice what the rival
            # does: gain_x - r gain_y = y^T (P_x - P_0 - r (P_y - P_0)) y > 0.
            ratio = UNDETERMINED_GAIN_RATIO
            terms = [(self.fitted(x), 1.0), (base, ratio - 1.0), (self.fitted(y), -ratio)]
            first *= generalized_chi2_sf(0.0, *quadratic_form(terms, signal))
        # ... or the rival first, this one accepted on top of it (the nested test: a
        # non-central chi-square of what the rival leaves of it), and the rival then dropped
        # as not needed beside it (a central one below the first round's threshold).
        rank_0 = orthonormal_span(base).shape[1]
        both = orthonormal_span(np.hstack([base, own_x, own_y])).shape[1] - rank_0
        k_on_top, k_rival = both - k_y, both - k_x
        on_top = detection_power(left, k_on_top, m, second_round) if k_on_top else 0.0
        dropped = 1.0 - detection_power(0.0, k_rival, m, first_round) if k_rival else 1.0
        choice = 1.0 - (1.0 - first) * (1.0 - on_top * dropped)
        return {
            "signal_chi2": alone,
            "misfit_chi2": left,
            "added_rank": k_x,
            "rival_added_rank": k_y,
            "determined": determined[0],
            "rival_determined": determined[1],
            "power_detect": detect,
            "power_first": first,
            "power_on_top": on_top * dropped,
            "power_choice": choice,
            "power": detect * choice,
        }

    def power(self) -> float:
        """The smaller chance of the right name (either effect true)."""
        return min(self.numbers(x)["power"] for x in range(2))


def design_separate(
    space: DesignSpace,
    n_positions: int,
    *,
    from_data=None,
    amplitudes: Mapping[str, Mapping[str, float]] | None = None,
    noise_arcsec: float | None = None,
    dwell_s: float = 60.0,
    target: float = POWER_TARGET,
) -> SeparationDesign:
    """The ``n_positions`` of ``space`` that tell its two effects apart (module docstring).

    Args:
        space: the table, the two effects (A, B), limits and candidates
            (:func:`~.space.design_space`).
        n_positions: how many positions to choose.
        from_data: measurements already made (``OrientationMeasurements``): the design adds to
            their positions; each effect not in ``amplitudes`` is fitted on them with the base
            errors; without ``noise_arcsec`` their noise is the new measurements' noise.
        amplitudes: ``{effect: {parameter: value in its user units}}`` (parameters not given
            are zero).
        noise_arcsec: 1-sigma noise of a measured angle (default: from ``from_data``, else 1).
        dwell_s: time between measurements, seconds (the plan's ``time_s``).
        target: the chance of the right name :attr:`SeparationDesign.positions_for_power` is
            given for.

    Raises:
        InputError: ``n_positions`` not from 1 to the candidates (checked first); not two
            distinct effects; an effect with neither an amplitude nor data to
            fit it on; an effect whose prediction no position within the limits sees beyond the
            base errors; more positions than candidates.
    """
    n_positions = check_positions_count(n_positions, space.candidates_deg.shape[0])
    with one_blas_thread():  # tall-by-small products: many threads on busy cores only wait
        return _design_separate(
            space, n_positions, from_data, amplitudes, noise_arcsec, dwell_s, target
        )


def _design_separate(space, n_positions, from_data, amplitudes, noise_arcsec, dwell_s, target):
    """:func:`design_separate`, on one BLAS thread."""
    problem = _setup(space, n_positions, from_data, amplitudes, noise_arcsec, dwell_s)
    implausible = _implausible(problem)
    if implausible:
        none = np.zeros((0, space.n_joints))
        return problem.result(target, none, positions_deg=none, implausible=implausible)
    names, settled = problem.names, _settled(problem)
    if "none" in settled:
        x = settled.index("none")
        because = (
            f"{names[1 - x]} reproduces {names[x]} ({_values(problem.user[x])} "
            f"{problem.units[x]}) at every position, with no more parameters"
        )
        return _inseparable(problem, target, because)
    directions = problem.directions(settled)
    found, chosen, plan, new = problem.run_of(directions, n_positions)
    design = problem.rows_of(new, 3 * plan.n_rows)
    numbers = [design.numbers(x) for x in range(2)]
    power = min(h["power"] for h in numbers)

    def scaled(count: int) -> float:
        factor = count / n_positions
        return problem.rows_of(new, round(3 * plan.n_rows * factor), factor).power()

    def designed(count: int) -> float:
        run = problem.run_of(directions, count)
        return problem.rows_of(run[3], 3 * run[2].n_rows).power()

    count, count_power, verified = _positions_for(
        scaled, designed, target, n_positions, power, int(problem.c.keep.sum())
    )
    measured = np.zeros((0, space.n_joints))
    if from_data is not None:
        measured = np.degrees(np.asarray(from_data.joint_rad, dtype=float))
    return problem.result(
        target,
        measured,
        positions_deg=space.candidates_deg[chosen][plan.first_order()],
        plan=plan,
        hypotheses=_hypotheses(problem, settled, numbers, new, plan, n_positions),
        misfit_by_position=_shares(design, new, plan, n_positions),
        power=float(power),
        positions_for_power=count,
        power_at_positions_for_power=count_power,
        positions_for_power_designed=verified,
        power_curve=tuple((c, scaled(c)) for c in _curve_counts(n_positions, count)),
        catalogue_size=problem.size,
        n_swaps=found.swaps,
        n_passes=found.passes,
    )


def _setup(space, n_positions, from_data, amplitudes, noise_arcsec, dwell_s) -> _Problem:
    """The :class:`_Problem` of ``space``'s two effects on its candidates (see
    :func:`design_separate` for what is refused)."""
    names, amplitudes = _checked_pair(space, amplitudes)
    c = candidate_rows(space, n_positions, from_data, noise_arcsec, dwell_s)
    model = c.model
    source, vectors, user, units = _amplitudes(model, space, amplitudes, from_data)
    listed = [e.name for e in catalogue(space.table)]
    rank = [listed.index(name) if name in listed else len(listed) for name in names]
    fixed = None if c.information is None else information_rows(c.information, ROUNDING_ROWS)
    return _Problem(
        space, c, dwell_s, np.arange(len(model.base_names)),
        tuple(_columns(model, e)[0] for e in space.effects), vectors, fixed, len(listed),
        0 if rank[0] <= rank[1] else 1, names, user, units, source,
    )  # fmt: skip


def _hypotheses(problem, settled, numbers, new, plan, n_positions) -> tuple[Hypothesis, ...]:
    """Each effect as the truth: on the design (``numbers``), on the positions measured alone,
    on the new ones alone and on the grid of the design's size."""
    measured = alone = [None, None]
    if problem.fixed is not None:
        measured = [problem.rows_of(None, 0).numbers(x) for x in range(2)]
        alone = [problem.rows(new, 3 * plan.n_rows, leader=0).numbers(x) for x in range(2)]
    grid = _grid_misfits(problem, n_positions)
    names = problem.names
    return tuple(
        Hypothesis(
            effect=names[x],
            rival=names[1 - x],
            amplitude=problem.user[x],
            unit=problem.units[x],
            misfit_measured_chi2=None if measured[x] is None else measured[x]["misfit_chi2"],
            misfit_grid_chi2=None if grid is None else grid[x],
            settled_by=settled[x],
            power_measured=None if measured[x] is None else measured[x]["power"],
            power_new_alone=None if alone[x] is None else alone[x]["power"],
            **numbers[x],
        )  # fmt: skip
        for x in range(2)
    )


def _checked_pair(space, amplitudes) -> tuple[tuple[str, str], dict]:
    """The two effects' names and the amplitudes given (``{effect: {parameter: value}}``), or
    :class:`InputError`."""
    names = tuple(e.name for e in space.effects)
    if len(names) != 2 or names[0] == names[1]:
        raise InputError(
            f"{argument('separate')} takes two different effects (A,B), got "
            f"{', '.join(names) or 'none'}"
        )
    amplitudes = {k: dict(v) for k, v in (amplitudes or {}).items()}
    unknown = [k for k in amplitudes if k not in names]
    if unknown:
        raise InputError(
            f"{argument('amplitude')} names effect '{unknown[0]}', which is not one of "
            f"{names[0]}, {names[1]}"
        )
    return names, amplitudes


def _amplitudes(model, space, amplitudes, from_data):
    """Each effect's amplitude: where it comes from (``{effect: text}``), its vector (internal
    units), its values by parameter and its unit(s) (user units)."""
    source, vectors = {}, []
    for effect in space.effects:
        if effect.name in amplitudes:
            values, source[effect.name] = amplitudes[effect.name], "given"
        elif from_data is not None:
            values = _fitted_amplitude(from_data, effect, space.table)
            source[effect.name] = f"fitted on {from_data.source or 'the data measured'}"
        else:
            raise InputError(
                f"no amplitude for {effect.name}: give it "
                f"({argument('amplitude')} {effect.name}:P=V,...) or the data to fit it on "
                f"({argument('from_data')} DATA.csv)"
            )
        vectors.append(_amplitude_vector(model, effect, values))
    own = [_columns(model, e)[0] for e in space.effects]
    user = [_in_user_units(model, e, v) for e, v in zip(space.effects, vectors, strict=True)]
    units = [", ".join(dict.fromkeys(model.parameter_units[i] for i in own[x])) for x in range(2)]
    return source, vectors, user, units


def _implausible(problem: _Problem) -> dict[str, str]:
    """``{effect: what one would have to believe}`` of each effect whose amplitude was fitted on
    the data and is beyond its plausible scale on this kind of machine (a given amplitude is the
    user's hypothesis, not judged)."""
    machine = MOUNT if problem.space.measured.telescope_mount else TURNTABLE
    out = {}
    for x, effect in enumerate(problem.space.effects):
        if problem.source[effect.name] == "given":
            continue
        judge = getattr(effect, "implausibility", None)
        belief = judge(problem.user[x], machine) if judge is not None else None
        if belief:
            out[effect.name] = belief
    return out


def _settled(problem: _Problem) -> list[str]:
    """How each direction is settled, judged over every candidate at once: ``misfit`` (positions
    separate it), ``parsimony`` (the rival reproduces it with more ranks) or ``none``.

    Raises:
        InputError: an effect whose prediction the base errors explain everywhere.
    """
    every = problem.rows(tall_r_factor(problem.c.rows.reshape(-1, problem.c.model.n_params)), 1)
    base, settled = every.rows[:, problem.base], []
    for x in range(2):
        signal = every.signal(x)
        alone = misfit(base, signal)
        if not alone > SAME_RTOL * max(float(signal @ signal), 1e-300):
            raise InputError(
                f"{problem.names[x]} at its amplitude ({_values(problem.user[x])} "
                f"{problem.units[x]}) changes nothing "
                "that the base errors do not explain at any position within the limits: there "
                "is nothing to separate"
            )
        if misfit(every.fitted(1 - x), signal) > SAME_RTOL * alone:
            settled.append("misfit")
            continue
        ranks = [
            orthonormal_span(np.hstack([base, every.rows[:, problem.own[z]]])).shape[1]
            for z in (x, 1 - x)
        ]
        settled.append("parsimony" if ranks[0] < ranks[1] else "none")
    return settled


def _shares(design: _Rows, new: np.ndarray, plan, n_positions: int) -> np.ndarray:
    """(N, 2) each position's share of each misfit (where the rival cannot follow), in the order
    the positions are first measured."""
    shares = np.zeros((n_positions, 2))
    for x in range(2):
        by_row = np.sum(design.residual(x)[: new.shape[0]].reshape(plan.n_rows, 3) ** 2, axis=1)
        per_position = np.bincount(plan.position, by_row, minlength=n_positions)
        shares[:, x] = per_position[plan.first_order()]
    return shares


@dataclass(frozen=True)
class _Problem:
    """The separation on the candidates (``c``: their whitened rows, the data measured, the noise,
    the run's times): the columns of the base errors and of each effect, the amplitudes (internal
    and user units), the data measured as rows of their information, the catalogue's size and
    which effect it lists first."""

    space: DesignSpace
    c: CandidateRows
    dwell_s: float
    base: np.ndarray
    own: tuple[np.ndarray, ...]
    vectors: list
    fixed: np.ndarray | None
    size: int
    leader: int
    names: tuple[str, str]
    user: list
    units: list
    source: dict

    def result(self, target: float, measured_deg: np.ndarray, **found) -> SeparationDesign:
        """The :class:`SeparationDesign` with what ``found`` says."""
        c = self.c
        return SeparationDesign(
            space=self.space, pair=self.names, measured_deg=measured_deg,
            noise_arcsec=float(c.noise), noise_source=c.noise_source,
            amplitude_source=self.source, n_from=c.n_from, target=float(target), **found,
        )  # fmt: skip

    def rows(self, rows: np.ndarray, observations: int, leader: int | None = None) -> _Rows:
        """:class:`_Rows` of ``rows`` standing for ``observations`` measured angles."""
        return _Rows(self, rows, observations, self.leader if leader is None else leader)

    def rows_of(self, new: np.ndarray | None, observations: int, factor: float = 1.0) -> _Rows:
        """The rows of a run (its Gram matrix times ``factor``) and of the data measured."""
        stacked = [new * math.sqrt(factor)] if new is not None else []
        stacked += [self.fixed] if self.fixed is not None else []
        return self.rows(np.concatenate(stacked), observations + self.c.from_rows)

    def directions(self, settled: list[str]) -> list:
        """The :class:`~turntable_pin.stats.discrimination.Direction` of each effect the
        positions must separate (``settled`` ``misfit``)."""
        rows, fixed, out = self.c.rows, self.fixed, []
        for x in (x for x in range(2) if settled[x] == "misfit"):
            fitted = np.concatenate([self.base, self.own[1 - x]])
            own, a = self.own[x], self.vectors[x]
            parts = [rows[:, :, fitted], rows[:, :, own] @ a]
            parts += [None, None] if fixed is None else [fixed[:, fitted], fixed[:, own] @ a]
            out.append(Direction(*parts))
        return out

    def run_of(self, directions, count: int):
        """The ``count`` designed positions: the exchange's result, their candidate indices,
        their run and its whitened rows."""
        space = self.space
        found = t_optimal_exchange(directions, count, seed=space.seed)
        chosen = np.flatnonzero(self.c.keep)[np.sort(found.chosen)]
        plan = plan_measurements(
            space.candidates_deg[chosen], needs_time=space.needs_time,
            needs_dirs=space.needs_dirs, dwell_s=self.dwell_s, seed=space.seed,
            start_s=self.c.start_s, visits=space.visits.subset(chosen), table=space.table,
        )  # fmt: skip
        variables = PositionVariables.of(plan.rows)
        jac = _evaluate(space, variables)[0].reshape(-1, self.c.model.n_params)
        return found, chosen, plan, jac / self.c.noise_rad


def _values(amplitude: Mapping[str, float]) -> str:
    return ", ".join(f"{k} = {v:.3g}" for k, v in amplitude.items())


def _grid_misfits(problem: _Problem, n_positions: int):
    """What each effect's rival leaves of it on the 30-degree grid within the limits, scaled to
    the design's size (with the data measured); ``None`` when no grid position can be used."""
    rows = grid_rows(problem.space, problem.c.start_s, problem.c.duration_s)[0]
    if not rows.shape[0]:
        return None
    factor = n_positions / rows.shape[0]
    on_grid = problem.rows_of(rows.reshape(-1, rows.shape[-1]) / problem.c.noise_rad, 0, factor)
    return [misfit(on_grid.fitted(1 - x), on_grid.signal(x)) for x in range(2)]


VERIFY_POSITIONS = 96
"""Counts for the target power up to this many are checked by designing them (larger ones are
the design's misfits scaled, which replicating it reaches)."""


def _positions_for(scaled_power, designed_power, target, n_design, power_design, n_candidates):
    """The fewest positions with at least ``target`` power, that many positions' power, and
    whether it was checked by designing them: estimated on the design scaled
    (``scaled_power(count)``: the design replicated, exact for whole multiples), then, up to
    :data:`VERIFY_POSITIONS`, checked by designing that many (``designed_power(count)``) and
    raised by a tenth when short (at most three times); ``(None, None, False)`` when even
    :data:`MAX_POWER_POSITIONS` (or every candidate) would not do."""
    top = min(MAX_POWER_POSITIONS, n_candidates)
    if scaled_power(top) < target:
        return None, None, False
    low, high = 0, top  # scaled_power(high) >= target
    while high - low > 1:
        middle = (low + high) // 2
        if scaled_power(middle) >= target:
            high = middle
        else:
            low = middle
    count = high
    for _ in range(4):
        if count == n_design:
            return count, float(power_design), True
        if count > VERIFY_POSITIONS:
            return count, float(scaled_power(count)), False
        checked = designed_power(count)
        if checked >= target or count >= top:
            return count, float(checked), True
        count = min(top, count + max(1, math.ceil(0.1 * count)))
    return count, float(designed_power(count)), True


def _curve_counts(n_design: int, n_target: int | None) -> list[int]:
    """The counts the power curve is drawn at: 1 to twice the larger of the design's and the
    target's (at most 40 points)."""
    top = 2 * max(n_design, n_target or 0)
    return sorted({int(round(c)) for c in np.linspace(1, top, min(top, 40))})


ROUNDING_ROWS = 1e-7
"""Rows of the measured data's information root (whitened) below this fraction of the largest
are rounding (an eigenvalue of 1e-14 of the largest), not directions the data see: kept, they
would count as seen once a column is scaled to unit norm."""


def _inseparable(problem: _Problem, target, because):
    """The result when no positions within the limits separate the two effects: one line saying
    why, and the independent measurements of their ``confirm`` texts."""
    space = problem.space
    a, b = space.effects
    limits = "; ".join(r.describe() for r in space.ranges)
    text = (
        f"no positions within the joints' limits ({limits}) separate {a.name} from {b.name}: "
        f"{because}; an independent measurement does. For {a.name}: {a.confirm} "
        f"For {b.name}: {b.confirm}"
    )
    none = np.zeros((0, space.n_joints))
    return problem.result(target, none, positions_deg=none, inseparable=text)
