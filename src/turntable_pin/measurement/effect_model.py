"""The orientation error predicted by the turntable's exact chain plus catalogued effects.

The chain is the turntable's :class:`~turntable_pin.model.chain.ErrorChain` (nominal placements,
joint axes, error factors), the same object Pinocchio evaluation and :class:`OrientationErrorField`
read. Effects (:mod:`turntable_pin.measurement.effects`) add to the error angles per position,
insert rotations before or after ``Rt``, or add to a measured angle itself. Every parametrised
factor is a rotation about a coordinate axis by an angle *linear* in the parameters, so the
Jacobian is exact and cheap: for ``Rt = A R_a(theta) B``, ``dRt/dtheta = A R_a(theta) [e_a]x B``,
composed from prefix and suffix products.

Parameters (internal units): the table's base errors (rad; the paper's table: the eight angular
errors in :data:`ANGULAR_ERROR_NAMES` order), then each effect's parameters as
``"<effect>.<name>"``. Offsets (``deta``, ``<joint>.offset_a``...) are left out: they move the
payload origin, never its orientation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..core.exceptions import InputError
from ..core.rotations import AXIS_INDEX, axis_rotation
from ..core.units import ARCSEC_PER_RAD
from ..model.angles import ANGLE_ENTRIES, ANGLE_NAMES
from ..model.chain import ROTATION, skew
from ..model.errors import ANGULAR_ERROR_NAMES
from .effects.base import MEASURED, POST, PRE, Effect, ParameterSpec, PositionVariables
from .table import MeasuredTable, measured_table

__all__ = ["AXIS_INDEX", "BASE_PARAMETERS", "OrientationModel", "base_parameters"]


def base_parameters(names) -> tuple[ParameterSpec, ...]:
    """The base errors ``names`` as parameters in arcsec."""
    return tuple(ParameterSpec(name, "arcsec", 1.0 / ARCSEC_PER_RAD, name) for name in names)


BASE_PARAMETERS: tuple[ParameterSpec, ...] = base_parameters(ANGULAR_ERROR_NAMES)
"""The paper's base errors as parameters."""

_GENERATORS = {
    axis: np.array(m, dtype=float)
    for axis, m in {
        "x": [[0, 0, 0], [0, 0, -1], [0, 1, 0]],
        "y": [[0, 0, 1], [0, 0, 0], [-1, 0, 0]],
        "z": [[0, -1, 0], [1, 0, 0], [0, 0, 0]],
    }.items()
}


@dataclass(frozen=True)
class _Factor:
    """One rotation of the chain: fixed matrices (N or 1, 3, 3) or ``R_axis(G @ p)``."""

    fixed: np.ndarray | None = None
    axis: str | None = None
    gain: np.ndarray | None = None  # (N, n_params): angle = gain @ p


class OrientationModel:
    """``dpsi, dtheta, dgamma`` at N positions from the base errors and a set of effects.

    Args:
        variables: the commanded angles (and time, directions) of the positions.
        effects: catalogued effects to include (their required columns must be present).
        turntable: the table (:func:`~turntable_pin.measurement.table.measured_table` reads a
            ``TurntableModel``, a ``GenericTable`` or ``None``: the bundled paper table).
    """

    def __init__(
        self,
        variables: PositionVariables,
        effects: Sequence[Effect] = (),
        turntable: MeasuredTable | object | None = None,
    ) -> None:
        self.variables = variables
        self.effects = tuple(effects)
        self.table = turntable = measured_table(turntable)
        if variables.n_joints != turntable.n_joints:
            raise InputError(
                f"the data have {variables.n_joints} joint angle(s), the table has "
                f"{turntable.n_joints} ({', '.join(turntable.joint_names)})"
            )
        self.base_names = turntable.base_names
        specs: list[ParameterSpec] = list(base_parameters(self.base_names))
        names = list(self.base_names)
        terms_by_effect = []
        for effect in self.effects:
            missing = effect.missing_columns(variables)
            if missing:
                raise InputError(
                    f"effect '{effect.name}' needs the column(s) {', '.join(missing)}, "
                    "which the data do not have"
                )
            for spec in effect.parameters(variables):
                specs.append(spec)
                names.append(f"{effect.name}.{spec.name}")
            terms_by_effect.append((effect, effect.chain_terms(variables)))
        self.parameter_specs = tuple(specs)
        self.parameter_names = tuple(names)
        self.parameter_units = tuple(s.unit for s in specs)
        self.per_user_unit = np.array([s.per_user_unit for s in specs])
        self._index = {name: i for i, name in enumerate(names)}
        self._added = None  # (N, 3, n_params): terms added to a measured angle, if any
        self._factors, self._rd = self._build_chain(turntable, terms_by_effect)

    @property
    def n_params(self) -> int:
        """Number of parameters: the base errors plus every effect's parameters."""
        return len(self.parameter_names)

    def _gain(self, weights: dict[str, np.ndarray], prefix: str) -> np.ndarray:
        gain = np.zeros((self.variables.n, self.n_params))
        for name, w in weights.items():
            gain[:, self._index[f"{prefix}{name}"]] += np.asarray(w, dtype=float)
        return gain

    def _build_chain(self, turntable: MeasuredTable, terms_by_effect):
        n = self.variables.n
        pre, post = [], []
        error_gain = {}
        for name in self.base_names:
            gain = np.zeros((n, self.n_params))
            gain[:, self._index[name]] = 1.0
            error_gain[name] = gain
        for effect, terms in terms_by_effect:
            for term in terms:
                gain = self._gain(term.weights, f"{effect.name}.")
                if term.site == PRE:
                    pre.append(_Factor(axis=term.axis, gain=gain))
                elif term.site == POST:
                    post.append(_Factor(axis=term.axis, gain=gain))
                elif term.site == MEASURED and term.axis in ANGLE_NAMES:
                    if self._added is None:
                        self._added = np.zeros((n, 3, self.n_params))
                    self._added[:, ANGLE_NAMES.index(term.axis)] += gain
                elif term.site in error_gain:
                    error_gain[term.site] = error_gain[term.site] + gain
                else:
                    raise InputError(
                        f"effect '{effect.name}' changes '{term.site}', which is not an error of "
                        f"this table; its errors: {', '.join(self.base_names)}"
                    )

        joint_angles = iter(self.variables.joint_rad.T)
        chain: list[_Factor] = list(pre)
        ideal = np.broadcast_to(np.eye(3), (n, 3, 3))
        for link in turntable.chain.links:
            placement = link.nominal[None, :3, :3]
            chain.append(_Factor(fixed=placement))
            chain.extend(
                _Factor(axis=f.axis, gain=error_gain[f.error])
                for f in link.factors
                if f.kind == ROTATION
            )
            ideal = ideal @ placement
            if link.is_joint:
                rotation = axis_rotation(link.axis, np.asarray(next(joint_angles), float))
                chain.append(_Factor(fixed=rotation))
                ideal = ideal @ rotation
        chain.extend(post)
        return chain, np.swapaxes(ideal, -1, -2).copy()

    def _matrices(self, params: np.ndarray) -> list[np.ndarray]:
        n = self.variables.n
        out = []
        for f in self._factors:
            if f.fixed is not None:
                out.append(np.broadcast_to(f.fixed, (n, 3, 3)))
            else:
                out.append(axis_rotation(f.axis, f.gain @ params))
        return out

    def _check(self, params) -> np.ndarray:
        params = np.asarray(params, dtype=float).reshape(-1)
        if params.size != self.n_params:
            raise InputError(f"expected {self.n_params} parameters, got {params.size}")
        return params

    def rotation_error(self, params) -> np.ndarray:
        """``dR = Rd^T Rt`` at each position, (N, 3, 3)."""
        total = None
        for m in self._matrices(self._check(params)):
            total = m if total is None else total @ m
        return self._rd @ total

    def predict(self, params) -> np.ndarray:
        """``[dpsi, dtheta, dgamma]`` (rad) at each position, (N, 3)."""
        dR = self.rotation_error(params)
        angles = np.stack([dR[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)
        return angles if self._added is None else angles + self._added @ params

    def jacobian(self, params) -> np.ndarray:
        """Exact derivative of :meth:`predict` with respect to the parameters, (N, 3, n)."""
        mats = self._matrices(self._check(params))
        n = self.variables.n
        prefix = [self._rd]
        for m in mats:
            prefix.append(prefix[-1] @ m)
        suffix = [np.broadcast_to(np.eye(3), (n, 3, 3))]
        for m in reversed(mats):
            suffix.append(m @ suffix[-1])
        suffix = suffix[::-1]  # suffix[f] = product of factors f..end
        jac = np.zeros((n, 3, self.n_params)) if self._added is None else self._added.copy()
        for f, factor in enumerate(self._factors):
            if factor.fixed is not None:
                continue
            generator = (
                _GENERATORS[factor.axis] if isinstance(factor.axis, str) else skew(factor.axis)
            )
            d = prefix[f + 1] @ generator @ suffix[f + 1]
            entries = np.stack([d[:, i, j] for i, j in ANGLE_ENTRIES], axis=1)  # (N, 3)
            jac += entries[:, :, None] * factor.gain[:, None, :]
        return jac

    def parameter_vector(self, values: dict[str, float] | None = None) -> np.ndarray:
        """A parameter vector (internal units) from ``{name: value in internal units}``."""
        p = np.zeros(self.n_params)
        for name, value in (values or {}).items():
            if name not in self._index:
                raise InputError(f"unknown parameter '{name}'; parameters: {self.parameter_names}")
            p[self._index[name]] = value
        return p
