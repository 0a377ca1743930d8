"""GyroWheel calibration positions least sensitive to the table's orientation errors (issue 19,
item 4: the paper's own question, section 2).

How accurate must a turntable be for a GyroWheel calibration of accuracy ``w_m``? For given
positions, the requirement box of :mod:`turntable_pin.calibration.requirement` (the largest box
of orientation errors whose every point keeps the rate errors of eqs. 7-14 within ``w_m``). To
first order the rate error at a position is ``J(p) (dpsi, dtheta, dgamma)`` (eq. 13 as printed),
so the most sensitive positions set the box: on the paper's Table 1 GyroWheel, gravity along the
payload's z axis bounds dpsi and dgamma (the 43.2 and 33.2 deg/h/g terms), gravity in or near
its x-y plane bounds dtheta (15 to 82 deg/h per rad, by its azimuth there).

The design chooses ``N`` positions within the joints' limits with the largest box (the loosest
requirement for the same ``w_m``) that still calibrate the 14 drift coefficients (eqs. 5-6) at
least as precisely as the reference: D-efficiency ``exp((log det M - log det M_ref) / 14)`` (``M``
both axes' information, :func:`~turntable_pin.calibration.gyrowheel.regressor_matrix`) at least
``min_efficiency`` (default 1). Without that floor, positions clustered where gravity changes the
drift least would give a loose requirement and a calibration that amplifies the noise unbounded.

The reference is the evenly spaced grid of ``N`` positions within the limits that calibrates
(:func:`comparison_grid`: on the paper's table ``grid:90x60`` for 24, ``grid:60`` for 36,
``grid:45`` for 64); it joins the candidates and starts the search, so the design is never worse.
The search (:func:`loosest_positions`) exchanges a position that bounds the box for a candidate
inside it while the floor holds and the box grows (or fewer positions bound it); when none can,
a Fedorov exchange among the positions inside the box
(:func:`~turntable_pin.stats.design.fedorov_exchange`) raises the precision to make room; it
ends when neither helps.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..calibration.drift_fit import require_identifiable
from ..calibration.gyrowheel import AXES, N_COEFFICIENTS, GyroWheelModel, regressor_matrix
from ..calibration.positions import PositionSet, position_inputs
from ..calibration.requirement import (
    OrientationRequirement,
    RequirementBox,
    check_accuracy_dph,
    holding_scale,
    largest_box,
    orientation_requirement,
    rate_error_jacobian,
    requirement_box,
)
from ..calibration.site import DEFAULT_LATITUDE_DEG
from ..core.blas_threads import one_blas_thread
from ..core.exceptions import IdentifiabilityError, InputError
from ..core.notebook import NotebookResult
from ..core.sizes import check_positions_count
from ..core.turn_grid import every_combination, full_turn_grid_deg
from ..core.units import DEG_PER_RAD
from ..core.words import argument, command
from ..model.angles import ANGLE_SYMBOLS
from ..stats.design import d_optimal_design, fedorov_exchange, log_det
from .schedule import MeasurementPlan, plan_measurements
from .space import DesignSpace

__all__ = [
    "DEFAULT_MIN_EFFICIENCY",
    "CalibrationDesign",
    "comparison_grid",
    "design_calibration",
    "loosest_positions",
]

DEFAULT_MIN_EFFICIENCY = 1.0
"""Default precision floor: the design calibrates the 14 coefficients at least as precisely
(D-efficiency) as the reference grid of the same number of positions."""

MAX_MIN_EFFICIENCY = 10.0
"""Largest precision floor accepted (no exact design is ten times as informative per
coefficient as a grid that calibrates)."""

MAX_STEPS = 5000
"""Most steps of the local search (each grows the box, or raises the precision)."""

_N_PARAMETERS = len(AXES) * N_COEFFICIENTS
_BINDS = 1e-7
"""A position bounds the box when its first-order worst case is within this fraction of w_m."""


# ---- the reference ---------------------------------------------------------------------------
def _factorizations(n: int, parts: int):
    """Every ordered tuple of ``parts`` positive integers whose product is ``n``."""
    if parts == 1:
        yield (n,)
        return
    for first in range(1, n + 1):
        if n % first == 0:
            for rest in _factorizations(n // first, parts - 1):
                yield (first, *rest)


def _evenly_spaced_deg(joint_range, count: int) -> np.ndarray:
    """``count`` angles evenly spaced over a joint's range: a full turn in steps of
    ``360/count`` from its start, a limited range from end to end (its middle for one)."""
    if joint_range.full_turn:
        return full_turn_grid_deg(360.0 / count, starts_deg=(joint_range.low_deg,))[:, 0]
    if count == 1:
        return np.array([0.5 * (joint_range.low_deg + joint_range.high_deg)])
    return np.linspace(joint_range.low_deg, joint_range.high_deg, count)


def comparison_grid(
    space: DesignSpace, n_positions: int, latitude_rad: float = np.radians(DEFAULT_LATITUDE_DEG)
) -> PositionSet:
    """The evenly spaced grid of ``n_positions`` within the limits that calibrates the 14 drift
    coefficients: of the ways to write ``N = n1 n2 ...`` (one count per joint), the most even
    one whose grid passes :func:`~turntable_pin.calibration.drift_fit.require_identifiable`.
    Where every joint turns a full turn from 0 it is the scheme ``grid:S1xS2`` (``S = 360/n``).

    Raises:
        InputError: no such grid (``N`` prime, or the limits too narrow), naming the shapes tried.
    """
    ranges = space.ranges
    shapes = sorted(_factorizations(n_positions, len(ranges)), key=lambda s: (max(s) / min(s), s))
    tried = []
    for shape in shapes:
        axes = [_evenly_spaced_deg(r, c) for r, c in zip(ranges, shape, strict=True)]
        if all(r.full_turn and r.low_deg == 0.0 for r in ranges):
            grid = PositionSet.grid(*(360.0 / c for c in shape), table=space.table)
        else:
            angles = every_combination(axes) / DEG_PER_RAD
            name = "x".join(str(c) for c in shape) + " evenly spaced within the limits"
            grid = PositionSet(angles, table=space.table, name=name)
        tried.append(grid.name)
        try:
            require_identifiable(position_inputs(grid, latitude_rad))
        except IdentifiabilityError:
            continue
        return grid
    raise InputError(
        f"no evenly spaced grid of {n_positions} positions within the limits calibrates the 14 "
        f"drift coefficients to compare the design with (tried {', '.join(tried)}); choose "
        f"another number of positions ({argument('n_positions')}), e.g. 24, 36 or 64"
    )


# ---- the search --------------------------------------------------------------------------------
def _stacked_rows(features: np.ndarray) -> np.ndarray:
    """Each candidate's two regressor rows (x, y) as rows of the 14 coefficients (C, 2, 14)."""
    rows = np.zeros((features.shape[0], 2, _N_PARAMETERS))
    rows[:, 0, :N_COEFFICIENTS] = features[:, 0]
    rows[:, 1, N_COEFFICIENTS:] = features[:, 1]
    return rows


def _log_det(features: np.ndarray, chosen: np.ndarray) -> float:
    """``log det`` of the information of both axes (block diagonal: the sum of the two)."""
    return sum(log_det(features[chosen, b].T @ features[chosen, b]) for b in range(2))


def _box(sensitivity: np.ndarray, chosen: np.ndarray, accuracy_dph: float, near=None):
    """The first-order requirement box of the ``chosen`` candidates (3,), radians."""
    return largest_box(sensitivity[chosen], accuracy_dph, start_rad=near)[0]


@dataclass(frozen=True)
class SearchStep:
    """One step of :func:`loosest_positions`: ``kind`` (``start``; ``exchange``: a position
    that bounds the box exchanged, the box grows; ``repeat``: the same, fewer positions bound
    the box; ``precision``: an exchange among the positions inside the box raises ``log det``),
    the box volume (rad^3, first order) and ``log det``."""

    kind: str
    volume_rad3: float
    log_det: float


def loosest_positions(
    features: np.ndarray,
    sensitivity: np.ndarray,
    start,
    floor_log_det: float,
    accuracy_dph: float,
    *,
    max_steps: int = MAX_STEPS,
) -> tuple[np.ndarray, tuple[SearchStep, ...]]:
    """The local search of the module docstring, from the design ``start``: the exchange of a
    bounding position that grows the box most, else leaves the fewest positions bounding it
    (:func:`_exchange_bounding`), while the floor holds; else a Fedorov exchange among the
    positions inside the box. (Volume, fewer bounding positions, ``log det``) rises at every
    step, so the search ends.

    Args:
        features: each candidate's regressor rows of the two axes (C, 2, 7).
        sensitivity: each candidate's ``|J|`` (C, 2, 3), deg/h per rad of (dpsi, dtheta,
            dgamma) (:func:`~turntable_pin.calibration.requirement.rate_error_jacobian`).
        start: indices of the starting design (``log det`` at least ``floor_log_det``).
        floor_log_det: the precision floor (``log det`` of both axes' information).
        accuracy_dph: ``w_m``, deg/h.

    Returns:
        The chosen indices and the steps taken (never a smaller box, never below the floor).
    """

    chosen = np.array(start, dtype=int)
    box = _box(sensitivity, chosen, accuracy_dph)
    current = _log_det(features, chosen)
    steps = [SearchStep("start", float(np.prod(box)), current)]
    rows = None
    for _ in range(max_steps):
        load = (sensitivity @ box).max(axis=1)  # first-order worst |dw| over the box, deg/h
        taken = np.zeros(load.size, dtype=bool)
        taken[chosen] = True
        inside = (load < accuracy_dph * (1 - 1e-9)) & ~taken
        moved = _exchange_bounding(
            features, sensitivity, chosen, box, current, floor_log_det, accuracy_dph, inside
        )
        if moved is not None:
            kind, chosen, box, current = moved
            steps.append(SearchStep(kind, float(np.prod(box)), current))
            continue
        pool = np.flatnonzero(inside | taken)
        if rows is None:
            rows = _stacked_rows(features)
        where = np.full(load.size, -1)
        where[pool] = np.arange(pool.size)
        found = fedorov_exchange(rows[pool], where[chosen])
        if not found.log_det > current + 1e-9:
            break
        chosen = pool[found.chosen]
        current = _log_det(features, chosen)
        box = _box(sensitivity, chosen, accuracy_dph, box)
        steps.append(SearchStep("precision", float(np.prod(box)), current))
    return chosen, tuple(steps)


def _bounding(sensitivity, chosen, box, accuracy_dph) -> np.ndarray:
    """The slots of the ``chosen`` positions whose first-order worst case over ``box`` is
    ``w_m`` (to :data:`_BINDS`): the positions that bound the box."""
    load = (sensitivity[chosen] @ box).max(axis=1)
    return np.flatnonzero(load >= accuracy_dph * (1 - _BINDS))


def _exchange_bounding(
    features, sensitivity, chosen, box, current, floor_log_det, accuracy_dph, inside
):
    """The step of :func:`loosest_positions` that exchanges a bounding position:
    ``(kind, chosen, box, log det)``, or None.

    Each bounding position's exchange is for the candidate inside the box that keeps the most
    precision (when it keeps the floor); of these, the one that grows the box most, else one
    that leaves fewer positions bounding it. A position whose sensitivity another bounding
    position repeats (the same gravity direction) cannot grow the box: its exchange leaves the
    box as it is, with one bounding position fewer (no box to compute). The change of
    ``log det`` of an exchange is Fedorov's, per axis: ``det(M - x_i x_i^T + x_j x_j^T) / det M
    = (1 + d_j)(1 - d_i) + d_ij^2`` with ``d_ij = x_i^T M^-1 x_j``, for every candidate j at once.
    """
    bounding = _bounding(sensitivity, chosen, box, accuracy_dph)
    if bounding.size == 0 or not np.any(inside):
        return None
    projected, leverage = [], []
    for b in range(2):
        x = features[chosen, b]
        z = features[:, b] @ np.linalg.inv(x.T @ x)
        projected.append(z)
        leverage.append(np.einsum("ij,ij->i", z, features[:, b]))
    rows = np.round(sensitivity[chosen[bounding]].reshape(bounding.size, -1), 12)
    _, group, size = np.unique(rows, axis=0, return_inverse=True, return_counts=True)
    volume = float(np.prod(box))
    best_key, best = None, None
    for n, slot in enumerate(bounding):
        gain = np.zeros(inside.size)
        for b in range(2):
            cross = projected[b] @ features[chosen[slot], b]
            ratio = (1 + leverage[b]) * (1 - cross[chosen[slot]]) + cross**2
            gain += np.log(np.maximum(ratio, 1e-300))
        gain[~inside] = -np.inf
        j = int(np.argmax(gain))
        if not current + gain[j] >= floor_log_det:
            continue
        trial = chosen.copy()
        trial[slot] = j
        if size[group.ravel()[n]] > 1:
            grown, key = box, (1.0, 1 - bounding.size)
        else:
            grown = _box(sensitivity, trial, accuracy_dph, box)
            fewer = _bounding(sensitivity, trial, grown, accuracy_dph).size
            key = (float(np.prod(grown)) / volume, -fewer)
            if not (key[0] > 1 + 1e-9 or (key[0] >= 1 - 1e-12 and fewer < bounding.size)):
                continue
        if best_key is None or key > best_key:
            best_key, best = key, (trial, grown)
    if best is None:
        return None
    kind = "exchange" if best_key[0] > 1 + 1e-9 else "repeat"
    return kind, best[0], best[1], _log_det(features, best[0])


# ---- the result ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class CalibrationDesign(NotebookResult):
    """GyroWheel calibration positions with the loosest orientation requirement.

    Attributes:
        space: the :class:`~.space.DesignSpace` (table, limits, candidates, seed).
        positions_deg: the chosen positions (N, J), degrees, in the run's order.
        plan: the run that measures them (each once, in the order of their angles).
        reference: the grid of the same N it is compared with (:func:`comparison_grid`).
        accuracy_dph: the required rate accuracy ``w_m``, deg/h.
        min_efficiency: the precision floor (D-efficiency against the reference).
        d_efficiency: the design's D-efficiency against the reference (14 coefficients).
        box, reference_box: the requirement boxes of the design and of the reference.
        uniform_factor: the largest k such that k times the reference's box holds at the
            design's positions: the table may be k times less accurate on every angle.
        planes, reference_planes: the paper's planes (eqs. 15-16) of both, for comparison.
        steps: the search's steps (:class:`SearchStep`).
        latitude_rad: the test site's latitude (eq. 13 as printed does not depend on it).
    """

    space: DesignSpace
    positions_deg: np.ndarray = field(repr=False)
    plan: MeasurementPlan = field(repr=False)
    reference: PositionSet = field(repr=False)
    accuracy_dph: float
    min_efficiency: float
    d_efficiency: float
    box: RequirementBox
    reference_box: RequirementBox
    uniform_factor: float
    planes: OrientationRequirement = field(repr=False)
    reference_planes: OrientationRequirement = field(repr=False)
    steps: tuple[SearchStep, ...] = field(repr=False)
    latitude_rad: float

    @property
    def n_positions(self) -> int:
        """Number of positions chosen N."""
        return int(self.positions_deg.shape[0])

    @property
    def looser_by(self) -> float:
        """How many times less accurate the table may be: the ratio of the boxes' geometric
        means ``(I_psi I_theta I_gamma)^(1/3)``, design over reference."""
        return float((self.box.volume_rad3 / self.reference_box.volume_rad3) ** (1 / 3))

    @property
    def looser_by_angle(self) -> dict[str, float]:
        """Each limit of the design's box over the reference's."""
        ratio = self.box.limits_rad / self.reference_box.limits_rad
        return {name: float(r) for name, r in zip(ANGLE_SYMBOLS, ratio, strict=True)}

    def positions(self) -> PositionSet:
        """The chosen positions as a :class:`PositionSet` of the table."""
        return PositionSet(
            self.positions_deg / DEG_PER_RAD,
            table=self.space.table,
            name=str(command("design", calibrate=True)),
        )

    def comment(self) -> str:
        """The comment lines of the positions' CSV: what made it, with its seed."""
        return "\n".join(
            [
                f"designed by {command('design', calibrate=True)} (loosest orientation "
                "requirement)",
                f"table: {self.space.table_name}; accuracy_dph={self.accuracy_dph:g}",
                f"{self.space.seed_text(self.n_positions)} min_efficiency={self.min_efficiency:g}",
                self.space.limits_text,
                f"reference: {self.reference.name}; looser by {self.looser_by:.4g}; "
                f"D-efficiency {self.d_efficiency:.4g}",
            ]
        )

    def to_dict(self) -> dict:
        """The design as a JSON-ready dict."""

        def planes(result: OrientationRequirement) -> dict:
            full = result.to_dict()
            keys = [f"I_{n}_deg" for n in ANGLE_SYMBOLS] + ["box_dwx_dph", "box_dwy_dph"]
            return {k: full[k] for k in keys}

        return {
            "mode": "calibrate",
            "space": self.space.to_dict(),
            "n_positions": self.n_positions,
            "accuracy_dph": self.accuracy_dph,
            "latitude_deg": self.latitude_rad * DEG_PER_RAD,
            "reference": self.reference.name,
            "min_efficiency": self.min_efficiency,
            "d_efficiency": self.d_efficiency,
            "looser_by": self.looser_by,
            "looser_by_angle": self.looser_by_angle,
            "uniform_factor": self.uniform_factor,
            "box": self.box.to_dict(),
            "reference_box": self.reference_box.to_dict(),
            "planes": planes(self.planes),
            "reference_planes": planes(self.reference_planes),
            "n_steps": len(self.steps) - 1,
            "positions_deg": self.positions_deg.tolist(),
            "plan": self.plan.to_dict(),
        }

    def report(self) -> str:
        """The design as text: the boxes and the planes of design and reference, the positions."""
        space, ref = self.space, self.reference.name
        lines = [
            f"design (calibrate, loosest orientation requirement): "
            f"{space.chosen_text(self.n_positions)}, for a rate accuracy of "
            f"{self.accuracy_dph:g} deg/h",
            space.limits_text,
            f"reference: {ref} ({len(self.reference)} positions); D-efficiency of the design "
            f"against it {self.d_efficiency:.3f} (floor {self.min_efficiency:g}: the 14 drift "
            "coefficients at least as precisely)",
            "the largest box that holds (every orientation error in it meets the accuracy), deg:",
            f"  {'':16s}{'I_psi':>10s}{'I_theta':>10s}{'I_gamma':>10s}",
        ]
        for name, box in (("design", self.box), (ref, self.reference_box)):
            values = "".join(f"{v * DEG_PER_RAD:10.5f}" for v in box.limits_rad)
            lines.append(f"  {name[:16]:16s}{values}")
        ratios = "".join(f"{v:10.3f}" for v in self.looser_by_angle.values())
        lines.append(f"  {'ratio':16s}{ratios}")
        lines.append(
            f"the same calibration accuracy with a table {self.looser_by:.2f} times less accurate "
            f"(ratio of the boxes' geometric means; {self.uniform_factor:.2f} times on every "
            f"angle: {self.uniform_factor:.2f} x the {ref} box holds at the design's positions)"
        )
        lines.append("the paper's planes (eqs. 15-16; the three at once exceed w_m), deg:")
        for name, result in (("design", self.planes), (ref, self.reference_planes)):
            values = "".join(f"{v * DEG_PER_RAD:10.5f}" for v in result.limits_rad)
            lines.append(
                f"  {name[:16]:16s}{values}   (corners: dwx {result.box_dwx_dph:.4g}, "
                f"dwy {result.box_dwy_dph:.4g} deg/h)"
            )
        lines += space.positions_lines(self.positions_deg)
        return "\n".join(lines)


def design_calibration(
    space: DesignSpace,
    n_positions: int,
    *,
    accuracy_dph: float = 0.01,
    min_efficiency: float = DEFAULT_MIN_EFFICIENCY,
    gyrowheel: GyroWheelModel | None = None,
    latitude_rad: float = np.radians(DEFAULT_LATITUDE_DEG),
) -> CalibrationDesign:
    """The ``n_positions`` calibration positions of the module docstring.

    Args:
        space: the table, its limits and the candidates (:func:`~.space.design_space`).
        n_positions: N (at least 7: seven coefficients per axis).
        accuracy_dph: the required rate accuracy ``w_m``, deg/h.
        min_efficiency: the precision floor, D-efficiency against the reference grid.
        gyrowheel: the drift coefficients (default: paper Table 1).
        latitude_rad: the test site's latitude, radians (the planes' report; eq. 13 as printed
            does not depend on it).

    Raises:
        IdentifiabilityError: no position within the limits turns gravity so as to calibrate
            (e.g. a table that keeps gravity in a plane of the payload).
        InputError: N above the candidates of ``space`` (checked first), N below 7 or no grid
            of N to compare with; a precision floor no design reaches.
    """
    n_positions, accuracy_dph = _checked_request(space, n_positions, accuracy_dph, min_efficiency)
    gyrowheel = gyrowheel if gyrowheel is not None else GyroWheelModel.nominal()
    table = space.table
    reference, candidates, reference_index = _candidates(space, n_positions, latitude_rad)
    inputs = position_inputs(candidates, latitude_rad)
    features = np.stack([regressor_matrix(a, inputs.specific_force_g) for a in AXES], axis=1)
    sensitivity = np.abs(rate_error_jacobian(gyrowheel, inputs))
    reference_log_det = _log_det(features, reference_index)
    floor = reference_log_det + _N_PARAMETERS * np.log(min_efficiency)
    start = reference_index
    if min_efficiency > 1:
        start = _most_precise(features, n_positions, reference_index, floor, min_efficiency)
    with one_blas_thread():  # small matrices: threads only wait for each other on busy cores
        chosen, steps = loosest_positions(features, sensitivity, start, floor, accuracy_dph)

    found = PositionSet(candidates.angles_rad[chosen], table=table, name="design")
    box = requirement_box(accuracy_dph, gyrowheel, position_inputs(found, latitude_rad))
    reference_box = requirement_box(
        accuracy_dph, gyrowheel, position_inputs(reference, latitude_rad)
    )
    if min_efficiency <= 1 and box.volume_rad3 < reference_box.volume_rad3:
        chosen, box = reference_index, reference_box  # the full model's last digits: the grid
    plan = plan_measurements(np.round(candidates.angles_rad[chosen] * DEG_PER_RAD, 9), table=table)
    design_set = PositionSet(plan.rows.angles_rad, table=table, name="design")
    uniform, _ = holding_scale(
        accuracy_dph, gyrowheel, position_inputs(design_set, latitude_rad),
        reference_box.limits_rad,
    )  # fmt: skip
    return CalibrationDesign(
        space=space,
        positions_deg=plan.rows.angles_deg(),
        plan=plan,
        reference=reference,
        accuracy_dph=accuracy_dph,
        min_efficiency=float(min_efficiency),
        d_efficiency=float(
            np.exp((_log_det(features, chosen) - reference_log_det) / _N_PARAMETERS)
        ),
        box=box,
        reference_box=reference_box,
        uniform_factor=uniform,
        planes=orientation_requirement(accuracy_dph, design_set, latitude_rad, gyrowheel=gyrowheel),
        reference_planes=orientation_requirement(
            accuracy_dph, reference, latitude_rad, gyrowheel=gyrowheel
        ),
        steps=steps,
        latitude_rad=float(latitude_rad),
    )


def _checked_request(space, n_positions, accuracy_dph, min_efficiency) -> tuple[int, float]:
    """N (checked against the candidates, at least 7) and ``w_m``, or :class:`InputError`; a
    precision floor outside (0, :data:`MAX_MIN_EFFICIENCY`] is refused too."""
    n_positions = check_positions_count(n_positions, space.candidates_deg.shape[0])
    accuracy_dph = check_accuracy_dph(accuracy_dph)
    if int(n_positions) < N_COEFFICIENTS:
        raise InputError(
            f"{argument('n_positions')} {n_positions}: a calibration needs at least "
            f"{N_COEFFICIENTS} positions (seven drift coefficients per axis)"
        )
    if not (np.isfinite(min_efficiency) and 0 < min_efficiency <= MAX_MIN_EFFICIENCY):
        raise InputError(
            f"the precision floor (D-efficiency) must be in (0, {MAX_MIN_EFFICIENCY:g}], "
            f"got {min_efficiency!r}"
        )
    return int(n_positions), accuracy_dph


def _candidates(space, n_positions: int, latitude_rad: float):
    """The reference grid, the candidates (those drawn within the limits that the grid does not
    hold, then the grid's) and the grid's indices among them.

    Raises:
        IdentifiabilityError: no position within the limits calibrates.
    """
    table = space.table
    drawn = PositionSet(space.candidates_deg / DEG_PER_RAD, table=table, name="within the limits")
    require_identifiable(position_inputs(drawn, latitude_rad))
    reference = comparison_grid(space, n_positions, latitude_rad)
    others = _without(drawn.angles_rad, reference.angles_rad)
    candidates = PositionSet(
        np.concatenate([others, reference.angles_rad]), table=table, name="candidates"
    )
    return reference, candidates, np.arange(len(others), len(candidates))


def _without(angles_rad: np.ndarray, known_rad: np.ndarray) -> np.ndarray:
    """The rows of ``angles_rad`` that command no position of ``known_rad`` (to 1e-9 deg,
    modulo a turn): a candidate the reference grid already holds is not drawn twice."""

    def key(angles):
        return np.round(np.mod(angles * DEG_PER_RAD, 360.0), 9) % 360.0

    known = {tuple(row) for row in key(known_rad)}
    keep = [tuple(row) not in known for row in key(angles_rad)]
    return angles_rad[np.array(keep, dtype=bool)]


def _most_precise(features, n_positions, reference_index, floor, min_efficiency) -> np.ndarray:
    """The D-optimal positions (greedy and Fedorov exchange, also from the reference), the
    start of a search whose precision floor is above the reference's.

    Raises:
        InputError: they do not reach the floor either.
    """
    found = d_optimal_design(_stacked_rows(features), n_positions, also_from=[reference_index])
    if not found.log_det >= floor:
        best = np.exp((found.log_det - floor) / _N_PARAMETERS) * min_efficiency
        raise InputError(
            f"no {n_positions} positions within the limits reach a D-efficiency of "
            f"{min_efficiency:g} against the reference grid (the most precise found: "
            f"{best:.3g}); lower the precision floor"
        )
    return np.asarray(found.chosen, dtype=int)
