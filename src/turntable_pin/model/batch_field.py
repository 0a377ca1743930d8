"""Fast orientation error over many angle pairs and many error sets, from the model's placements.

Every entry of ``dR(phi1, phi2) = Rd^T Rt`` is a trigonometric polynomial of degree two in each
angle: ``phi1`` enters only through the outer joint's rotation in ``Rt`` and in ``Rd^T`` (twice),
``phi2`` likewise through the inner joint. So, exactly,

    dR_ij(phi1, phi2) = u(phi1)^T C_ij u(phi2),   u(a) = [1, cos a, sin a, cos 2a, sin 2a],

with a 5x5 coefficient matrix ``C_ij`` per entry. The coefficients are obtained by composing the
placement chain (the Pinocchio model's own placements, :meth:`TurntableModel.placement_chain`, or
the :class:`~turntable_pin.model.chain.ErrorChain` with many error sets) on a 5x5 grid of equally
spaced angles and inverting the (orthogonal) trigonometric basis there. Evaluating ``dR`` at N
angle pairs then costs two small matrix products, which is what makes allocation, Monte Carlo
and fitting fast.
"""

from __future__ import annotations

import numpy as np

from .angles import ANGLE_ENTRIES
from .chain import compose_rotation
from .errors import ERROR_NAMES
from .turntable import TurntableModel

__all__ = ["N_BASIS", "OrientationErrorField", "trig_basis"]

N_BASIS = 5
_GRID_RAD = 2.0 * np.pi * np.arange(N_BASIS) / N_BASIS


_CHUNK = 8192  # angle pairs per block: keeps the intermediates in cache


def _basis_rows(angle_rad: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Fill ``out`` (5, ...) with ``1, cos a, sin a, cos 2a, sin 2a``.

    cos and sin come from one ``tan(a/2)`` through the rational half-angle formulas (a few ulp
    of error): one transcendental call instead of two, which is most of the cost of a batch.
    """
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


_BASIS_INV = np.linalg.inv(trig_basis(_GRID_RAD))  # rows: grid points, cols: basis functions


def _coefficients(actual_chain, ideal_chain) -> np.ndarray:
    """Coefficients C (K, 3, 3, 5, ..., 5) of dR (one 5 per joint) for chains whose placements
    have a leading dim K."""
    n_joints = sum(axis is not None for _, axis in actual_chain)
    grid = np.meshgrid(*([_GRID_RAD] * n_joints), indexing="ij")  # (5, ..., 5)
    # Placements (K, 4, 4) broadcast against the grid of joint values.
    lead = (slice(None),) + (None,) * n_joints
    rt = compose_rotation([(p[lead], a) for p, a in actual_chain], grid)
    rd = compose_rotation([(p[lead], a) for p, a in ideal_chain], grid)
    dR = np.swapaxes(rd, -1, -2) @ rt  # (K, 5, ..., 5, 3, 3)
    # dR[k, a, b] = sum_mn B[a, m] C[m, n] B[b, n]  ->  C = Binv dR Binv^T on the grid axes
    # (two joints: "ma,kabij,nb->kijmn"; likewise one Binv per grid axis).
    grid_in, grid_out = "abc"[:n_joints], "mno"[:n_joints]
    inputs = [f"{grid_out[0]}{grid_in[0]}", f"k{grid_in}ij"]
    inputs += [f"{o}{i}" for o, i in zip(grid_out[1:], grid_in[1:], strict=True)]
    operands = [_BASIS_INV, dR] + [_BASIS_INV] * (n_joints - 1)
    return np.einsum(f"{','.join(inputs)}->kij{grid_out}", *operands)


class OrientationErrorField:
    """``dR`` of one or many turntables as a function of (phi1, phi2), evaluated in batches.

    Build it with :meth:`from_model` (one Pinocchio model) or :meth:`from_error_values` (many
    error sets on the same URDF). ``coefficients`` has shape (K, 3, 3, 5, 5).
    """

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
    def from_model(cls, model: TurntableModel) -> OrientationErrorField:
        """The field of one :class:`TurntableModel`, read off its Pinocchio placements."""
        actual = [(p[None], a) for p, a in model.placement_chain(model.pin_model)]
        ideal = [(p[None], a) for p, a in model.placement_chain(model.nominal_pin_model)]
        return cls(_coefficients(actual, ideal))

    @classmethod
    def from_error_values(
        cls, error_values: np.ndarray, model: TurntableModel | None = None
    ) -> OrientationErrorField:
        """The fields of K error sets, ``error_values`` of shape (K, 9) (rad, deta in m).

        The placements are the model's :class:`ErrorChain` with each error set applied
        (:meth:`ErrorChain.placements`), the same construction :class:`TurntableModel` writes
        into Pinocchio.
        """
        model = model or TurntableModel()
        values = np.atleast_2d(np.asarray(error_values, dtype=float))
        if values.shape[-1] == len(ERROR_NAMES) - 1:
            values = np.concatenate([values, np.zeros((values.shape[0], 1))], axis=1)
        return cls.from_chain(model.chain, values)

    @classmethod
    def from_chain(cls, chain, error_values: np.ndarray) -> OrientationErrorField:
        """The fields of K error sets on any :class:`ErrorChain` (1 to 3 joints).

        ``error_values`` has shape (K, E) in ``chain.error_names`` order (rad, m).
        """
        values = np.atleast_2d(np.asarray(error_values, dtype=float))
        actual = chain.placements(values)
        ideal = [(p[None], a) for p, a in chain.placements()]
        return cls(_coefficients(actual, ideal), n_joints=len(chain.joints))

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
        """Full ``dR`` at N joint-angle tuples (chain order; broadcast, flattened): (K, N, 3, 3).

        For the paper's table ``rotation(phi1_rad, phi2_rad)``.
        """
        k = self.n_sets
        values = self._evaluate(
            self.coefficients.reshape((k, 9) + (N_BASIS,) * self.n_joints), angles_rad
        )
        return values.transpose(0, 2, 1).reshape(k, -1, 3, 3)

    def angles(self, *angles_rad) -> np.ndarray:
        """``(dpsi, dtheta, dgamma)`` in radians at N joint-angle tuples, shape (K, N, 3).

        For two joints one (3K, 25) x (25, P) product per block of P pairs (5^K rows for K
        joints); see the module docstring.
        """
        return self._evaluate(self._angle_coefficients, angles_rad).transpose(0, 2, 1)

    def angles_on_phi2_grid(self, phi1_rad: float, phi2_grid_rad) -> np.ndarray:
        """``(dpsi, dtheta, dgamma)`` of every error set on a grid of phi2 at one phi1.

        Returns shape (K, 3, M) for M grid values: one (K*3, 5) x (5, M) product, the fast path
        of Monte Carlo runs over many turntables.
        """
        u1 = trig_basis(float(phi1_rad))
        u2 = trig_basis(np.asarray(phi2_grid_rad, dtype=float).ravel())
        per_phi2 = np.einsum("m,kemn->ken", u1, self._angle_coefficients)  # (K, 3, 5)
        return per_phi2 @ u2.T
