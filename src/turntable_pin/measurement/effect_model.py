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
from ..core.user_code import is_user_code
from ..model.angles import ANGLE_ENTRIES, ANGLE_NAMES
from ..model.chain import ROTATION
from ..model.errors import ANGULAR_ERROR_NAMES
from .effects.base import MEASURED, POST, PRE, Effect, ParameterSpec, PositionVariables
from .effects.contract import check_effect
from .table import MeasuredTable, measured_table

__all__ = ["AXIS_INDEX", "BASE_PARAMETERS", "OrientationModel", "base_parameters"]


def base_parameters(names) -> tuple[ParameterSpec, ...]:
    """The base errors ``names`` as parameters in arcsec."""
    return tuple(ParameterSpec(name, "arcsec", 1.0 / ARCSEC_PER_RAD, name) for name in names)


BASE_PARAMETERS: tuple[ParameterSpec, ...] = base_parameters(ANGULAR_ERROR_NAMES)
"""The paper's base errors as parameters."""


@dataclass(frozen=True)
class _Factor:
    """One rotation of the chain: fixed matrices or ``R_axis(angle)``.

    Matrices are stored entry-major, (3, 3, N or 1): ``m[r, c]`` is the entry (r, c) at every
    position, so products and the Jacobian work on contiguous vectors. A parametrised factor's
    angle is ``p[columns] @ weights`` (rad): ``columns`` are the indices of the few parameters
    that turn it, ``weights`` their gains per position, (k, N or 1). The gains are kept sparse:
    a dense (N, n_params) gain per factor cost most of the memory and time of the Jacobian on
    long logs.
    """

    fixed: np.ndarray | None = None
    axis: str | np.ndarray | None = None
    columns: np.ndarray | None = None
    weights: np.ndarray | None = None

    def angle(self, params: np.ndarray, rows: slice = slice(None)) -> np.ndarray:
        """The factor's angle at the positions ``rows`` (rad): (n,), or (1,) when it is the same
        at every position (its cosine and sine are then computed once)."""
        weights = self.weights if self.weights.shape[-1] == 1 else self.weights[:, rows]
        return params[self.columns] @ weights

    def matrices(self, rows: slice) -> np.ndarray:
        """The fixed matrices of the positions ``rows`` (3, 3, n or 1)."""
        return self.fixed if self.fixed.shape[-1] == 1 else self.fixed[..., rows]


_UNIT_GAIN = np.asarray(1.0)
"""The gain of a base error on its own rotation (one object: models share what is built on it)."""
_UNIT_GAIN.setflags(write=False)


def _merged(entry: tuple | None, new: tuple) -> tuple:
    """Two ``(gain, origin)`` of one parameter added (``new`` itself when there is no ``entry``)."""
    return new if entry is None else (entry[0] + new[0], entry[1] + new[1])


def _stacked_gain(rows: tuple[np.ndarray, ...], n: int) -> np.ndarray:
    """Gains (each (N,) or a scalar) as the weights (k, N or 1) of a factor."""
    rows = tuple(np.asarray(r, dtype=float) for r in rows)
    if all(r.ndim == 0 for r in rows):
        out = np.array([[float(r)] for r in rows])
    else:
        out = np.stack([np.broadcast_to(r, (n,)) for r in rows])
    out.setflags(write=False)
    return out


def _entry_major(matrices: np.ndarray) -> np.ndarray:
    """Stacked matrices (N, 3, 3) as (3, 3, N)."""
    return np.ascontiguousarray(np.moveaxis(matrices, 0, -1))


def _product(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a @ b`` of entry-major stacks (3, 3, N or 1) (the last axes broadcast)."""
    return sum(a[:, k, None, :] * b[None, k, :, :] for k in range(3))


def _merge_fixed(chain: list[_Factor]) -> list[_Factor]:
    """The chain with runs of fixed factors multiplied into one (identities dropped)."""
    identity = np.eye(3)[:, :, None]
    out: list[_Factor] = []
    for factor in chain:
        if isinstance(factor, _Factor) and factor.fixed is not None:
            fixed = factor.fixed
            if fixed.shape[-1] == 1 and np.array_equal(fixed, identity):
                continue
            if out and isinstance(out[-1], _Factor) and out[-1].fixed is not None:
                out[-1] = _Factor(fixed=_product(out[-1].fixed, fixed))
                continue
        out.append(factor)
    return out


def _rotate_columns(m: np.ndarray, axis: str, angle: np.ndarray) -> None:
    """``m <- m @ R_axis(angle)`` in place for an entry-major stack (3, 3, N): only two columns
    mix."""
    i = AXIS_INDEX[axis]
    j, k = (i + 1) % 3, (i + 2) % 3
    c, s = np.cos(angle), np.sin(angle)
    mj = m[:, j].copy()
    m[:, j] *= c
    m[:, j] += m[:, k] * s
    m[:, k] *= c
    m[:, k] -= mj * s


_TABLE_PART: list = []
"""The last table part built: ``[(turntable, joint_rad, part, rd)]`` (at most one entry)."""


def _table_part(turntable: MeasuredTable, joint_rad: np.ndarray):
    """The table's chain at these joint angles: fixed matrices (entry-major, runs multiplied)
    and ``(axis, error name)`` of its error rotations, in chain order, and ``Rd^T`` (3, 3, N).

    None of it depends on parameters or effects, so the models of one diagnosis (the base and
    every candidate, each step) share the arrays: the last result is kept and reused when the
    table and the joint angles are the same.
    """
    for table, joints, part, rd in _TABLE_PART:
        if table is turntable and joints.shape == joint_rad.shape:
            if np.array_equal(joints, joint_rad):
                return part, rd
    n = joint_rad.shape[0]
    angles = iter(joint_rad.T)
    chain: list = []
    ideal = np.broadcast_to(np.eye(3), (n, 3, 3))
    for link in turntable.chain.links:
        placement = link.nominal[None, :3, :3]
        chain.append(_Factor(fixed=_entry_major(placement)))
        chain.extend((f.axis, f.error) for f in link.factors if f.kind == ROTATION)
        ideal = ideal @ placement
        if link.is_joint:
            rotation = axis_rotation(link.axis, np.asarray(next(angles), float))
            chain.append(_Factor(fixed=_entry_major(rotation)))
            ideal = ideal @ rotation
    part = _merge_fixed(chain)
    rd = _entry_major(np.swapaxes(ideal, -1, -2))
    _TABLE_PART[:] = [(turntable, joint_rad.copy(), part, rd)]
    return part, rd


def _specs_and_terms(effect: Effect, variables: PositionVariables, base_names: tuple[str, ...]):
    """``effect``'s parameters and chain terms on ``variables``; a user's effect checked against
    its contract first (:func:`~.effects.contract.check_effect`, once per data set: the models of
    one diagnosis share the result)."""
    if not is_user_code(effect):
        return effect.parameters(variables), effect.chain_terms(variables)
    return variables.memo(
        ("contract", id(effect), base_names),
        (effect,),
        lambda: check_effect(effect, variables, base_names),
    )


class OrientationModel:
    """``dpsi, dtheta, dgamma`` at N positions from the base errors and a set of effects.

    Args:
        variables: the commanded angles (and time, directions) of the positions.
        effects: catalogued effects to include (their required columns must be present).
        turntable: the table (:func:`~turntable_pin.measurement.table.measured_table` reads a
            a ``GenericTable`` or ``None``: the bundled paper table).
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
                    f"effect '{effect.name}' needs the column(s) "
                    f"{variables.missing_columns_words(missing)}"
                )
            effect_specs, terms = _specs_and_terms(effect, variables, self.base_names)
            for spec in effect_specs:
                specs.append(spec)
                names.append(f"{effect.name}.{spec.name}")
            terms_by_effect.append((effect, terms))
        self.parameter_specs = tuple(specs)
        self.parameter_names = tuple(names)
        self.parameter_units = tuple(s.unit for s in specs)
        self.per_user_unit = np.array([s.per_user_unit for s in specs])
        self._index = {name: i for i, name in enumerate(names)}
        self._added: list[tuple[int, dict[int, np.ndarray]]] = []  # (angle, gain) added to it
        self._factors, self._rd = self._build_chain(turntable, terms_by_effect)

    @property
    def n_params(self) -> int:
        """Number of parameters: the base errors plus every effect's parameters."""
        return len(self.parameter_names)

    def _gain(self, effect: Effect, t: int, weights: dict[str, np.ndarray]) -> dict[int, tuple]:
        """``{parameter index: (gain, origin)}`` of term ``t`` of ``effect``; the origin names
        where the gain comes from: ``((id(effect), t, weight name), ...)``."""
        gain: dict[int, tuple] = {}
        for name, w in weights.items():
            i = self._index[f"{effect.name}.{name}"]
            entry = (np.asarray(w, dtype=float), ((id(effect), t, name),))
            gain[i] = _merged(gain.get(i), entry)
        return gain

    def _build_chain(self, turntable: MeasuredTable, terms_by_effect):
        variables = self.variables
        pre, post = [], []
        unit = (_UNIT_GAIN, (("unit",),))
        error_gain = {name: {self._index[name]: unit} for name in self.base_names}
        by_id = {id(e): e for e in self.effects}

        def factor(axis, gain):
            columns = np.array(sorted(gain), dtype=int)
            rows = tuple(gain[c][0] for c in columns)
            origins = tuple(gain[c][1] for c in columns)
            # Gains of the same origins are the same numbers: the models of one data set (a
            # diagnosis's base and candidates) share their stacked weights while any uses them.
            effects = tuple(by_id[o[0]] for origin in origins for o in origin if o[0] != "unit")
            weights = variables.memo(
                ("gain", origins),
                effects,
                lambda: _stacked_gain(rows, variables.n),
                weak=True,
            )
            return _Factor(axis=axis, columns=columns, weights=weights)

        for effect, terms in terms_by_effect:
            for t, term in enumerate(terms):
                gain = self._gain(effect, t, term.weights)
                if term.site == PRE:
                    pre.append(factor(term.axis, gain))
                elif term.site == POST:
                    post.append(factor(term.axis, gain))
                elif term.site == MEASURED and term.axis in ANGLE_NAMES:
                    angle = ANGLE_NAMES.index(term.axis)
                    self._added.append((angle, {i: w for i, (w, _) in gain.items()}))
                elif term.site in error_gain:
                    merged = dict(error_gain[term.site])
                    for i, entry in gain.items():
                        merged[i] = _merged(merged.get(i), entry)
                    error_gain[term.site] = merged
                else:
                    raise InputError(
                        f"effect '{effect.name}' changes '{term.site}', which is not an error of "
                        f"this table; its errors: {', '.join(self.base_names)}"
                    )

        part, rd = _table_part(turntable, self.variables.joint_rad)
        chain = [*pre]
        for entry in part:
            if isinstance(entry, _Factor):
                chain.append(entry)
            else:
                axis, error = entry
                chain.append(factor(axis, error_gain[error]))
        chain.extend(post)
        return _merge_fixed(chain), rd

    def _check(self, params) -> np.ndarray:
        params = np.asarray(params, dtype=float).reshape(-1)
        if params.size != self.n_params:
            raise InputError(f"expected {self.n_params} parameters, got {params.size}")
        return params

    def _forward(self, params: np.ndarray, axes: bool, rows: slice = slice(None)):
        """``dR = Rd^T * factors`` entry-major (3, 3, N) by one pass along the chain, and with
        ``axes`` the rotation axis of every parametrised factor in the frame of ``dR``'s rows,
        (3, N) each.

        The matrices are all rotations, so the suffix after factor f is ``P_f^T dR`` (``P_f``
        the prefix up to f): ``d dR / d angle_f = P_f [a_f]x P_f^T dR = [P_f a_f]x dR``, and the
        Jacobian needs no suffix products (see :meth:`predict_and_jacobian`).
        """
        m = self._rd[..., rows].copy()
        n = m.shape[-1]
        found = []
        for f in self._factors:
            if f.fixed is not None:
                m = _product(m, f.matrices(rows))
                continue
            angle = f.angle(params, rows)
            if angle.shape[0] != n and not isinstance(f.axis, str):
                angle = np.full(n, angle[0])
            if isinstance(f.axis, str):
                _rotate_columns(m, f.axis, angle)
                if axes:
                    found.append(m[:, AXIS_INDEX[f.axis]].copy())
            else:
                m = _product(m, _entry_major(axis_rotation(f.axis, angle)))
                if axes:
                    generator_axis = np.asarray(f.axis, dtype=float)
                    found.append(sum(m[:, k] * generator_axis[k] for k in range(3)))
        return m, found

    def rotation_error(self, params) -> np.ndarray:
        """``dR = Rd^T Rt`` at each position, (N, 3, 3)."""
        dR = self._forward(self._check(params), False)[0]
        return np.ascontiguousarray(np.moveaxis(dR, -1, 0))

    def predict(self, params) -> np.ndarray:
        """``[dpsi, dtheta, dgamma]`` (rad) at each position, (N, 3); on the rows whose roll is
        not measured (:attr:`PositionVariables.boresight_only`) ``dpsi`` is ``-dR[2, 0]``, the
        entry (0, 2) of ``dR`` without its twist about x."""
        params = self._check(params)
        dR = self._forward(params, False)[0]
        return self._with_added(self._entries(dR), params)

    def _entries(self, dR: np.ndarray, rows: slice = slice(None)) -> np.ndarray:
        """The measured angles' entries of ``dR`` (entry-major, 3 x 3 x n) as (n, 3)."""
        out = np.stack([dR[i, j] for i, j in ANGLE_ENTRIES], axis=1)
        swing = self._boresight_only(rows)
        if swing is not None:
            out[swing, 0] = -dR[2, 0][swing]
        return out

    def _boresight_only(self, rows: slice = slice(None)) -> np.ndarray | None:
        """The rows (of ``rows``) whose ``dpsi`` is the swing's, or ``None``."""
        mask = self.variables.boresight_only
        return None if mask is None else mask[rows]

    def jacobian(self, params) -> np.ndarray:
        """Exact derivative of :meth:`predict` with respect to the parameters, (N, 3, n)."""
        return self.predict_and_jacobian(params)[1]

    def predict_and_jacobian(
        self, params, rows: slice = slice(None)
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`predict` (N, 3) and :meth:`jacobian` (N, 3, n) from one pass along the chain
        (of the positions ``rows`` only: a block of a long log).

        For a factor ``R_a(angle)`` whose axis is ``u`` in the frame of ``dR``'s rows, the
        derivative of ``dR`` is ``[u]x dR``, whose entry (i, j) is ``(u x dR[:, j])_i``; times
        the factor's gains it goes to the columns of the parameters that turn it. The Jacobian
        is a new array, laid out parameter by parameter (a transposed view).
        """
        params = self._check(params)
        dR, axes = self._forward(params, True, rows)
        n = dR.shape[-1]
        jac = np.zeros((self.n_params, n, 3))
        entries = np.empty((n, 3))
        factors = [f for f in self._factors if f.fixed is None]
        swing = self._boresight_only(rows)
        for factor, u in zip(factors, axes, strict=True):
            for e, (i, j) in enumerate(ANGLE_ENTRIES):
                i1, i2 = (i + 1) % 3, (i + 2) % 3
                np.subtract(u[i1] * dR[i2, j], u[i2] * dR[i1, j], out=entries[:, e])
            if swing is not None:  # d(-dR[2, 0]) = -(u x dR[:, 0])_2
                entries[swing, 0] = (u[1] * dR[0, 0] - u[0] * dR[1, 0])[swing]
            weights = factor.weights if factor.weights.shape[-1] == 1 else factor.weights[:, rows]
            for column, weight in zip(factor.columns, weights, strict=True):
                if weight.size == 1 and weight[0] == 1.0:
                    jac[column] += entries
                else:
                    jac[column] += entries * weight[:, None]
        for a, gain in self._added:  # terms added to a measured angle itself: linear
            for column, weight in gain.items():
                w = np.asarray(weight, dtype=float)
                jac[column][:, a] += w if w.ndim == 0 else w[rows]
        return self._with_added(self._entries(dR, rows), params, rows), jac.transpose(1, 2, 0)

    def _with_added(self, predicted: np.ndarray, params, rows: slice = slice(None)) -> np.ndarray:
        """``predicted`` (N, 3) plus the terms added to a measured angle itself."""
        for a, gain in self._added:
            for column, weight in gain.items():
                w = np.asarray(weight, dtype=float)
                predicted[:, a] += (w if w.ndim == 0 else w[rows]) * params[column]
        return predicted

    def parameter_vector(self, values: dict[str, float] | None = None) -> np.ndarray:
        """A parameter vector (internal units) from ``{name: value in internal units}``."""
        p = np.zeros(self.n_params)
        for name, value in (values or {}).items():
            if name not in self._index:
                raise InputError(f"unknown parameter '{name}'; parameters: {self.parameter_names}")
            p[self._index[name]] = value
        return p
