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

import numpy as np

from ..core.exceptions import InputError
from ..core.sizes import DIAGNOSIS_ROW_BYTES, MAX_DIAGNOSED_ROWS, check_count
from ..core.units import ARCSEC_PER_RAD
from ..stats.least_squares import RANK_RTOL
from ..stats.model_selection import Diagnosis, diagnose
from ..stats.structure_search import Probe
from .catalogue import catalogue as table_catalogue
from .catalogue import resolve_effect
from .data import ANGLE_NAMES, OrientationMeasurements
from .effect_model import OrientationModel
from .effects.base import Effect, PositionVariables
from .fit import OrientationFit, fit_orientation, orientation_zero_point
from .table import measured_table

__all__ = ["MAX_HARMONIC", "SEPARATION_CHI2", "OrientationFamily", "diagnose_measurements"]

MAX_HARMONIC = 5
SEPARATION_CHI2 = 25.0
"""Noise-free misfit chi2 above which a denser design is said to separate two effects."""


def _max_order(angle_rad: np.ndarray) -> int:
    distinct = np.unique(np.round(np.mod(angle_rad, 2 * np.pi), 9)).size
    return int(min(MAX_HARMONIC, max(0, (distinct - 1) // 2)))


class OrientationFamily:
    """Orientation data, the table's base error model and its effect catalogue (a
    ``ModelFamily``).

    Args:
        data: the measurements.
        catalogue: the candidate effects (default: the table's catalogue).
        turntable: the table (see :func:`~turntable_pin.measurement.table.measured_table`).
    """

    record_label = "positions"
    observation_unit = "arcsec"

    def __init__(
        self,
        data: OrientationMeasurements,
        catalogue: Sequence[Effect] | None = None,
        turntable=None,
    ) -> None:
        self.data = data
        self.table = measured_table(turntable)
        self.turntable = self.table
        self.catalogue = tuple(catalogue if catalogue is not None else table_catalogue(self.table))
        self.n_records = data.n_positions
        self.sigma_scale = (
            float(np.nanmedian(np.where(data.measured, data.sigma_rad, np.nan)) * ARCSEC_PER_RAD)
            if data.sigma_rad is not None
            else ARCSEC_PER_RAD
        )
        self._mask = data.measured.reshape(-1)
        self._cache: dict[tuple[str, ...], OrientationFit] = {}

    def fit(self, effects: Sequence[Effect], noise_variance: float | None = None) -> OrientationFit:
        """The fit of the base errors plus ``effects`` (cached per effect list)."""
        key = tuple(e.name for e in effects)
        if key not in self._cache:
            self._cache[key] = fit_orientation(
                self.data, effects, turntable=self.table, zero_point=self._zero_point()
            )
        return self._cache[key]

    def _zero_point(self):
        """The reduced Jacobian at zero of the base and every testable catalogued effect, shared
        by all fits of the diagnosis (computed on first use)."""
        if not hasattr(self, "_zero"):
            variables = self.data.variables()
            testable = [e for e in self.catalogue if not e.missing_columns(variables)]
            try:
                self._zero = orientation_zero_point(self.data, testable, turntable=self.table)
            except InputError:  # effects that cannot share one model: each fit on its own
                self._zero = None
        return self._zero

    def untestable_reason(self, effect: Effect) -> str | None:
        """Why ``effect`` cannot be tested here (its data columns are missing), or None."""
        missing = effect.missing_columns(self.data.variables())
        if missing:
            return f"needs the column(s) {', '.join(missing)}, absent from the data"
        return None

    def effect(self, name: str) -> Effect:
        """The effect called ``name``: in this family's catalogue first, then the table's."""
        return resolve_effect(name, self.table, self.catalogue)

    def describe(self, effect: Effect | str) -> dict:
        """The effect's story: title, definition, explanation, how to confirm it."""
        return (self.effect(effect) if isinstance(effect, str) else effect).describe()

    def design_warnings(self, base_fit: OrientationFit) -> list[str]:
        """Warn when the positions determine fewer error combinations than a full grid does.

        The base model's rank on the data is compared with its rank on a dense grid over every
        axis; fewer means some turntable errors (and any effect that varies with a joint angle)
        cannot be told apart here, so a step with ``dir`` or a drift with ``time_s`` may stand
        for whatever changed between the rows.
        """
        data = self.data
        rank = base_fit.result.rank
        dense = OrientationModel(self._dense_variables(), (), self.table)
        jac = dense.jacobian(np.zeros(dense.n_params)).reshape(-1, dense.n_params)
        singular = np.linalg.svd(jac / np.linalg.norm(jac, axis=0).clip(1e-300), compute_uv=False)
        full_rank = int(np.sum(singular > RANK_RTOL * singular[0]))
        if rank >= full_rank:
            return []
        wrapped = np.round(np.mod(np.degrees(data.joint_rad), 360.0), 6) % 360.0
        distinct = np.unique(wrapped, axis=0)
        labels = [self.table.angle_label(k) for k in range(1, data.n_joints + 1)]
        axes = " or ".join(labels)
        where = (
            f"all {data.n_positions} rows are at one position ("
            + ", ".join(f"{lab} {v:g}" for lab, v in zip(labels, distinct[0], strict=True))
            + " deg)"
            if len(distinct) == 1
            else f"the {data.n_positions} rows are at {len(distinct)} distinct positions"
        )
        return [
            f"{where}: they determine {rank} of the {full_rank} combinations of the turntable "
            f"errors that a grid over every axis determines, so effects that vary with {axes} "
            "cannot be tested, and an effect named here (a step with dir, a drift in time) may "
            "stand for any error that changed between the rows; measure more positions over the "
            "full turn of every axis"
        ]

    def _observations(self, cols: np.ndarray) -> np.ndarray:
        """(N, 3, g) per-angle columns as (m, g) rows of the measured observations."""
        cols = cols.reshape(-1, cols.shape[-1])
        return cols if self._mask.all() else cols[self._mask]

    def _measured_angle_probes(self, trig: np.ndarray, shape: str, w: np.ndarray) -> list[Probe]:
        """One probe per measured angle: the columns ``trig`` (N, g) added to that angle."""
        probes = []
        for a, angle in enumerate(ANGLE_NAMES):
            if not self.data.measured[:, a].any():
                continue

            def columns(a=a):
                cols = np.zeros((self.data.n_positions, 3, trig.shape[1]))
                cols[:, a, :] = trig * w[:, a, None]
                return self._observations(cols)

            probes.append(
                Probe(
                    f"{angle} {shape}",
                    f"a {shape.replace('/rev', '/rev term', 1)} of {angle} itself",
                    columns,
                    ARCSEC_PER_RAD,
                    "arcsec",
                )
            )
        return probes

    def _error_probes(self, jac, w, trig, shape: str, what: str) -> list[Probe]:
        """One probe per base error: its derivative times the columns ``trig`` (N, g)."""
        probes = []
        for e, name in enumerate(self.table.base_names):

            def columns(e=e):
                return self._observations(jac[:, :, e, None] * trig[:, None, :] * w[:, :, None])

            probes.append(
                Probe(
                    f"{name} {shape}",
                    f"a {what} of {name} ({self.table.descriptions.get(name, name)})",
                    columns,
                    ARCSEC_PER_RAD,
                    "arcsec",
                )
            )
        return probes

    def probes(self, fit: OrientationFit) -> list[Probe]:
        """The structure-search probes, weighted like the residuals of ``fit`` (see the module)."""
        data = self.data
        w = np.nan_to_num(fit.per_angle(fit.result.weights))  # (N, 3), 0 where not measured
        jac = fit.model.jacobian(fit.result.params)  # (N, 3, n)
        probes = []
        labels = [self.table.angle_label(k) for k in range(1, data.n_joints + 1)]
        for var, phi in zip(labels, data.joint_rad.T, strict=True):
            for k in range(1, _max_order(phi) + 1):
                trig = np.stack([np.cos(k * phi), np.sin(k * phi)], axis=-1)  # (N, 2)
                probes += self._error_probes(jac, w, trig, f"{k}/rev in {var}",
                                             f"{k}/rev term in {var}")  # fmt: skip
                probes += self._measured_angle_probes(trig, f"{k}/rev in {var}", w)
        # Terms coupling two angles (k/rev in phiA + phiB or phiA - phiB) on each angle: the
        # shapes above are separable in the angles and would miss them.
        for i in range(data.n_joints):
            for j in range(i + 1, data.n_joints):
                a, b = data.joint_rad[:, i], data.joint_rad[:, j]
                for sign, combined in (("+", a + b), ("-", a - b)):
                    label = f"{labels[i]}{sign}{labels[j]}"
                    for k in range(1, min(2, _max_order(combined)) + 1):
                        trig = np.stack([np.cos(k * combined), np.sin(k * combined)], axis=-1)
                        probes += self._measured_angle_probes(trig, f"{k}/rev in {label}", w)
        extra = []
        if data.time_s is not None and np.ptp(data.time_s) > 0:
            t = (data.time_s - data.time_s.min()) / np.ptp(data.time_s)
            extra.append(("drift in time", "a drift with time (quadratic over the run)",
                          np.stack([t, t**2], axis=1)))  # fmt: skip
        for k, value in enumerate(data.dirs, start=1):
            if value is not None:
                extra.append((f"with dir{k}", f"a step with the approach direction dir{k}",
                              value[:, None]))  # fmt: skip
        for label, text, columns in extra:
            for a, angle in enumerate(ANGLE_NAMES):
                if not data.measured[:, a].any():
                    continue

                def matrix(a=a, columns=columns):
                    cols = np.zeros((data.n_positions, 3, columns.shape[1]))
                    cols[:, a, :] = columns * w[:, a, None]
                    return self._observations(cols)

                probes.append(Probe(f"{angle} {label}", f"{text} in {angle}", matrix,
                                    ARCSEC_PER_RAD, "arcsec"))  # fmt: skip
        # Other numeric columns (temperature, load, ...) as suspects: each base error and each
        # measured angle linear and quadratic in the column.
        for column, values in data.extra.items():
            span = np.ptp(values)
            if not span > 0:
                continue
            c = (values - values.min()) / span
            trig = np.stack([c, c**2], axis=1)
            probes += self._error_probes(jac, w, trig, f"in {column}",
                                         f"term linear and quadratic in {column}")  # fmt: skip
            probes += self._measured_angle_probes(trig, f"in {column}", w)
        return probes

    def _dense_variables(self) -> PositionVariables:
        """A dense design over every axis (15-degree grid; 30 degrees for three axes), with a
        random time order and random approach directions where the data have them."""
        step = 30.0 if self.data.n_joints > 2 else 15.0
        g = np.radians(np.arange(0.0, 360.0, step))
        grids = np.meshgrid(*([g] * self.data.n_joints), indexing="ij")
        joints = np.stack([x.ravel() for x in grids], axis=1)
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

    def separation(self, fit_a: OrientationFit, effect_b: Effect) -> str:
        """Whether more positions would separate effect A (fitted) from B, or only another test."""
        a_effects = fit_a.model.effects
        a = a_effects[-1]
        variables = self._dense_variables()
        truth = OrientationModel(variables, a_effects, self.table).predict(fit_a.result.params)
        sigma = float(np.median(fit_a.sigma_rad))
        dense = OrientationMeasurements(
            variables.joint_rad, truth, np.full(variables.n, sigma), variables.time_s,
            variables.dirs, dict(variables.extra), source="dense design",
        )  # fmt: skip
        base_effects = [e for e in a_effects if e is not a]
        misfit = fit_orientation(dense, [*base_effects, effect_b], turntable=self.table)
        chi2 = misfit.result.rss
        grid = "30-degree" if self.data.n_joints > 2 else "15-degree"
        if chi2 > SEPARATION_CHI2:
            return (
                f"{effect_b.name} mimics {a.name} on these positions only: on a {grid} grid "
                f"({variables.n} positions, random time order) it would leave chi2 = {chi2:.0f} "
                f"of misfit at the same noise, so measuring more angles separates them"
            )
        return (
            f"{effect_b.name} reproduces the fitted {a.name} at every turntable position "
            f"(noise-free misfit chi2 = {chi2:.2g} on a {grid} grid), so no set of positions "
            f"separates them; an independent measurement does. For {a.name}: {a.confirm} "
            f"For {effect_b.name}: {effect_b.confirm}"
        )


def diagnose_measurements(
    data: OrientationMeasurements,
    *,
    until_explained: bool = False,
    catalogue: Sequence[Effect] | None = None,
    turntable=None,
) -> Diagnosis:
    """Diagnose orientation measurements against the effect catalogue (see :mod:`diagnosis`).

    Raises:
        InputError: more rows than :data:`~turntable_pin.core.sizes.MAX_DIAGNOSED_ROWS`.
    """
    check_count(data.n_positions, MAX_DIAGNOSED_ROWS, "measurement rows", DIAGNOSIS_ROW_BYTES)
    return diagnose(OrientationFamily(data, catalogue, turntable), until_explained=until_explained)
