"""The orientation-data model family for :func:`diagnose`: base + catalogued effects, probes.

Probes of the structure search (what "shape" the missing part has):

- ``<error> k/rev in <phi>``: the per-position derivative of the prediction with respect to one
  of the eight turntable errors times ``cos(k phi)``, ``sin(k phi)`` -- a harmonic of order k of
  that error in either axis angle (k = 1 .. 5, fewer when the data have fewer distinct angles);
- ``<angle> k/rev in <phi>``: a harmonic added directly to ``dpsi``, ``dtheta`` or ``dgamma``;
- ``<angle> k/rev in phi1+phi2`` / ``phi1-phi2`` (k = 1, 2): shapes that couple the two angles;
- ``<angle> drift in time`` (with ``time_s``): a quadratic in time;
- ``<angle> with dir1`` / ``dir2``: a step with the approach direction.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from ..core.resources import default_urdf_path, models_dir
from ..core.turn_grid import every_combination, full_turn_grid_deg
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..core.words import Command, argument, command
from ..model.mount_declaration import NO_MOUNT
from ..stats.diagnosis_engine import (
    DATA_PLACEHOLDER,
    DataFamily,
    PageWords,
    SeparationWords,
    diagnose_data,
)
from ..stats.least_squares import RANK_RTOL, fit_least_squares
from ..stats.model_selection import Diagnosis
from ..stats.outliers import outlier_rule_words
from ..stats.structure_search import Probe
from .catalogue import catalogue as table_catalogue
from .catalogue import resolve_effect
from .data import ANGLE_NAMES, OrientationMeasurements
from .effect_model import OrientationModel
from .effects.base import MOUNT, TURNTABLE, Effect, PositionVariables
from .fit import (
    RELINEARISE_RAD,
    OrientationFit,
    OrientationFitProblem,
    fit_orientation,
    orientation_zero_point,
)
from .residuals import ResidualSet, orientation_residuals
from .table import measured_table

__all__ = [
    "DATA_PLACEHOLDER",
    "MAX_HARMONIC",
    "OUTLIER_RULE",
    "OrientationFamily",
    "design_command",
    "diagnose_measurements",
    "dense_joint_grid",
    "harmonic_basis",
    "joint_harmonics",
    "max_harmonic_order",
    "mount_option",
    "polynomial_basis",
    "urdf_option",
]

MAX_HARMONIC = 5


def harmonic_basis(k: int):
    """The basis functions ``cos(k x), sin(k x)`` of a k/rev probe, (p,) -> (p, 2)."""
    return lambda x: np.stack([np.cos(k * x), np.sin(k * x)], axis=-1)


def polynomial_basis(values: np.ndarray):
    """The basis ``u, u^2`` with ``u`` the column scaled to [0, 1] over the data, (p,) -> (p, 2)."""
    low, span = float(np.min(values)), float(np.ptp(values))

    def functions(x):
        u = (np.asarray(x, dtype=float) - low) / span
        return np.stack([u, u**2], axis=-1)

    return functions


def _step(x) -> np.ndarray:
    """The basis of a step with the approach direction (+1/-1), (p,) -> (p, 1)."""
    return np.asarray(x, dtype=float)[:, None]


def _one_angle(w: np.ndarray, a: int):
    """The direction of a term added to measured angle ``a`` alone, weighted, (N, 3)."""

    def direction():
        d = np.zeros_like(w)
        d[:, a] = w[:, a]
        return d

    return direction


def _along_error(jac: np.ndarray, w: np.ndarray, e: int):
    """The direction a change of base error ``e`` enters the angles, weighted, (N, 3)."""

    def direction():
        return jac[:, :, e] * w

    return direction


def dense_joint_grid(table) -> np.ndarray:
    """A dense grid over every joint of ``table`` (a ``MeasuredTable``), (N, J) rad: every 15
    degrees (30 for three joints) over a joint that turns all the way round; within a joint's
    limits, the same number of angles at the centres of equal cells (the ends, where a term such
    as cot(elevation) may be infinite, are not positions)."""
    step = 30.0 if table.n_joints > 2 else 15.0
    g = np.radians(full_turn_grid_deg(step)[:, 0])
    count = g.size
    axes = [
        g if limits is None else limits[0] + (np.arange(count) + 0.5) * np.ptp(limits) / count
        for limits in table.joint_limits_rad
    ]
    return every_combination(axes)


def max_harmonic_order(angle_rad: np.ndarray) -> int:
    """The highest harmonic order a structure search tries in an angle: at most
    :data:`MAX_HARMONIC`, and (distinct angles - 1) // 2 (a k/rev term needs 2k + 1 angles)."""
    distinct = np.unique(np.round(np.mod(angle_rad, 2 * np.pi), 9)).size
    return int(min(MAX_HARMONIC, max(0, (distinct - 1) // 2)))


def joint_harmonics(labels: Sequence[str], joint_rad: np.ndarray):
    """The harmonic shapes a structure search tries in the joint angles, in order: each k/rev
    term in each joint angle (k up to :func:`max_harmonic_order`), then each k/rev term
    (k = 1, 2) in the sum and in the difference of two joint angles (``phiA+phiB``,
    ``phiA-phiB``: shapes that couple them, which terms in one angle each miss). Yields
    ``(variable, values rad (N,), k, coupled)``."""
    for var, phi in zip(labels, joint_rad.T, strict=True):
        for k in range(1, max_harmonic_order(phi) + 1):
            yield var, phi, k, False
    for i in range(len(labels)):
        for j in range(i + 1, len(labels)):
            a, b = joint_rad[:, i], joint_rad[:, j]
            for sign, combined in (("+", a + b), ("-", a - b)):
                for k in range(1, min(2, max_harmonic_order(combined)) + 1):
                    yield f"{labels[i]}{sign}{labels[j]}", combined, k, True


OUTLIER_RULE = outlier_rule_words(
    "measured angles", "the same angle, dpsi, dtheta or dgamma,", "all", "angles"
)
"""The outlier rule of :func:`diagnose_measurements` in words (``turntable_pin.stats.outliers``)."""


class OrientationFamily(DataFamily):
    """Orientation data, the table's base error model and its effect catalogue (a
    :class:`~turntable_pin.stats.diagnosis_engine.DataFamily`).

    Args:
        data: the measurements.
        catalogue: the candidate effects (default: the table's catalogue).
        turntable: the table (see :func:`~turntable_pin.measurement.table.measured_table`).
        left_out_rad: the measured values (N, 3) of the angles left out of ``data`` as
            outliers, NaN elsewhere (shown in the plots, never fitted), or ``None``.
        noise_per_angle: sigma unknown and the angles' noise differ: every model is fitted
            with a noise level per measured angle estimated with that model (iteratively
            reweighted to the maximum of its likelihood), and scored with each level profiled
            (``FitResult.profiled_rss``), so that each comparison is made at each model's own
            noise. ``data``'s relative sigmas are only the first weights.
    """

    columns = ANGLE_NAMES
    column_key = "angle"
    record_label = "positions"
    record_words = "measurement rows"
    observations = "measured angles"
    observation_unit = "arcsec"
    unit_words = "arcsec"
    user_unit_scale = ARCSEC_PER_RAD
    outlier_rule = OUTLIER_RULE
    noise_subject = "the measured angles'"
    noise_column = "angle"
    noise_how = (
        "each angle is weighted by its own estimated noise (state it with sigma_dpsi_arcsec, "
        "sigma_dtheta_arcsec, sigma_dgamma_arcsec)"
    )
    page = PageWords(
        title="Turntable measurement diagnosis",
        page_title="turntable-pin report",
        sections=(
            ("measurement_intro", ""),
            ("warnings", ""),
            ("outliers", ""),
            ("data", "1. The data"),
            ("base", "2. The base model"),
            ("fails", "3. Where the base model fails"),
            ("diagnosis", "4. Diagnosis: which physical effect is missing?"),
            ("added", "5. Add it and watch the error fall"),
            ("parameters", "6. Parameters of the final model"),
            ("decision_rule", ""),
        ),
        fit_columns=("rms", "chi2_reduced", "rank", "n_params", "p_value"),
        candidate_columns=(
            "delta_bic",
            "after_first",
            "rms",
            "chi2_reduced",
            "added_rank",
            "alternatives",
        ),
        parts=frozenset({"anchor", "base_errors", "untestable", "story", "maps"}),
        structure_shapes="harmonic shapes of each turntable error and of each measured angle, "
        "drifts, steps with the approach direction",
    )

    def __init__(
        self,
        data: OrientationMeasurements,
        catalogue: Sequence[Effect] | None = None,
        turntable=None,
        left_out_rad: np.ndarray | None = None,
        noise_per_angle: bool = False,
    ) -> None:
        self.data = data
        self.left_out_rad = left_out_rad
        self.table = measured_table(turntable)
        # The plausible scales of the catalogue are those of this kind of machine.
        self.machine_kind = MOUNT if self.table.telescope_mount else TURNTABLE
        scale = ARCSEC_PER_RAD
        if data.sigma_rad is not None:
            scale *= float(np.nanmedian(np.where(data.measured, data.sigma_rad, np.nan)))
        super().__init__(
            catalogue if catalogue is not None else table_catalogue(self.table),
            data.measured,
            sigma_scale=scale,
            noise_per_column=noise_per_angle,
        )

    # ---- the hooks of the one diagnosis (stats.diagnosis_engine) ---------------------------
    def fit_model(self, effects: Sequence[Effect], zero_point) -> OrientationFit:
        """The fit of the base errors plus ``effects`` (:func:`~.fit.fit_orientation`)."""
        return fit_orientation(
            self.data,
            effects,
            turntable=self.table,
            zero_point=zero_point,
            base_fit=self.fit([]) if effects else None,
        )

    def zero_point_of(self, effects: Sequence[Effect]):
        """:func:`~.fit.orientation_zero_point` of the base and ``effects`` on these data."""
        return orientation_zero_point(self.data, effects, turntable=self.table)

    def initial_column_sigma(self) -> np.ndarray | None:
        """The per-angle levels the data are weighted with (the first pass' estimate)."""
        data = self.data
        return None if data.sigma_rad is None else np.nanmedian(data.sigma_rad, axis=0)

    def refit(self, fit: OrientationFit, column_sigma: np.ndarray) -> OrientationFit:
        """``fit``'s model fitted again with the relative noise ``column_sigma`` (3,) rad per
        angle: from zero errors, or from ``fit``'s solution when its base errors are large
        offsets (:data:`~.fit.RELINEARISE_RAD`, as :func:`~.fit.fit_orientation` restarts)."""
        n_base = len(fit.model.base_names)
        large = np.max(np.abs(fit.result.params[:n_base]), initial=0.0) > RELINEARISE_RAD
        problem = OrientationFitProblem(_weighted(self.data, column_sigma), fit.model)
        result = fit_least_squares(problem, origin=fit.result.params if large else None)
        return OrientationFit(problem.data, fit.model, result)

    def residual_table(self, fit: OrientationFit) -> np.ndarray:
        """(N, 3) the residuals of ``fit``, rad, NaN where not measured."""
        return fit.residuals_rad

    def full_residuals(self, fit: OrientationFit) -> np.ndarray:
        """(N, 3) the measured minus ``fit``'s angles, rad, the cells left out too."""
        return self.data.angles_rad - fit.fitted_rad()

    def residual_set(self, fit: OrientationFit) -> ResidualSet:
        """The residuals of ``fit`` for the figures, the angles left out as outliers apart."""
        return orientation_residuals(fit, left_out_rad=self.left_out_rad)

    @property
    def source(self) -> str | None:
        """The file the measurements were read from."""
        return self.data.source

    def sigma_table(self) -> np.ndarray | None:
        """(N, 3) the data's sigmas, rad (stated or relative), or None."""
        return self.data.sigma_rad

    @property
    def sigma_given(self) -> bool:
        """Whether the data state their sigmas."""
        return self.data.sigma_rad is not None

    @property
    def rows(self) -> np.ndarray:
        """The data file's row number of each position."""
        return self.data.rows

    def without(self, cells: np.ndarray) -> OrientationFamily:
        """The family on these data with the angles ``cells`` (N, 3) left out as outliers."""
        return OrientationFamily(
            _without(self.data, cells), self.catalogue, self.table,
            np.where(cells, self.data.angles_rad, np.nan), self.noise_per_column,
        )  # fmt: skip

    def with_column_noise(self, column_sigma: np.ndarray) -> OrientationFamily:
        """The family on these data weighted by ``column_sigma`` (3,) rad per angle, every
        model fitted at its own per-angle noise."""
        return OrientationFamily(_weighted(self.data, column_sigma), self.catalogue, self.table,
                                 noise_per_angle=True)  # fmt: skip

    def screen_fit(self, cells: np.ndarray, effects: Sequence[Effect]):
        """The fit of base + ``effects`` without the angles ``cells`` (the outlier screen)."""
        return fit_orientation(_without(self.data, cells), effects, turntable=self.table).result

    @property
    def doubt_words(self) -> str:
        """The doubt about the table: were the data measured on another one?"""
        where = self.table.urdf_path
        urdf = f"the URDF {Path(where).name}" if where is not None else "the default URDF"
        return (
            f"no rigid error set of {urdf} and no catalogued effect makes these data; were they "
            f"measured on another table ({argument('turntable')})? Or is the stated sigma too "
            "small?"
        )

    def complete(self, diagnosis: Diagnosis) -> None:
        """The ``design`` command (``separate``) that settles each separation of the verdict."""
        if not diagnosis.separations:
            return
        data = self.data
        data_name = data.source if data.source and Path(data.source).is_file() else DATA_PLACEHOLDER
        urdf, mount = urdf_option(self.table), mount_option(self.table)
        diagnosis.separation_commands = {
            name: design_command(data_name, (diagnosis.missing_effect, name), urdf, mount)
            for name in diagnosis.separations
        }

    @property
    def data_columns(self) -> PositionVariables:
        """The measurements' columns (their :class:`~.effects.base.PositionVariables`)."""
        return self.data.variables()

    def effect(self, name: str) -> Effect:
        """The effect called ``name``: in this family's catalogue first, then the table's."""
        return resolve_effect(name, self.table, self.catalogue)

    def design_warnings(self, base_fit: OrientationFit) -> list[str]:
        """Warn when the positions determine fewer error combinations than a full grid does.

        The base model's rank on the data is compared with its rank on a dense grid over every
        axis; fewer means some turntable errors (and any effect that varies with a joint angle)
        cannot be told apart here, so a step with ``dir`` or a drift with ``time_s`` may stand
        for whatever changed between the rows.
        """
        data = self.data
        warnings = []
        lost = base_fit.unobserved_combinations()
        if lost:
            # empty in the file, not the cells the outlier rule left out of these data
            left = np.zeros_like(data.measured)
            if self.left_out_rad is not None:
                left = ~np.isnan(self.left_out_rad)
            empty = ~data.measured & ~left
            counts = ", ".join(
                f"{name} at {int(np.sum(empty[:, i]))}"
                for i, name in enumerate(ANGLE_NAMES)
                if empty[:, i].any()
            )
            outliers = int(left.sum())
            besides = f"; {outliers} more left out as outliers" if outliers else ""
            warnings.append(
                f"angles not measured ({counts} of {data.n_positions} positions{besides}): "
                f"{'; '.join(lost)} {'is' if len(lost) == 1 else 'are'} not observed, so no "
                "effect that acts only there can be tested; measure those angles to see it"
            )
        rank = base_fit.result.rank
        dense = OrientationModel(self._dense_variables(), (), self.table)
        jac = dense.jacobian(np.zeros(dense.n_params)).reshape(-1, dense.n_params)
        singular = np.linalg.svd(jac / np.linalg.norm(jac, axis=0).clip(1e-300), compute_uv=False)
        full_rank = int(np.sum(singular > RANK_RTOL * singular[0]))
        full_rank -= len(lost)  # what the empty cells hide is said above
        wrapped = np.round(np.mod(np.degrees(data.joint_rad), 360.0), 6) % 360.0
        distinct = np.unique(wrapped, axis=0)
        labels = [self.table.angle_label(k) for k in range(1, data.n_joints + 1)]
        sampling = self._sampling_warnings(wrapped, labels) if len(distinct) > 1 else []
        if rank >= full_rank:
            return warnings + sampling
        held = [lab for k, lab in enumerate(labels) if np.unique(wrapped[:, k]).size == 1]
        axes = " or ".join(held if len(distinct) > 1 and held else labels)
        where = (
            f"all {data.n_positions} rows are at one position ("
            + ", ".join(f"{lab} {v:g}" for lab, v in zip(labels, distinct[0], strict=True))
            + " deg)"
            if len(distinct) == 1
            else f"the {data.n_positions} rows are at {len(distinct)} distinct positions"
        )
        rank_warning = (
            f"{where}: they determine {rank} of the {full_rank} combinations of the turntable "
            f"errors that a grid over every axis determines, so effects that vary with {axes} "
            "cannot be tested, and an effect named here (a step with dir, a drift in time) may "
            "stand for any error that changed between the rows; measure more positions over the "
            "full turn of every axis"
        )
        return warnings + [rank_warning] + sampling

    def _sampling_warnings(self, wrapped_deg: np.ndarray, labels: list[str]) -> list[str]:
        """What positions at more than one place still cannot tell: an axis held at one angle,
        too few angles of an axis for the 2/rev terms, single-axis sweeps (no coupled terms), an
        approach direction that never changes (no backlash)."""
        counts = [np.unique(wrapped_deg[:, k]).size for k in range(self.data.n_joints)]
        out = []
        held = [k for k, c in enumerate(counts) if c == 1]
        if held:
            where = ", ".join(f"{labels[k]} at {wrapped_deg[0, k]:g} deg" for k in held)
            names = " or ".join(labels[k] for k in held)
            out.append(
                f"the rows hold {where}: effects that vary with {names} cannot be tested here "
                f"(the diagnosis lists them as indistinguishable from the base); move {names} "
                f"over its turn too (simulate {argument('sweep')} {','.join(labels)}, or a grid)"
            )
        for k, count in enumerate(counts):
            if 1 < count < 5:
                top = (count - 1) // 2
                out.append(
                    f"{labels[k]} takes only {count} distinct angles: a k/rev term in {labels[k]} "
                    f"needs at least 2k+1 angles over the turn, so terms of order {top + 1} and "
                    "above (the 2/rev terms of encoders and wobble) alias with lower orders or "
                    f"vanish at every row and cannot be tested; measure {labels[k]} at 5 or more "
                    "angles spread over the turn (a step of at most 72 deg)"
                )
        moving = [k for k, c in enumerate(counts) if c > 1]
        if len(moving) > 1:
            out += self._sweep_warning(wrapped_deg, labels, moving)
        return out + self._fixed_direction_warning(labels)

    def _sweep_warning(self, wrapped_deg: np.ndarray, labels: list[str], moving) -> list[str]:
        """The rows are single-axis sweeps of the axes ``moving``: no coupled terms."""
        n_joints = self.data.n_joints
        base = [np.unique(wrapped_deg[:, k], return_counts=True) for k in range(n_joints)]
        centre = np.array([v[np.argmax(c)] for v, c in base])
        if not np.all(np.sum(wrapped_deg != centre, axis=1) <= 1):
            return []
        lines = ", ".join(
            f"{labels[k]} swept at "
            + ", ".join(f"{labels[j]} {centre[j]:g}" for j in range(n_joints) if j != k)
            + " deg"
            for k in moving
        )
        return [
            f"the rows are single-axis sweeps ({lines}): an effect is seen only along these "
            "lines, so one that varies with several axes together (a term in phi1+phi2 or "
            "phi1-phi2, a product such as the gravity sag) cannot be told from terms in one axis "
            "each; measure positions where the axes move together (a grid or random positions) "
            "to see it"
        ]

    def _fixed_direction_warning(self, labels: list[str]) -> list[str]:
        """An approach direction the same at every row: no step with it (backlash)."""
        fixed = [
            (k, float(d[0])) for k, d in enumerate(self.data.dirs, start=1)
            if d is not None and np.unique(d).size == 1
        ]  # fmt: skip
        if not fixed:
            return []
        dirs = ", ".join(f"dir{k}" for k, _ in fixed)
        sides = ", ".join(f"{labels[k - 1]} from {'below' if v > 0 else 'above'}" for k, v in fixed)
        return [
            f"{dirs} {'is' if len(fixed) == 1 else 'are'} the same at every row ({sides}): a "
            "step with the approach direction (backlash) cannot be told from a constant offset "
            "of the axis, so it is indistinguishable from the base here; approach the positions "
            f"from both sides (simulate {argument('approach')} random, or {argument('passes')}) "
            "to see it"
        ]

    def _measured_angle_probes(
        self, shape: str, text: str, plot: tuple, directions, spec: str
    ) -> list[Probe]:
        """One probe per measured angle: the shape ``plot`` (variable, values, functions, value
        scale, unit) added to that angle itself (``directions[a]``, shared by the probes of every
        shape); ``text`` describes it (``{angle}``: the angle), ``spec`` is the shape part of its
        ``effect_spec`` (``h3(phi1)``)."""
        sites = [
            (angle, directions[a], text.format(angle=angle))
            for a, angle in enumerate(ANGLE_NAMES)
            if self.data.measured[:, a].any()
        ]
        return self.shape_probes(plot, shape, spec, sites)

    def _error_probes(
        self,
        directions,
        shape: str,
        text: str,
        plot: tuple,
        spec: str,
        unseen=frozenset(),
        alike=None,
    ) -> list[Probe]:
        """One probe per base error: its derivative (the direction it enters the angles,
        ``directions[e]``, shared by the probes of every shape) times the shape ``plot``
        (variable, values, functions, value scale, unit); none for the errors
        ``unseen`` (those the measured angles do not see to first order: their derivative at the
        fitted errors is a second-order remainder, and a shape along it is no finding).

        ``alike`` (:meth:`_alike_errors`): errors that enter the measured angles alike give the
        same probe, so a shape found along them is named after the most physical of them and
        says which others it cannot be told from."""
        names = self.table.base_names
        sites = []
        for e, name in enumerate(names):
            if name in unseen:
                continue
            group = (alike or {}).get(e, [e])
            lead = names[group[0]]
            description = f"a {text} of {lead} ({self.table.descriptions.get(lead, lead)})"
            if len(group) > 1:
                others = " or ".join(names[k] for k in group[1:])
                description += (
                    f", or of {others}: they enter the measured angles alike on these data, "
                    "which see only their combination"
                )
            sites.append((lead, directions[e], description))
        return self.shape_probes(plot, shape, spec, sites)

    def _alike_errors(self, jac: np.ndarray, w: np.ndarray, unseen) -> dict[int, list[int]]:
        """``{error index: the errors entering the measured angles alike, most physical first}``
        for the base errors whose weighted derivatives ``jac[:, :, e] * w`` are parallel (the
        data see only a combination of them): position errors (a k/rev term of an encoder)
        before tilts (a wobble), before the rest (an orthogonality or a mount error, which has
        no reason to vary with an angle)."""
        names = self.table.base_names
        positions = {j.position for j in self.table.joints}
        tilts = {t for j in self.table.joints for t in j.tilts}
        live = [e for e, n in enumerate(names) if n not in unseen]
        if len(live) < 2:
            return {}
        vectors = np.stack([(jac[:, :, e] * w).reshape(-1) for e in live])
        norms = np.linalg.norm(vectors, axis=1)
        unit = vectors / np.where(norms > 0, norms, 1.0)[:, None]
        parallel = np.abs(unit @ unit.T) > 1.0 - 1e-9
        rank = {e: (0 if names[e] in positions else 1 if names[e] in tilts else 2) for e in live}
        out = {}
        for i, e in enumerate(live):
            group = [live[k] for k in np.flatnonzero(parallel[i]) if norms[k] > 0]
            if len(group) > 1:
                out[e] = sorted(group, key=lambda k: (rank[k], k))
        return out

    def probes(self, fit: OrientationFit) -> list[Probe]:
        """The structure-search probes, weighted like the residuals of ``fit`` (see the module)."""
        data = self.data
        w = np.nan_to_num(fit.per_angle(fit.result.weights))  # (N, 3), 0 where not measured
        jac = fit.model.jacobian(fit.result.params)  # (N, 3, n)
        unseen = set(fit.result.identifiability.unresponsive)
        along = [_along_error(jac, w, e) for e in range(len(self.table.base_names))]
        alike = self._alike_errors(jac, w, unseen)
        on_angle = [_one_angle(w, a) for a in range(len(ANGLE_NAMES))]  # a term on one angle
        probes = []
        labels = [self.table.angle_label(k) for k in range(1, data.n_joints + 1)]
        # Each harmonic on each base error and on each angle itself; those coupling two angles
        # (k/rev in phiA + phiB or phiA - phiB) on each angle only.
        for var, values, k, coupled in joint_harmonics(labels, data.joint_rad):
            plot = (var, values, harmonic_basis(k), DEG_PER_RAD, "deg")
            shape = f"{k}/rev in {var}"
            spec = f"h{k}({var})"
            if not coupled:
                probes += self._error_probes(
                    along, shape, f"{k}/rev term in {var}", plot, spec, unseen, alike
                )
            probes += self._measured_angle_probes(
                shape, f"a {k}/rev term in {var} of {{angle}} itself", plot, on_angle, spec
            )
        if data.time_s is not None and np.ptp(data.time_s) > 0:
            plot = ("time_s", data.time_s, polynomial_basis(data.time_s), 1.0, "s")
            probes += self._measured_angle_probes(
                "drift in time",
                "a drift with time (quadratic over the run) in {angle}",
                plot,
                on_angle,
                "poly2(time_s)",
            )
        for k, value in enumerate(data.dirs, start=1):
            if value is not None:
                plot = (f"dir{k}", value, _step, 1.0, "")
                probes += self._measured_angle_probes(
                    f"with dir{k}",
                    f"a step with the approach direction dir{k} in {{angle}}",
                    plot,
                    on_angle,
                    f"sign(dir{k})",
                )
        # Other numeric columns (temperature, load, ...) as suspects: each base error and each
        # measured angle linear and quadratic in the column.
        for column, values in data.extra.items():
            if not np.ptp(values) > 0:
                continue
            plot = (column, values, polynomial_basis(values), 1.0, "")
            text = f"term linear and quadratic in {column}"
            spec = f"poly2({column})"
            probes += self._error_probes(along, f"in {column}", text, plot, spec, unseen, alike)
            probes += self._measured_angle_probes(
                f"in {column}", f"a {text} of {{angle}}", plot, on_angle, spec
            )
        return probes

    def base_inputs(self) -> set[str]:
        """The joint angles' labels (``phi1``, or ``azimuth`` on a mount): the probes in them
        are not suspects."""
        return {self.table.angle_label(k) for k in range(1, self.data.n_joints + 1)}

    def _dense_variables(self) -> PositionVariables:
        """A dense design over every axis (15-degree grid; 30 degrees for three axes; as many
        angles within the limits of a joint that does not turn all the way round), with a
        random time order and random approach directions where the data have them."""
        joints = dense_joint_grid(self.table)
        n = joints.shape[0]
        rng = np.random.default_rng(0)
        data = self.data
        time = None
        if data.time_s is not None:
            time = rng.permutation(np.linspace(data.time_s.min(), data.time_s.max(), n))
        dirs = tuple(rng.choice([-1.0, 1.0], n) if d is not None else None for d in data.dirs)
        extra = {k: rng.permutation(np.linspace(v.min(), v.max(), n))
                 for k, v in data.extra.items()}  # fmt: skip
        return PositionVariables(joints, time, dirs, extra)

    def dense_misfit(self, fit_a: OrientationFit, effect_b: Effect) -> float:
        """The noise-free chi2 of the model with ``effect_b`` in place of ``fit_a``'s last effect
        fitted to ``fit_a``'s prediction on the dense design (:meth:`_dense_variables`), at
        ``fit_a``'s noise."""
        a_effects = fit_a.model.effects
        variables = self._dense_variables()
        truth = OrientationModel(variables, a_effects, self.table).predict(fit_a.result.params)
        sigma = float(np.median(fit_a.sigma_rad))
        dense = OrientationMeasurements(
            variables.joint_rad, truth, np.full(variables.n, sigma), variables.time_s,
            variables.dirs, dict(variables.extra), source="dense design",
        )  # fmt: skip
        base_effects = [e for e in a_effects if e is not a_effects[-1]]
        return fit_orientation(dense, [*base_effects, effect_b], turntable=self.table).result.rss

    def separation_words(self) -> SeparationWords:
        """The dense design in words (its step, its limits, its size), and the checks."""
        grid = ("30-degree" if self.data.n_joints > 2 else "15-degree") + " grid"
        if any(limits is not None for limits in self.table.joint_limits_rad):
            grid += " within the joints' limits"
        n = dense_joint_grid(self.table).shape[0]
        return SeparationWords(
            grid=grid,
            grid_cannot=f"dense {grid}",
            grid_mimics=f"{grid} ({n} positions, random time order)",
            position="turntable position",
            check="measurement",
            more_data="measuring more angles",
        )


def _without(data: OrientationMeasurements, cells: np.ndarray) -> OrientationMeasurements:
    """``data`` with the cells ``cells`` (N, 3) left out (as not measured)."""
    if not cells.any():
        return data
    angles = data.angles_rad.copy()
    angles[cells] = np.nan
    return data.replace(angles_rad=angles)


def _weighted(data: OrientationMeasurements, column_sigma: np.ndarray) -> OrientationMeasurements:
    """``data`` weighted by the relative noise ``column_sigma`` (3,) rad of each angle."""
    return data.replace(
        sigma_rad=np.broadcast_to(column_sigma, data.angles_rad.shape).copy(), sigma_relative=True
    )


def diagnose_measurements(
    data: OrientationMeasurements,
    *,
    until_explained: bool = False,
    catalogue: Sequence[Effect] | None = None,
    turntable=None,
    outliers: bool = True,
) -> Diagnosis:
    """Diagnose orientation measurements against the effect catalogue (see :mod:`diagnosis`):
    :func:`~turntable_pin.stats.diagnosis_engine.diagnose_data` on the :class:`OrientationFamily`
    of ``data``.

    With ``outliers`` (the default) gross outliers are found by :data:`OUTLIER_RULE`, left out of
    every fit of the verdict and listed in ``Diagnosis.outliers``; ``outliers=False`` keeps every
    measured angle. Without sigmas, when the residuals show that the three angles' noise differ,
    the diagnosis is made again with each model fitted at its own per-angle noise, and a warning
    says so.

    Raises:
        InputError: more rows than :data:`~turntable_pin.core.sizes.MAX_DIAGNOSED_ROWS`.
    """
    family = OrientationFamily(data, catalogue, turntable)
    return diagnose_data(family, until_explained=until_explained, outliers=outliers)


def design_command(
    data: str,
    pair: tuple[str, str],
    urdf: str | None = None,
    mount: str | None = None,
    *,
    data_argument: str = "from_data",
    **more: object,
) -> Command:
    """The ``design`` command that chooses the positions telling the two effects ``pair`` apart,
    or says that none do (``turntable_pin.design.separate``): ``separate``, the data under
    ``data_argument`` (``run`` for a calibration run), ``urdf`` when the table is not the
    paper's, ``mount`` when it is not what its URDF declares, then ``more``."""
    data_given = {data_argument: data}
    return command("design", separate=",".join(pair), **data_given, urdf=urdf, mount=mount, **more)


def urdf_option(turntable) -> str | None:
    """What ``urdf`` names the table by: nothing for the paper's bundled table, the name of a
    bundled table, else its URDF's path."""
    table = getattr(turntable, "table", turntable)
    path = getattr(table, "urdf_path", None)
    if path is None:
        return None
    path = Path(path).resolve()
    if path == default_urdf_path().resolve():
        return None
    return path.stem if path.parent == models_dir().resolve() else str(path)


def mount_option(turntable) -> str | None:
    """What ``mount`` says of the table: nothing when it is what its URDF declares, else its
    mount kind or ``none`` (a turntable whose URDF declares a mount)."""
    table = measured_table(turntable)
    if table.telescope_mount == table.declared_mount:
        return None
    return table.telescope_mount or NO_MOUNT
