"""Fast orientation error of many error sets over many joint angles, from the error chain.

Every entry of ``dR(q) = Rd(q)^T Rt(q)`` of a table with J joints is a trigonometric polynomial of
degree two in each joint angle, exactly::

    dR_ij(q) = sum_p C_ij[p] u_p1(q_1) ... u_pJ(q_J),   u(a) = [1, cos a, sin a, cos 2a, sin 2a],

with 5^J coefficients per entry that depend on the error set only. They are derived here without
evaluating the chain at any angle. A joint's rotation is linear in ``v(q) = [1, cos q, sin q]``
(Rodrigues: ``R(q) = a a^T + cos q (I - a a^T) + sin q [a]x`` about the unit axis ``a``), so the
actual chain ``Rt = A_0 R_1(q_1) A_1 ... R_J(q_J) A_J`` of the :class:`~.chain.ErrorChain` (``A_j``:
the nominal placements and error factors between two joints, a 3x3 rotation per error set) is
linear in ``v(q_1) x ... x v(q_J)`` with coefficient matrices ``T[m]``, built by a few batched
3x3 products per error set. ``Rd`` is the same with no errors (coefficients ``D[n]``, one for all
sets), and the products ``v_n v_m`` of two such bases are fixed combinations of ``u``
(``cos^2 = (1 + cos 2a)/2``, ``cos sin = sin 2a / 2``...). Hence one matrix product per batch::

    C (sets x 5^J per entry) = T (sets x 3^J*9) @ L (3^J*9 x 5^J per entry),

``L`` made once from the nominal chain (:class:`ChainExpansion`). Evaluating ``dR`` at N angle
tuples is then a (sets x 5^J) @ (5^J x N) product; on a full grid over every joint it is done one
joint at a time (:func:`max_abs_on_grid`), which is what makes the Monte Carlo check fast.
"""

from __future__ import annotations

import numpy as np

from .angles import ANGLE_ENTRIES
from .chain import ROTATION, skew

__all__ = [
    "N_BASIS",
    "ChainExpansion",
    "OrientationErrorField",
    "joint_dependence",
    "max_abs_on_grid",
    "trig_basis",
]

N_BASIS = 5
"""Trigonometric basis functions per joint: ``1, cos a, sin a, cos 2a, sin 2a``."""

_ALL_ENTRIES = tuple((i, j) for i in range(3) for j in range(3))
_CHUNK = 8192  # angle tuples per block of a scattered evaluation: the intermediates stay in cache
_GRID_BLOCK_BYTES = 1 << 19
"""Output block of a grid evaluation, bytes: about the L2 cache, where the largest-value
reduction that follows reads it back fastest (measured: 4.7 s for 10^5 three-axis tables on a
24^3 grid with 2.6 MB blocks, 8.7 s with 7 MB blocks)."""

# v_n(a) v_m(a) = sum_p _PRODUCT_TO_SUM[n, m, p] u_p(a) for v = [1, cos, sin], u = trig_basis.
_PRODUCT_TO_SUM = np.zeros((3, 3, N_BASIS))
_PRODUCT_TO_SUM[0, 0, 0] = 1.0
_PRODUCT_TO_SUM[0, 1, 1] = _PRODUCT_TO_SUM[1, 0, 1] = 1.0
_PRODUCT_TO_SUM[0, 2, 2] = _PRODUCT_TO_SUM[2, 0, 2] = 1.0
_PRODUCT_TO_SUM[1, 1, [0, 3]] = 0.5, 0.5
_PRODUCT_TO_SUM[2, 2, [0, 3]] = 0.5, -0.5
_PRODUCT_TO_SUM[1, 2, 4] = _PRODUCT_TO_SUM[2, 1, 4] = 0.5


def _basis_rows(angle_rad: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Fill ``out`` (5, ...) with ``1, cos a, sin a, cos 2a, sin 2a``; cos and sin from one
    ``tan(a/2)`` (half-angle formulas, a few ulp): one transcendental call, not two."""
    t = np.tan(0.5 * angle_rad)
    t2 = t * t
    inv = 1.0 / (1.0 + t2)
    c = np.multiply(1.0 - t2, inv, out=out[1])
    s = np.multiply(2.0 * t, inv, out=out[2])
    out[0] = 1.0
    np.subtract(c * c, s * s, out=out[3])
    np.multiply(2.0 * s, c, out=out[4])
    return out


def trig_basis(angle_rad) -> np.ndarray:
    """``[1, cos a, sin a, cos 2a, sin 2a]`` stacked on a new last axis."""
    a = np.asarray(angle_rad, dtype=float)
    flat = a.reshape(-1)
    rows = _basis_rows(flat, np.empty((N_BASIS, flat.size)))
    return rows.T.reshape(a.shape + (N_BASIS,))


def _outer_basis_blocks(*angles_rad: np.ndarray):
    """Yield ``(slice, B)`` per block: ``B[5*m + n, p] = u_m(phi1[p]) u_n(phi2[p])`` for two
    joints, the Kronecker product of the K bases (5^K rows) in general."""
    buffers = [np.empty((N_BASIS, _CHUNK)) for _ in angles_rad]
    for start in range(0, angles_rad[0].size, _CHUNK):
        block = slice(start, min(start + _CHUNK, angles_rad[0].size))
        size = block.stop - block.start
        pairs = zip(angles_rad, buffers, strict=True)
        rows = [_basis_rows(a[block], u[:, :size]) for a, u in pairs]
        basis = rows[0]
        for b in rows[1:]:
            basis = (basis[:, None, :] * b[None, :, :]).reshape(-1, size)
        yield block, basis


def _rodrigues_terms(axis) -> np.ndarray:
    """(3, 3, 3): the rotation about the unit ``axis`` by ``a`` is ``G[0] + cos a G[1] +
    sin a G[2]``."""
    a = np.asarray(axis, dtype=float).reshape(3)
    a = a / np.linalg.norm(a)
    outer = np.outer(a, a)
    return np.stack([outer, np.eye(3) - outer, skew(a)])


class ChainExpansion:
    """An :class:`~.chain.ErrorChain` (1 to 3 joints) prepared for the batch path: its rotations
    only (translations never change ``dR``) per stretch between joints, the joints' Rodrigues
    terms, and per row of ``dR`` the operator ``L``. Plain arrays: cheap to send to workers."""

    def __init__(self, chain) -> None:
        index = {name: i for i, name in enumerate(chain.error_names)}
        self.n_errors = len(chain.error_names)
        stretches: list[list] = [[]]
        joints = []
        for link in chain.links:
            stretches[-1].append(np.array(link.nominal[:3, :3], dtype=float))
            for factor in link.factors:
                if factor.kind == ROTATION:
                    stretches[-1].append((index[factor.error], _rodrigues_terms(factor.unit)))
            if link.is_joint:
                joints.append(_rodrigues_terms(link.axis))
                stretches.append([])
        self.n_joints = len(joints)
        self._stretches = stretches
        # (3, 9) per joint: [G0 | G1 | G2], so that X @ it gives the three terms side by side.
        self._joint_terms = [np.concatenate(list(g), axis=1) for g in joints]
        product = np.ones((1, 1, 1))  # v_n v_m -> u_p over every joint (Kronecker product)
        for _ in joints:
            product = np.einsum("nmp,xyz->nxmypz", product, _PRODUCT_TO_SUM)
            product = product.reshape([3 * product.shape[0], 3 * product.shape[2], -1])
        nominal = self._chain_terms(None)[0].reshape(3, -1, 3)  # D: (a, n_1..n_J, i)
        # C_ij = T[:, :, j] @ L_i with L_i[(a, m), p] = sum_n D[a, n, i] W[n, m, p], W = product.
        self._operators = [
            np.einsum("an,nmp->amp", nominal[:, :, i], product).reshape(len(product) * 3, -1)
            for i in range(3)
        ]

    # ---- per error set ---------------------------------------------------------------------
    def _stretch_rotation(self, steps, values: np.ndarray | None) -> np.ndarray:
        """The rotation of one stretch: (3, 3), or (K, 3, 3) when it holds error factors."""
        out = np.eye(3)
        for step in steps:
            if isinstance(step, np.ndarray):
                out = out @ step
                continue
            if values is None:  # the nominal chain: no errors
                continue
            column, terms = step
            angle = values[:, column]
            factor = terms[0] + np.cos(angle)[:, None, None] * terms[1]
            factor += np.sin(angle)[:, None, None] * terms[2]
            out = out @ factor
        return out

    def _chain_terms(self, values: np.ndarray | None) -> np.ndarray:
        """``T`` (K, 3 * 3^J, 3): rows (a, m_1..m_J), ``Rt[a, b] = sum_m T[(a, m), b] v_m(q)``."""
        k = 1 if values is None else values.shape[0]
        x = np.broadcast_to(self._stretch_rotation(self._stretches[0], values), (k, 3, 3))
        for terms, steps in zip(self._joint_terms, self._stretches[1:], strict=True):
            rows = x.shape[1]
            x = (x.reshape(-1, 3) @ terms).reshape(k, 3 * rows, 3)
            x = x @ self._stretch_rotation(steps, values)
        return x

    def coefficients(self, error_values, entries=ANGLE_ENTRIES) -> np.ndarray:
        """Coefficients (K, len(entries), 5^J) of the ``dR`` entries ``entries`` (row, column;
        default dpsi, dtheta, dgamma) for ``error_values`` (K, E), the first joint slowest."""
        values = np.atleast_2d(np.asarray(error_values, dtype=float))
        if values.shape[-1] != self.n_errors:
            raise ValueError(f"expected {self.n_errors} error values, got shape {values.shape}")
        terms = self._chain_terms(values)
        return np.stack([terms[:, :, j] @ self._operators[i] for i, j in entries], axis=1)


def joint_dependence(coefficients: np.ndarray, n_joints: int) -> np.ndarray:
    """(J,) per joint, the largest coefficient of a harmonic of that joint's angle in
    ``coefficients`` (K, E, 5^J): 0 when the entries do not depend on the joint at all."""
    c = np.abs(coefficients.reshape(coefficients.shape[:2] + (N_BASIS,) * n_joints))
    return np.array([np.take(c, range(1, N_BASIS), axis=2 + j).max() for j in range(n_joints)])


def max_abs_on_grid(coefficients: np.ndarray, grids_rad) -> np.ndarray:
    """Largest ``|value|`` of each polynomial of ``coefficients`` (K, E, 5^J) over the full grid
    ``grids_rad`` (one array per joint, every combination): (K, E). One joint at a time (a fifth
    of the work of the whole grid's basis, for three joints), in blocks of about
    :data:`_GRID_BLOCK_BYTES`; a joint with one angle is folded into the coefficients first."""
    k, e = coefficients.shape[:2]
    c = coefficients.reshape((k * e,) + (N_BASIS,) * len(grids_rad))
    grids = [np.asarray(g, dtype=float).ravel() for g in grids_rad]
    for axis in reversed(range(len(grids))):
        if grids[axis].size == 1:  # one angle: fold it in
            c = np.tensordot(c, trig_basis(grids[axis][0]), axes=([axis + 1], [0]))
    grids = [g for g in grids if g.size > 1]
    if not grids:
        return np.abs(c).reshape(k, e)
    first = trig_basis(grids[0]).T  # (5, M_1)
    rest = np.ones((1, 1))  # (5^(J-1), M_2...M_J): Kronecker product of the other joints' bases
    for g in grids[1:]:
        rest = np.einsum("pq,rs->prqs", rest, trig_basis(g).T).reshape(rest.shape[0] * N_BASIS, -1)
    c = c.reshape(k, e * N_BASIS, -1)
    n_points = grids[0].size * rest.shape[1]
    block = max(1, _GRID_BLOCK_BYTES // (e * n_points * 8))
    out = np.empty((k, e))
    for start in range(0, k, block):
        stop = min(start + block, k)
        rows = c[start:stop].reshape(-1, N_BASIS, c.shape[2])  # (sets*E, 5 first, 5^(J-1))
        if len(grids) > 1:  # (sets*E*5, 5^(J-1)) @ (5^(J-1), M_rest), first joint last
            rows = (rows.reshape(-1, rest.shape[0]) @ rest).reshape(rows.shape[0], N_BASIS, -1)
        values = (rows.transpose(0, 2, 1).reshape(-1, N_BASIS) @ first).reshape(stop - start, e, -1)
        np.maximum(values.max(axis=2), -values.min(axis=2), out=out[start:stop])
    return out


class OrientationErrorField:
    """``dR`` of K error sets of one table as a function of the joint angles (build it with
    :meth:`from_chain`); ``coefficients`` (K, 3, 3, 5, ..., 5), one 5 per joint."""

    def __init__(self, coefficients: np.ndarray, n_joints: int = 2) -> None:
        coefficients = np.asarray(coefficients, dtype=float)
        if coefficients.ndim == 2 + n_joints:
            coefficients = coefficients[None]
        self.n_joints = int(n_joints)
        self.coefficients = coefficients
        self.coefficients.setflags(write=False)
        # dpsi, dtheta, dgamma coefficient blocks, (K, 3, 5, ..., 5).
        self._angle_coefficients = np.stack(
            [coefficients[:, i, j] for i, j in ANGLE_ENTRIES], axis=1
        )

    @property
    def n_sets(self) -> int:
        """Number of error sets K."""
        return self.coefficients.shape[0]

    @classmethod
    def from_chain(cls, chain, error_values: np.ndarray) -> OrientationErrorField:
        """The fields of ``error_values`` (K, E; ``chain.error_names`` order, rad and m)."""
        expansion = ChainExpansion(chain)
        c = expansion.coefficients(error_values, _ALL_ENTRIES)
        shape = (c.shape[0], 3, 3) + (N_BASIS,) * expansion.n_joints
        return cls(c.reshape(shape), n_joints=expansion.n_joints)

    # ---- evaluation --------------------------------------------------------------------------
    def _evaluate(self, coefficients: np.ndarray, angles_rad) -> np.ndarray:
        """Contract (K, E, 5, ..., 5) coefficients with the basis at N angle tuples: (K, E, N)."""
        if len(angles_rad) != self.n_joints:
            raise ValueError(f"expected {self.n_joints} joint angle arrays, got {len(angles_rad)}")
        angles = np.broadcast_arrays(*(np.asarray(a, dtype=float).ravel() for a in angles_rad))
        k, e = coefficients.shape[:2]
        flat = coefficients.reshape(k * e, N_BASIS**self.n_joints)
        out = np.empty((k * e, angles[0].size))
        for block, basis in _outer_basis_blocks(*angles):
            out[:, block] = flat @ basis
        return out.reshape(k, e, angles[0].size)

    def rotation(self, *angles_rad) -> np.ndarray:
        """Full ``dR`` at N joint-angle tuples (chain order; broadcast, flattened): (K, N, 3, 3)."""
        k = self.n_sets
        values = self._evaluate(
            self.coefficients.reshape((k, 9) + (N_BASIS,) * self.n_joints), angles_rad
        )
        return values.transpose(0, 2, 1).reshape(k, -1, 3, 3)

    def angles(self, *angles_rad) -> np.ndarray:
        """``(dpsi, dtheta, dgamma)`` in radians at N joint-angle tuples, shape (K, N, 3)."""
        return self._evaluate(self._angle_coefficients, angles_rad).transpose(0, 2, 1)
