"""D-optimal positions that identify the base errors and the chosen effects (issue 19, item 1).

What orientation data can determine is a set of *combinations* of the parameters (the base
errors, the effects' parameters): a position measures ``dpsi, dtheta, dgamma``, linear in the
parameters near zero (the Jacobian of :class:`~turntable_pin.measurement.effect_model.
OrientationModel`), and some directions (``dphi_y1 - deps_y`` on the paper's table) change no
orientation anywhere. Those flat directions would make every design singular, so the design
works on the combinations that *some* position within the limits determines: the row space of
the Jacobian over all the candidates (:func:`~turntable_pin.stats.least_squares.
analyse_identifiability`, the same rule as the fit's), in whitened coordinates; the flat
directions are reported as what no position within the limits can determine.

The positions maximise ``log det`` of the Fisher information of those combinations (D-optimal,
as FIGAROH chooses robot calibration postures): a greedy start and Fedorov's exchange over the
candidates (:mod:`turntable_pin.stats.design`), each candidate measured as the run will measure
it (:mod:`.schedule`: twice, early and late, for a drift; from both sides for a backlash). Each
combination's expected standard error is then read from the information of the run as it will
be made (``sqrt(c M^-1 c^T)`` at the noise), the numbers ``fit`` reports on its data; and the
design is compared with the 30-degree grid within the limits: the D-efficiency
``(det M_design / det M_grid)^(1/p)`` per position (the grid's information scaled to the
design's number of positions), above 1 when the design does better.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np

from ..calibration.positions import PositionSet
from ..core.blas_threads import one_blas_thread
from ..core.exceptions import InputError, TurntablePinError
from ..core.notebook import NotebookResult
from ..core.sizes import check_positions_count
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..core.words import argument, command
from ..measurement.effect_model import OrientationModel
from ..measurement.effects.base import PositionVariables
from ..measurement.fit import fit_orientation
from ..stats.design import (
    d_optimal_design,
    greedy_design,
    information,
    information_rows,
    log_det,
)
from ..stats.least_squares import analyse_identifiability, combination_name, tall_r_factor
from .schedule import MeasurementPlan, Visits, candidate_visits, plan_measurements
from .space import DesignSpace

__all__ = [
    "CandidateRows",
    "IdentifyDesign",
    "candidate_rows",
    "design_identify",
    "design_rows",
    "grid_rows",
]

DEFAULT_NOISE_ARCSEC = 1.0
"""Noise of a measured angle when neither ``noise_arcsec`` nor data say it, arc seconds."""


@dataclass(frozen=True)
class IdentifyDesign(NotebookResult):
    """D-optimal positions and what they will determine.

    Attributes:
        space: the :class:`~.space.DesignSpace`.  plan: the run that measures the positions.
        positions_deg: the chosen positions (N, J), degrees (in the run's first order).
        combinations: each determined combination: ``name``, ``unit``, ``coefficients`` and its
            expected standard error on the design (``std``), on the grid as measured
            (``std_grid``) and on the grid at the design's size (``std_grid_same_n``; ``None``
            where the grid does not determine it).
        undetermined: the combinations no position within the limits determines.
        noise_arcsec, noise_source: the noise of a measured angle and where it comes from.
        n_from: positions already measured (``from_data``), 0 without.
        log_det, log_det_grid_same_n: ``log det`` of the information of the determined
            combinations (user units; with the data measured) on the design and on the grid at
            its size; d_efficiency: ``exp((log_det - log_det_grid_same_n) / p)`` (``None`` when
            the grid determines not all).
        n_grid: positions of the grid.  greedy_log_det: ``log det`` after the greedy start.
        n_exchanges, n_sweeps: of the exchange.
    """

    space: DesignSpace = field(repr=False)
    positions_deg: np.ndarray = field(repr=False)
    plan: MeasurementPlan = field(repr=False)
    combinations: tuple[dict, ...]
    undetermined: tuple[str, ...]
    noise_arcsec: float
    noise_source: str
    n_from: int
    log_det: float
    log_det_grid_same_n: float | None
    d_efficiency: float | None
    n_grid: int
    greedy_log_det: float
    n_exchanges: int
    n_sweeps: int

    @property
    def n_positions(self) -> int:
        """Number of positions chosen N."""
        return int(self.positions_deg.shape[0])

    @property
    def rank(self) -> int:
        """Number of determined combinations p."""
        return len(self.combinations)

    def comment(self) -> str:
        """The comment lines of the positions' CSV: what made it, with its seed."""
        effects = ", ".join(self.space.effect_names) or "none"
        return "\n".join(
            [
                f"designed by {command('design')} (identify: D-optimal)",
                f"table: {self.space.table_name}; effects: {effects}",
                f"{self.space.seed_text(self.n_positions)} n_from={self.n_from}",
                self.space.limits_text,
                f"noise_arcsec={self.noise_arcsec:g} ({self.noise_source})",
                f"run: {self.plan.rule}",
            ]
        )

    def to_dict(self) -> dict:
        """The design as a JSON-ready dict."""
        return {
            "mode": "identify",
            "space": self.space.to_dict(),
            "n_positions": self.n_positions,
            "n_from": self.n_from,
            "noise_arcsec": self.noise_arcsec,
            "noise_source": self.noise_source,
            "rank": self.rank,
            "log_det": self.log_det,
            "log_det_grid_same_n": self.log_det_grid_same_n,
            "d_efficiency": self.d_efficiency,
            "n_grid": self.n_grid,
            "greedy_log_det": self.greedy_log_det,
            "n_exchanges": self.n_exchanges,
            "n_sweeps": self.n_sweeps,
            "combinations": [dict(c) for c in self.combinations],
            "undetermined": list(self.undetermined),
            "positions_deg": self.positions_deg.tolist(),
            "plan": self.plan.to_dict(),
        }

    def report(self) -> str:
        """The design as text: what it determines, how well, against the grid, the positions."""
        space = self.space
        effects = " + ".join(("base", *space.effect_names))
        lines = [
            f"design (identify, D-optimal): {space.chosen_text(self.n_positions)}, for {effects}"
            + (f", after the {self.n_from} positions measured" if self.n_from else ""),
            space.limits_text,
            f"run: {self.plan.n_rows} measurements; {self.plan.rule}",
            f"noise: {self.noise_arcsec:.3g} arcsec per angle ({self.noise_source})",
        ]
        if self.d_efficiency is not None:
            lines.append(
                f"D-efficiency against the {self.n_grid}-position 30-degree grid: "
                f"{self.d_efficiency:.3f} per position (log det {self.log_det:.2f} against "
                f"{self.log_det_grid_same_n:.2f} for the grid's information at "
                f"{self.n_positions} positions)"
            )
        else:
            lines.append(
                f"the {self.n_grid}-position 30-degree grid within the limits does not determine "
                "every combination (no D-efficiency)"
            )
        lines.append(
            f"expected standard error of each of the {self.rank} determined combinations "
            f"(design; grid of {self.n_grid}; grid scaled to {self.n_positions} positions):"
        )
        for c in self.combinations:
            grid = "  ".join(
                f"{c[k]:8.3g}" if c[k] is not None else "       -"
                for k in ("std_grid", "std_grid_same_n")
            )
            lines.append(f"  {c['name']:55s} {c['std']:8.3g}  {grid}  {c['unit']}")
        if self.undetermined:
            lines.append(
                "not determined by any position within the limits: " + "; ".join(self.undetermined)
            )
        lines += space.positions_lines(self.positions_deg)
        return "\n".join(lines)


def _evaluate(space: DesignSpace, variables):
    """The Jacobian (M, 3, n) at zero of the base errors and ``space.effects`` at ``variables``,
    and the model (its parameter names, units)."""
    model = OrientationModel(variables, space.effects, space.table)
    return model.jacobian(np.zeros(model.n_params)), model


def _variables(space, joint_deg: np.ndarray, visits: Visits, start_s: float, duration_s: float):
    """Variables of every position in ``joint_deg`` (C, J) measured as ``visits`` says,
    position-major (C * visits.count rows)."""
    fractions = visits.time_fractions()
    signs = visits.signs()
    rows = PositionSet(
        np.repeat(joint_deg / DEG_PER_RAD, visits.count, axis=0), table=space.table,
        time_s=None if fractions is None else start_s + fractions.reshape(-1) * duration_s,
        dirs=() if signs is None else tuple(signs.reshape(-1, joint_deg.shape[1]).T),
    )  # fmt: skip
    return PositionVariables.of(rows)


def design_rows(
    space: DesignSpace, joint_deg, visits: Visits, start_s: float = 0.0, duration_s: float = 0.0
):
    """The Jacobian rows (C, 3 * visits, n) of each position of ``joint_deg`` (C, J) measured as
    ``visits`` says (internal units: rad per rad; the run lasting ``duration_s`` from
    ``start_s``), the mask (C,) of the positions every effect is defined at (an effect may
    refuse some: ``TX`` at the horizon) and the model.

    The rows of positions an effect refuses, or whose derivatives are not finite, are left out
    (bisection over the positions, so that a few refused ones cost a few evaluations).
    """
    joint_deg = np.asarray(joint_deg, dtype=float)
    keep = np.ones(joint_deg.shape[0], dtype=bool)

    def rows_of(index: np.ndarray):
        variables = _variables(space, joint_deg[index], visits.subset(index), start_s, duration_s)
        jac, model = _evaluate(space, variables)
        return jac.reshape(index.size, 3 * visits.count, -1), model

    def search(index: np.ndarray) -> None:
        try:
            rows_of(index)
        except InputError:
            if index.size == 1:
                keep[index] = False
                return
            half = index.size // 2
            search(index[:half])
            search(index[half:])

    try:
        rows, model = rows_of(np.arange(joint_deg.shape[0]))
    except InputError:
        search(np.arange(joint_deg.shape[0]))
        if not keep.any():
            raise
        rows, model = rows_of(np.flatnonzero(keep))
        full = np.full((joint_deg.shape[0], *rows.shape[1:]), np.nan)
        full[keep] = rows
        rows = full
    finite = np.all(np.isfinite(rows), axis=(1, 2))
    keep &= finite
    return rows[keep], keep, model


def grid_rows(space: DesignSpace, start_s: float, duration_s: float):
    """:func:`design_rows` of the 30-degree grid within the limits, measured by the same rules
    as the candidates (its visits seeded apart from theirs)."""
    visits = candidate_visits(
        space.grid_deg.shape[0], space.n_joints, needs_time=space.needs_time,
        needs_dirs=space.needs_dirs, rng=np.random.default_rng([space.seed, 2]),
    )  # fmt: skip
    return design_rows(space, space.grid_deg, visits, start_s, duration_s)


def _start_information(space, data, noise_arcsec, dwell_s: float):
    """What the data already measured bring: ``(information (n, n) or None, noise of the new
    measurements in arcsec, where it comes from, positions measured, time after them)``."""
    if data is None:
        noise = DEFAULT_NOISE_ARCSEC if noise_arcsec is None else float(noise_arcsec)
        return None, noise, "default" if noise_arcsec is None else "given", 0, 0.0
    where = data.source or "the data"
    try:
        jac, model = _evaluate(space, data.variables())
    except InputError as exc:
        raise InputError(f"{argument('from_data')} {where}: {exc.detail}") from None
    mask = data.measured.reshape(-1)
    jac = jac.reshape(-1, model.n_params)[mask]
    known = data.sigma_rad is not None and not data.sigma_relative
    if known:
        sigma_rad = np.broadcast_to(
            np.asarray(data.sigma_rad, dtype=float).reshape(data.n_positions, -1),
            (data.n_positions, 3),
        ).reshape(-1)[mask]
        median = float(np.median(sigma_rad)) * ARCSEC_PER_RAD
        noise, source = median, "the median sigma of the data measured"
    elif noise_arcsec is not None:
        sigma_rad = np.full(jac.shape[0], float(noise_arcsec) / ARCSEC_PER_RAD)
        noise, source = float(noise_arcsec), "given"
    else:
        try:
            fit = fit_orientation(data, space.effects, turntable=space.table)
        except TurntablePinError as exc:
            raise InputError(
                f"{argument('from_data')} {where}: their noise cannot be fitted ({exc}); give "
                f"{argument('noise_arcsec')}"
            ) from None
        sigma_rad = fit.sigma_angles_rad.reshape(-1)[mask]
        noise = float(np.median(sigma_rad)) * ARCSEC_PER_RAD
        source = "fitted on the data measured"
    if noise_arcsec is not None:
        noise, source = float(noise_arcsec), "given"
    weighted = jac / sigma_rad[:, None]
    start_s = 0.0
    if data.time_s is not None and space.needs_time:
        start_s = float(np.max(data.time_s)) + float(dwell_s)
    return weighted.T @ weighted, noise, source, data.n_positions, start_s


def _invisible_effect(space, model, stacked: np.ndarray) -> str | None:
    """Why one of the effects cannot be identified on the ``stacked`` rows (all the candidates):
    its parameters add no determined combination to the base errors (no position sees it) or
    to the other effects (naming those that explain it); ``None`` when every effect adds one."""
    names = np.array(model.parameter_names)
    owner = {e.name: np.array([n.startswith(f"{e.name}.") for n in names]) for e in space.effects}

    def rank(columns: np.ndarray) -> int:
        return analyse_identifiability(stacked[:, columns], tuple(names[columns])).rank

    everything = np.ones(names.size, dtype=bool)
    full = rank(everything)
    for effect in space.effects:
        own = owner[effect.name]
        if not own.any() or rank(~own) < full:
            continue
        base = ~np.any(list(owner.values()), axis=0)
        if rank(base | own) == rank(base):
            return (
                f"effect '{effect.name}' changes nothing that the base errors do not already "
                "explain at any position within the limits: no position can see it; leave it out "
                f"of {argument('effects')} or widen the limits"
            )
        culprits = [
            other.name
            for other in space.effects
            if other is not effect and rank(~owner[other.name]) > rank(~owner[other.name] & ~own)
        ]
        return (
            f"effect '{effect.name}' changes nothing that "
            + " and ".join(f"'{c}'" for c in culprits or ["the other effects"])
            + f" (with the base errors) {'does' if len(culprits) == 1 else 'do'} not already "
            "explain at any position within the limits:"
            " no position tells them apart; fit one of them, or widen the limits"
        )
    return None


def _fewest_positions(rows, start, rank) -> int | None:
    """The fewest candidates the greedy design needs to determine ``rank`` combinations (None:
    not even twice ``rank``)."""
    count = min(rows.shape[0], 2 * rank + 2)
    order = greedy_design(rows, count, start)
    for i in range(1, order.size + 1):
        if np.isfinite(log_det(information(rows, order[:i], start))):
            return i
    return None


def _standard_errors(information: np.ndarray, to_user: np.ndarray) -> list[float | None]:
    """The standard error of each combination ``to_user @ z`` (rows of ``to_user``) under the
    information (r, r) of ``z``; ``None`` for one the information does not determine."""
    values, vectors = np.linalg.eigh(0.5 * (information + information.T))
    top = max(float(values.max(initial=0.0)), 1e-300)
    live = values > 1e-10 * top
    projected = to_user @ vectors  # (r, r)
    out: list[float | None] = []
    for row in projected:
        norm = float(np.linalg.norm(row))
        if np.linalg.norm(row[~live]) > 1e-6 * max(norm, 1e-300):
            out.append(None)
            continue
        out.append(float(np.sqrt(np.sum(row[live] ** 2 / values[live]))))
    return out


def design_identify(
    space: DesignSpace,
    n_positions: int,
    *,
    from_data=None,
    noise_arcsec: float | None = None,
    dwell_s: float = 60.0,
) -> IdentifyDesign:
    """The D-optimal ``n_positions`` of ``space`` (module docstring).

    Args:
        space: the table, effects, limits and candidates (:func:`~.space.design_space`).
        n_positions: how many positions to choose.
        from_data: measurements already made (``OrientationMeasurements``): their information
            is where the design starts; without ``noise_arcsec`` their noise (their sigma
            column, else fitted) is the new measurements' noise.
        noise_arcsec: 1-sigma noise of a measured angle (default: from ``from_data``, else 1).
        dwell_s: time between measurements, seconds (the plan's ``time_s``).

    Raises:
        InputError: ``n_positions`` not from 1 to the candidates (checked first); no candidate
            where the effects are defined; fewer positions than the combinations need; an
            effect that no position within the limits can see; positions that cannot determine
            every combination.
    """
    n_positions = check_positions_count(n_positions, space.candidates_deg.shape[0])
    with one_blas_thread():  # tall-by-small products: many threads on busy cores only wait
        return _design_identify(space, n_positions, from_data, noise_arcsec, dwell_s)


def _design_identify(space, n_positions, from_data, noise_arcsec, dwell_s) -> IdentifyDesign:
    """:func:`design_identify`, on one BLAS thread."""
    c = candidate_rows(space, n_positions, from_data, noise_arcsec, dwell_s)
    n = c.model.n_params
    candidate_r = tall_r_factor(c.rows.reshape(-1, n))
    start_rows = () if c.information is None else (information_rows(c.information),)
    ident = analyse_identifiability(
        np.concatenate([candidate_r, *start_rows]), c.model.parameter_names
    )
    rank = ident.rank
    if rank == 0:
        raise InputError("no position within the limits determines any error of the table")
    invisible = _invisible_effect(space, c.model, candidate_r)
    if invisible:
        raise InputError(invisible)
    _check_enough_angles(n_positions, 3 * space.visits.count, c.from_rows, rank)
    # Whitened coordinates z of the determined combinations: parameters = basis @ z.
    basis = ident.basis / ident.singular_values[:rank]
    x = (c.rows.reshape(-1, n) @ basis).reshape(c.rows.shape[0], -1, rank)
    start = None if c.information is None else basis.T @ c.information @ basis
    # The exchange runs from the greedy design and from the grid (its best N, or completed):
    # never worse than the grid.
    first_grid = space.candidates_deg.shape[0] - space.grid_deg.shape[0]
    grid_start = np.flatnonzero(np.flatnonzero(c.keep) >= first_grid)
    found = d_optimal_design(x, n_positions, start, also_from=[grid_start])
    if not np.isfinite(found.log_det):
        fewest = _fewest_positions(x, start, rank)
        more = (
            f"the fewest that do: {fewest} ({argument('n_positions')} {fewest})"
            if fewest
            else "no number of them does: widen the limits or leave effects out"
        )
        raise InputError(
            f"{n_positions} positions within the limits cannot determine all {rank} "
            f"combinations; {more}"
        )
    chosen = np.flatnonzero(c.keep)[np.sort(found.chosen)]
    positions = space.candidates_deg[chosen]
    plan = plan_measurements(
        positions, needs_time=space.needs_time, needs_dirs=space.needs_dirs, dwell_s=dwell_s,
        seed=space.seed, start_s=c.start_s, visits=space.visits.subset(chosen), table=space.table,
    )  # fmt: skip

    def run_information(plan_: MeasurementPlan) -> np.ndarray:
        variables = PositionVariables.of(plan_.rows)
        z = _evaluate(space, variables)[0].reshape(-1, n) / c.noise_rad @ basis
        return z.T @ z

    zero = 0.0 if start is None else start
    m_design = run_information(plan) + zero
    m_grid, m_grid_n, n_grid = _grid_information(space, c, run_information, n_positions, dwell_s)
    # Combinations in user units: y = to_user @ z (pivot-scaled rows of the RREF, as fit names).
    pivots = [int(np.flatnonzero(row)[0]) for row in ident.determined]
    to_user = (ident.determined / c.model.per_user_unit[pivots][:, None]) @ basis
    shift = 2.0 * float(np.linalg.slogdet(to_user)[1])
    ld = log_det(m_design) - shift
    ld_grid = log_det(m_grid_n + zero) - shift
    finite_grid = bool(np.isfinite(ld_grid))
    return IdentifyDesign(
        space=space,
        positions_deg=positions[plan.first_order()],
        plan=plan,
        combinations=_combinations(
            ident, c.model, pivots, [m_design, m_grid + zero, m_grid_n + zero], to_user
        ),
        undetermined=_undetermined(ident, c.model),
        noise_arcsec=float(c.noise),
        noise_source=c.noise_source,
        n_from=c.n_from,
        log_det=float(ld),
        log_det_grid_same_n=float(ld_grid) if finite_grid else None,
        d_efficiency=float(np.exp((ld - ld_grid) / rank)) if finite_grid else None,
        n_grid=n_grid,
        greedy_log_det=float(found.greedy_log_det - shift),
        n_exchanges=found.n_exchanges,
        n_sweeps=found.n_sweeps,
    )


def _check_enough_angles(n_positions: int, per_position: int, from_rows: int, rank: int) -> None:
    """Refuse positions that measure no more angles (with those measured) than ``rank``."""
    if per_position * n_positions + from_rows <= rank:
        fewest = (rank - from_rows) // per_position + 1
        raise InputError(
            f"{n_positions} position{'s give' if n_positions > 1 else ' gives'} "
            f"{per_position * n_positions} measured angles"
            + (f" (with the {from_rows} measured)" if from_rows else "")
            + f", not more than the {rank} combinations to identify: choose at least {fewest} "
            f"positions ({argument('n_positions')})"
        )


def _grid_information(space, c: CandidateRows, run_information, n_positions: int, dwell_s: float):
    """The information of the 30-degree grid within the limits measured by the same rules (its
    positions where the effects are defined), as measured and at the design's size (its
    information per position, in a run as long as the design's: a drift rate is known better
    from a longer run, not from better positions), and the grid's number of positions."""
    grid = space.grid_deg[grid_rows(space, c.start_s, c.duration_s)[1]]
    n_grid, count = max(grid.shape[0], 1), space.visits.count

    def grid_information(dwell: float) -> np.ndarray:
        return run_information(
            plan_measurements(
                grid, needs_time=space.needs_time, needs_dirs=space.needs_dirs, dwell_s=dwell,
                seed=space.seed, start_s=c.start_s, table=space.table,
            )
        )  # fmt: skip

    same_duration = dwell_s * (n_positions * count - 1) / max(n_grid * count - 1, 1)
    m_grid_n = grid_information(same_duration) * (n_positions / n_grid)
    return grid_information(dwell_s), m_grid_n, int(grid.shape[0])


def _combinations(ident, model, pivots, informations, to_user) -> tuple[dict, ...]:
    """Each determined combination in user units (``name``, ``unit``, ``coefficients``) with its
    standard error under the design's, the grid's and the grid's at the design's size
    ``informations``."""
    names = model.parameter_names
    std, std_grid, std_grid_n = (_standard_errors(m, to_user) for m in informations)
    out = []
    for i, row in enumerate(ident.determined):
        coeffs = row * model.per_user_unit / model.per_user_unit[pivots[i]]
        out.append(
            {
                "name": combination_name(coeffs, names),
                "unit": model.parameter_units[pivots[i]],
                "coefficients": {a: float(c) for a, c in zip(names, coeffs, strict=True) if c},
                "std": std[i],
                "std_grid": std_grid[i],
                "std_grid_same_n": std_grid_n[i],
            }
        )
    return tuple(out)


def _undetermined(ident, model) -> tuple[str, ...]:
    """The combinations no position within the limits determines, in words (pivot-scaled)."""
    unit = model.per_user_unit
    return tuple(
        combination_name(row * unit / unit[int(np.flatnonzero(row)[0])], model.parameter_names)
        for row in ident.undetermined
    )


class CandidateRows(NamedTuple):
    """The candidates' whitened Jacobian rows (C', 3 * visits, n) and which candidates they are
    (``keep``, (C,)), the model, and what the data already measured bring
    (:func:`candidate_rows`)."""

    rows: np.ndarray
    keep: np.ndarray
    model: object
    information: np.ndarray | None
    noise: float
    noise_rad: float
    noise_source: str
    n_from: int
    from_rows: int
    start_s: float
    duration_s: float


def candidate_rows(space, n_positions, from_data, noise_arcsec, dwell_s) -> CandidateRows:
    """The :class:`CandidateRows` of a design of ``n_positions`` (after ``from_data``).

    Raises:
        InputError: no candidate where the effects are defined; fewer usable candidates than
            ``n_positions``; data measured that cannot be used.
    """
    information, noise, noise_source, n_from, start_s = _start_information(
        space, from_data, noise_arcsec, dwell_s
    )
    duration_s = (n_positions * space.visits.count - 1) * float(dwell_s)
    try:
        rows, keep, model = design_rows(
            space, space.candidates_deg, space.visits, start_s, duration_s
        )
    except InputError as exc:
        raise InputError(f"no candidate position within the limits can be used: {exc}") from None
    usable = int(keep.sum())
    if n_positions > usable:
        raise InputError(
            f"{n_positions} positions asked, but only {usable} candidates: give more "
            f"{argument('candidates')}"
        )
    noise_rad = noise / ARCSEC_PER_RAD
    from_rows = 0 if from_data is None else int(from_data.measured.sum())
    return CandidateRows(
        rows / noise_rad, keep, model, information, noise, noise_rad, noise_source, n_from,
        from_rows, start_s, duration_s,
    )  # fmt: skip
