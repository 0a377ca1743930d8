"""The orientation-data model family for :func:`diagnose`: base + catalogued effects, probes.

Probes of the structure search (what "shape" the missing part has):

- ``<error> k/rev in <phi>``: the per-position derivative of the prediction with respect to one
  of the eight turntable errors times ``cos(k phi)``, ``sin(k phi)`` -- a harmonic of order k of
  that error in either axis angle (k = 1 .. 5, fewer when the data have fewer distinct angles);
- ``<angle> k/rev in <phi>``: a harmonic added directly to ``dpsi``, ``dtheta`` or ``dgamma``;
- ``<angle> k/rev in phi1+phi2`` / ``phi1-phi2`` (k = 1, 2): shapes that couple the two angles;
- ``<angle> drift in time`` (with ``time_s``): a quadratic in time;
- ``<angle> with dir1`` / ``dir2``: a step with the approach direction.

Every probe also says how its columns factor per position (a weighted direction in ``dpsi,
dtheta, dgamma`` times functions of one variable: phi1, phi2, phi1+-phi2, time_s or dir), so the
report can plot each found term against its variable.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..core.sizes import DIAGNOSIS_ROW_BYTES, MAX_DIAGNOSED_ROWS, check_count
from ..core.units import ARCSEC_PER_RAD, DEG_PER_RAD
from ..model.errors import ANGULAR_ERROR_NAMES, ERROR_DESCRIPTIONS
from ..model.turntable import TurntableModel
from ..stats.least_squares import RANK_RTOL
from ..stats.model_selection import Diagnosis, diagnose
from ..stats.structure_search import Probe, ProbeFactors
from .data import ANGLE_NAMES, OrientationMeasurements
from .effect_model import OrientationModel
from .effects import EFFECTS, get_effect
from .effects.base import Effect, PositionVariables
from .fit import OrientationFit, fit_orientation

__all__ = ["MAX_HARMONIC", "SEPARATION_CHI2", "OrientationFamily", "diagnose_measurements"]

MAX_HARMONIC = 5
SEPARATION_CHI2 = 25.0
"""Noise-free misfit chi2 above which a denser design is said to separate two effects."""


def _harmonic(k: int):
    """The basis functions ``cos(k x), sin(k x)`` of a k/rev probe, (p,) -> (p, 2)."""
    return lambda x: np.stack([np.cos(k * x), np.sin(k * x)], axis=-1)


def _one_angle(w: np.ndarray, a: int):
    """The direction of a term added to measured angle ``a`` alone, weighted, (N, 3)."""

    def direction():
        d = np.zeros_like(w)
        d[:, a] = w[:, a]
        return d

    return direction


def _max_order(angle_rad: np.ndarray) -> int:
    distinct = np.unique(np.round(np.mod(angle_rad, 2 * np.pi), 9)).size
    return int(min(MAX_HARMONIC, max(0, (distinct - 1) // 2)))


class OrientationFamily:
    """Orientation data, the base error model, and the effect catalogue (a ``ModelFamily``)."""

    record_label = "positions"
    observation_unit = "arcsec"

    def __init__(
        self,
        data: OrientationMeasurements,
        catalogue: Sequence[Effect] | None = None,
        turntable: TurntableModel | None = None,
    ) -> None:
        self.data = data
        self.catalogue = tuple(catalogue if catalogue is not None else EFFECTS.values())
        self.turntable = turntable or TurntableModel()
        self.n_records = data.n_positions
        self.sigma_scale = (
            float(np.median(data.sigma_rad) * ARCSEC_PER_RAD)
            if data.sigma_rad is not None
            else ARCSEC_PER_RAD
        )
        self._cache: dict[tuple[str, ...], OrientationFit] = {}

    def fit(self, effects: Sequence[Effect], noise_variance: float | None = None) -> OrientationFit:
        """The fit of the base errors plus ``effects`` (cached per effect list)."""
        key = tuple(e.name for e in effects)
        if key not in self._cache:
            self._cache[key] = fit_orientation(self.data, effects, turntable=self.turntable)
        return self._cache[key]

    def untestable_reason(self, effect: Effect) -> str | None:
        """Why ``effect`` cannot be tested here (its data columns are missing), or None."""
        missing = effect.missing_columns(self.data.variables())
        if missing:
            return f"needs the column(s) {', '.join(missing)}, absent from the data"
        return None

    def describe(self, effect: Effect | str) -> dict:
        """The effect's story: title, definition, explanation, how to confirm it."""
        return (get_effect(effect) if isinstance(effect, str) else effect).describe()

    def design_warnings(self, base_fit: OrientationFit) -> list[str]:
        """Warn when the positions determine fewer error combinations than a full grid does.

        The base model's rank on the data is compared with its rank on a 15-degree grid of both
        axes; fewer means some turntable errors (and any effect that varies with phi1 or phi2)
        cannot be told apart here, so a step with ``dir`` or a drift with ``time_s`` may stand for
        whatever changed between the rows.
        """
        data = self.data
        rank = base_fit.result.rank
        dense = OrientationModel(self._dense_variables(), (), self.turntable)
        jac = dense.jacobian(np.zeros(dense.n_params)).reshape(-1, dense.n_params)
        singular = np.linalg.svd(jac / np.linalg.norm(jac, axis=0).clip(1e-300), compute_uv=False)
        full_rank = int(np.sum(singular > RANK_RTOL * singular[0]))
        if rank >= full_rank:
            return []
        wrapped = np.round(np.mod(np.degrees([data.phi1_rad, data.phi2_rad]), 360.0), 6) % 360.0
        distinct = np.unique(wrapped.T, axis=0)
        where = (
            f"all {data.n_positions} rows are at one position (phi1 {distinct[0, 0]:g}, phi2 "
            f"{distinct[0, 1]:g} deg)"
            if len(distinct) == 1
            else f"the {data.n_positions} rows are at {len(distinct)} distinct positions"
        )
        return [
            f"{where}: they determine {rank} of the {full_rank} combinations of the turntable "
            "errors that a grid over both axes determines, so effects that vary with phi1 or phi2 "
            "cannot be tested, and an effect named here (a step with dir, a drift in time) may "
            "stand for any error that changed between the rows; measure more positions over the "
            "full turn of both axes"
        ]

    def _measured_angle_probes(
        self,
        trig: np.ndarray,
        shape: str,
        w: np.ndarray,
        plot: tuple[str, np.ndarray, int] | None = None,
    ) -> list[Probe]:
        """One probe per measured angle: the harmonic pair ``trig`` (N, 2) added to that angle.

        ``plot`` (variable name, its values in rad, order k) describes ``trig`` as ``k/rev`` in
        that variable, for the probes' :class:`ProbeFactors`.
        """
        probes = []
        for a, angle in enumerate(ANGLE_NAMES):

            def columns(a=a):
                cols = np.zeros((self.data.n_positions, 3, 2))
                cols[:, a, :] = trig * w[:, a, None]
                return cols.reshape(-1, 2)

            factors = None
            if plot is not None:
                var, values, k = plot
                factors = ProbeFactors(
                    var, values, _harmonic(k), _one_angle(w, a), DEG_PER_RAD, "deg"
                )
            probes.append(
                Probe(
                    f"{angle} {shape}",
                    f"a {shape.replace('/rev', '/rev term', 1)} of {angle} itself",
                    columns,
                    ARCSEC_PER_RAD,
                    "arcsec",
                    factors,
                )
            )
        return probes

    def probes(self, fit: OrientationFit) -> list[Probe]:
        """The structure-search probes, weighted like the residuals of ``fit`` (see the module)."""
        data = self.data
        w = fit.result.weights.reshape(-1, 3)
        jac = fit.model.jacobian(fit.result.params)  # (N, 3, n)
        probes = []
        angles = {"phi1": data.phi1_rad, "phi2": data.phi2_rad}
        for var, phi in angles.items():
            for k in range(1, _max_order(phi) + 1):
                trig = np.stack([np.cos(k * phi), np.sin(k * phi)], axis=-1)  # (N, 2)
                for e, name in enumerate(ANGULAR_ERROR_NAMES):

                    def columns(e=e, trig=trig):
                        return (jac[:, :, e, None] * trig[:, None, :] * w[:, :, None]).reshape(
                            -1, 2
                        )

                    def direction(e=e):
                        return jac[:, :, e] * w

                    probes.append(
                        Probe(
                            f"{name} {k}/rev in {var}",
                            f"a {k}/rev term in {var} of {name} ({ERROR_DESCRIPTIONS[name]})",
                            columns,
                            ARCSEC_PER_RAD,
                            "arcsec",
                            ProbeFactors(var, phi, _harmonic(k), direction, DEG_PER_RAD, "deg"),
                        )
                    )
                probes += self._measured_angle_probes(trig, f"{k}/rev in {var}", w, (var, phi, k))
        # Terms coupling the two angles (k/rev in phi1 + phi2 or phi1 - phi2) on each angle: the
        # shapes above are separable in phi1 and phi2 and would miss them.
        for label, combined in (("phi1+phi2", data.phi1_rad + data.phi2_rad),
                                ("phi1-phi2", data.phi1_rad - data.phi2_rad)):  # fmt: skip
            for k in range(1, min(2, _max_order(combined)) + 1):
                trig = np.stack([np.cos(k * combined), np.sin(k * combined)], axis=-1)
                probes += self._measured_angle_probes(
                    trig, f"{k}/rev in {label}", w, (label, combined, k)
                )
        extra = []
        if data.time_s is not None and np.ptp(data.time_s) > 0:
            t = (data.time_s - data.time_s.min()) / np.ptp(data.time_s)
            t0, span = float(data.time_s.min()), float(np.ptp(data.time_s))

            def drift(x, t0=t0, span=span):
                u = (np.asarray(x, dtype=float) - t0) / span
                return np.stack([u, u**2], axis=-1)

            extra.append(("drift in time", "a drift with time (quadratic over the run)", [t, t**2],
                          ("time_s", data.time_s, drift, 1.0, "s")))  # fmt: skip
        for column in ("dir1", "dir2"):
            value = getattr(data, column)
            if value is not None:
                step = (column, value, lambda x: np.asarray(x, dtype=float)[:, None], 1.0, "")
                extra.append((f"with {column}", f"a step with the approach direction {column}",
                              [value], step))  # fmt: skip
        for label, text, columns, (var, values, functions, scale, unit) in extra:
            for a, angle in enumerate(ANGLE_NAMES):

                def matrix(a=a, columns=columns):
                    cols = np.zeros((data.n_positions, 3, len(columns)))
                    for j, c in enumerate(columns):
                        cols[:, a, j] = c * w[:, a]
                    return cols.reshape(-1, len(columns))

                factors = ProbeFactors(var, values, functions, _one_angle(w, a), scale, unit)
                probes.append(
                    Probe(
                        f"{angle} {label}",
                        f"{text} in {angle}",
                        matrix,
                        ARCSEC_PER_RAD,
                        "arcsec",
                        factors,
                    )
                )
        return probes

    def _dense_variables(self) -> PositionVariables:
        g = np.radians(np.arange(0.0, 360.0, 15.0))
        g1, g2 = np.meshgrid(g, g, indexing="ij")
        n = g1.size
        rng = np.random.default_rng(0)
        data = self.data
        time = None
        if data.time_s is not None:
            time = rng.permutation(np.linspace(data.time_s.min(), data.time_s.max(), n))
        dirs = [rng.choice([-1.0, 1.0], n) if getattr(data, c) is not None else None
                for c in ("dir1", "dir2")]  # fmt: skip
        return PositionVariables(g1.ravel(), g2.ravel(), time, dirs[0], dirs[1])

    def separation(self, fit_a: OrientationFit, effect_b: Effect) -> str:
        """Whether more positions would separate effect A (fitted) from B, or only another test."""
        a_effects = fit_a.model.effects
        a = a_effects[-1]
        variables = self._dense_variables()
        truth = OrientationModel(variables, a_effects, self.turntable).predict(fit_a.result.params)
        sigma = float(np.median(fit_a.sigma_rad))
        dense = OrientationMeasurements(
            variables.phi1_rad, variables.phi2_rad, truth, np.full(variables.n, sigma),
            variables.time_s, variables.dir1, variables.dir2, source="dense design",
        )  # fmt: skip
        base_effects = [e for e in a_effects if e is not a]
        misfit = fit_orientation(dense, [*base_effects, effect_b], turntable=self.turntable)
        chi2 = misfit.result.rss
        if chi2 > SEPARATION_CHI2:
            return (
                f"{effect_b.name} mimics {a.name} on these positions only: on a 15-degree grid "
                f"({variables.n} positions, random time order) it would leave chi2 = {chi2:.0f} "
                f"of misfit at the same noise, so measuring more angles separates them"
            )
        return (
            f"{effect_b.name} reproduces the fitted {a.name} at every turntable position "
            f"(noise-free misfit chi2 = {chi2:.2g} on a 15-degree grid), so no set of positions "
            f"separates them; an independent measurement does. For {a.name}: {a.confirm} "
            f"For {effect_b.name}: {effect_b.confirm}"
        )


def diagnose_measurements(
    data: OrientationMeasurements,
    *,
    until_explained: bool = False,
    catalogue: Sequence[Effect] | None = None,
    turntable: TurntableModel | None = None,
) -> Diagnosis:
    """Diagnose orientation measurements against the effect catalogue (see :mod:`diagnosis`).

    Raises:
        InputError: more rows than :data:`~turntable_pin.core.sizes.MAX_DIAGNOSED_ROWS`.
    """
    check_count(data.n_positions, MAX_DIAGNOSED_ROWS, "measurement rows", DIAGNOSIS_ROW_BYTES)
    return diagnose(OrientationFamily(data, catalogue, turntable), until_explained=until_explained)
