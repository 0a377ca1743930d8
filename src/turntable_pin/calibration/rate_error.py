"""The effect of an orientation error on a multi-position calibration (paper eqs. 7-14).

At the ideal orientation the GyroWheel senses ``a`` and ``w`` (eq. 3). An orientation error ``dR``
turns them into ``a' = a dR`` and ``w' = w dR`` as row vectors (eq. 8), so the outputs really
produced at the test positions are ``b1 = b2' + A' beta`` with the true coefficients ``beta``.
From these outputs:

- ``beta1 = A^+ (b1 - b2)`` (eq. 6): the calibration that believes the orientation is ideal;
- ``beta2 = A'^+ (b1 - b2')`` (eq. 11): the calibration with the true inputs (it returns ``beta``);
- ``dw = b1 - A beta2 - b2'`` (eq. 13, as printed in the paper) and
  ``dwx = ||dw||_inf`` (eq. 14); likewise ``dwy``.

Eq. 13 as printed equals ``(A' - A) beta``: the drift predicted from the ideal inputs misses the
drift at the actual inputs. A second reading is offered as ``definition="calibrated_coefficients"``:
``dw = b1 - A beta1 - b2'``, the rate error of an instrument compensated with the coefficients the
flawed calibration actually produced (it includes the earth-rate error and is blind to whatever
``beta1`` absorbs). The default is the printed eq. 13.

``dR`` is the first-order matrix of eq. 7 by default, or the exact rotation ``exp([r]x)`` with
rotation vector ``r = (dgamma, dpsi, dtheta)`` (about x, y, z), whose first-order part is eq. 7.
A field of per-position rotations (e.g. ``OrientationErrorField.rotation``) may be passed instead.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.exceptions import IdentifiabilityError, InputError
from ..core.units import DEG_PER_RAD, rad_to_arcsec
from ..model.errors import MAX_ANGULAR_ERROR_DEG
from ..model.small_angle import small_angle_rotation
from .drift_fit import require_identifiable
from .gyrowheel import AXES, N_COEFFICIENTS, GyroWheelModel, regressor_matrix
from .positions import PositionInputs

__all__ = [
    "DEFINITIONS",
    "RateErrorResult",
    "orientation_error_rotation",
    "rate_error",
    "rate_error_vectors_dph",
    "rate_errors_at_angles_dph",
    "rate_errors_dph",
]

DEFINITIONS: tuple[str, ...] = ("true_coefficients", "calibrated_coefficients")
"""``true_coefficients``: eq. 13 as printed (beta2). ``calibrated_coefficients``: with beta1."""


def orientation_error_rotation(dpsi_rad, dtheta_rad, dgamma_rad, *, exact: bool = False):
    """``dR`` of the three orientation-error angles, shape S + (3, 3) for angles of shape S.

    ``exact=False``: the first-order matrix of eq. 7 (``I + [r]x``, not exactly orthogonal).
    ``exact=True``: the rotation ``exp([r]x)`` (Rodrigues), ``r = (dgamma, dpsi, dtheta)``.
    """
    psi, theta, gamma = np.broadcast_arrays(
        *(np.asarray(v, dtype=float) for v in (dpsi_rad, dtheta_rad, dgamma_rad))
    )
    if psi.ndim == 0:
        if not exact:
            return small_angle_rotation(float(psi), float(theta), float(gamma))
    zero = np.zeros_like(psi)
    skew = np.stack(
        [
            np.stack([zero, -theta, psi], -1),
            np.stack([theta, zero, -gamma], -1),
            np.stack([-psi, gamma, zero], -1),
        ],
        -2,
    )
    eye = np.broadcast_to(np.eye(3), skew.shape)
    if not exact:
        return eye + skew
    angle = np.sqrt(psi**2 + theta**2 + gamma**2)[..., None, None]
    small = angle < 1e-8
    safe = np.where(small, 1.0, angle)
    # Series of sin(t)/t and (1 - cos t)/t^2 near zero keep full precision for tiny errors.
    c1 = np.where(small, 1.0 - angle**2 / 6.0, np.sin(safe) / safe)
    c2 = np.where(small, 0.5 - angle**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    return eye + c1 * skew + c2 * (skew @ skew)


def _perturbed(vectors: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Row vectors times dR: (N,3) with (K,3,3) or (K,N,3,3) -> (K,N,3)."""
    if rotations.ndim == 3:
        return np.matmul(vectors[None], rotations)
    return np.matmul(vectors[None, :, None, :], rotations)[:, :, 0, :]


def _pinv_checked(matrix: np.ndarray, axis: str) -> np.ndarray:
    rank = int(np.linalg.matrix_rank(matrix))
    if rank < N_COEFFICIENTS:
        raise IdentifiabilityError(
            f"axis {axis}: the test positions give a regressor matrix A of rank {rank} < 7, so "
            "eq. 6 cannot determine all seven drift coefficients; use more varied positions "
            "(e.g. grid:30 or grid:45; a 90-degree grid never makes ax*ay nonzero)"
        )
    return np.linalg.pinv(matrix)


def _true_coefficient_fit(
    design: np.ndarray, beta: np.ndarray, nominal_design: np.ndarray, perturbation: np.ndarray
) -> np.ndarray:
    """``beta2 = A'^+ (b1 - b2') = A'^+ A' beta`` (eq. 11) for K perturbed matrices (K,N,7).

    Where ``A'`` has full column rank, ``A'^+ A' = I`` and eq. 11 returns ``beta`` exactly. That
    is certain when ``perturbation``, an upper bound of ``||A' - A||_F`` per system, is below half
    the smallest singular value of the nominal ``A`` (Weyl); this shortcut is the inner loop of
    the requirement search. Elsewhere (e.g. a 90-degree grid, whose ``ax ay`` column is only as
    large as the orientation error) eq. 11 is solved: normal equations with unit-norm columns
    where their condition number is below 1e8, the pseudo-inverse otherwise.
    """
    k = design.shape[0]
    solution = np.broadcast_to(beta, (k, beta.size)).copy()
    sigma_min = np.linalg.svd(nominal_design, compute_uv=False)[-1]
    todo = perturbation >= 0.5 * sigma_min
    if not np.any(todo):
        return solution
    sub = design[todo]
    rhs = sub @ beta
    sub_t = sub.transpose(0, 2, 1)
    gram = sub_t @ sub
    projected = (sub_t @ rhs[..., None])[..., 0]
    norms = np.sqrt(np.einsum("kii->ki", gram))
    good = np.all(norms > 1e-150, axis=1)
    scale = 1.0 / np.where(norms > 1e-150, norms, 1.0)
    scaled = gram * scale[:, :, None] * scale[:, None, :]
    good[good] = np.linalg.cond(scaled[good]) < 1e8
    fitted = np.empty(projected.shape)
    if np.any(good):
        fitted[good] = (
            np.linalg.solve(scaled[good], (projected[good] * scale[good])[..., None])[..., 0]
            * scale[good]
        )
    if not np.all(good):
        bad = ~good
        fitted[bad] = np.einsum("kpn,kn->kp", np.linalg.pinv(sub[bad]), rhs[bad])
    solution[todo] = fitted
    return solution


def rate_errors_dph(
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    rotations: np.ndarray,
    *,
    definition: str = "true_coefficients",
) -> np.ndarray:
    """Rate-sensing errors for K orientation errors at once (vectorised eqs. 8-14).

    Same arguments as :func:`rate_error_vectors_dph`. Returns the (K, 2) array ``[dwx, dwy]`` in
    deg/h: the infinity norms over the positions of the per-position vectors.
    """
    dw = rate_error_vectors_dph(gyrowheel, inputs, rotations, definition=definition)
    return np.max(np.abs(dw), axis=-2)


def rate_errors_at_angles_dph(
    gyrowheel, inputs, angles_rad, *, exact=False, definition=DEFINITIONS[0]
):
    """:func:`rate_errors_dph` (the (M, 2) array ``[dwx, dwy]``, deg/h) at (M, 3) orientation
    errors ``(dpsi, dtheta, dgamma)``, radians, 4096 at a time (bounded memory)."""
    angles = np.asarray(angles_rad, dtype=float).reshape(-1, 3)
    out = np.empty((angles.shape[0], 2))
    for start in range(0, angles.shape[0], 4096):
        rotations = orientation_error_rotation(*angles[start : start + 4096].T, exact=exact)
        out[start : start + 4096] = rate_errors_dph(
            gyrowheel, inputs, rotations, definition=definition
        )
    return out


def rate_error_vectors_dph(
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    rotations: np.ndarray,
    *,
    definition: str = "true_coefficients",
) -> np.ndarray:
    """Rate-sensing error vectors for K orientation errors at the N positions (eqs. 8-14).

    Args:
        gyrowheel: the true drift coefficients ``beta``.
        inputs: ideal inputs ``a``, ``w`` at the N test positions.
        rotations: ``dR`` of shape (K, 3, 3) (one per case, the same at every position) or
            (K, N, 3, 3) (per position).
        definition: one of :data:`DEFINITIONS`.

    Returns:
        (K, N, 2) array of ``[dwx, dwy]`` at each position, deg/h.
    """
    if definition not in DEFINITIONS:
        raise InputError(f"unknown rate-error definition '{definition}'; expected {DEFINITIONS}")
    rotations = np.asarray(rotations, dtype=float)
    if rotations.ndim not in (3, 4) or rotations.shape[-2:] != (3, 3):
        raise InputError(f"rotations must have shape (K,3,3) or (K,N,3,3), got {rotations.shape}")
    a, w = inputs.specific_force_g, inputs.earth_rate_dph
    a_act, w_act = _perturbed(a, rotations), _perturbed(w, rotations)
    # Bound of ||A' - A||_F from ||dR - I||_F = d and |a| <= r: |da| <= d r per row, the squares
    # and the product change by at most 2 r^2 d + r^2 d^2 each.
    deviation = np.sqrt(np.sum((rotations - np.eye(3)) ** 2, axis=(-2, -1)))
    if deviation.ndim == 2:
        deviation = deviation.max(axis=1)
    radius = float(np.max(np.linalg.norm(a, axis=1)))
    change = deviation * radius
    perturbation = np.sqrt(len(a) * (change**2 + 3 * (2 * radius * change + change**2) ** 2))
    errors = []
    for index, axis in enumerate(AXES):
        beta = gyrowheel.axis(axis).as_array()
        design = regressor_matrix(axis, a)
        design_act = regressor_matrix(axis, a_act)
        b2_act = w_act[..., index]
        b1 = b2_act + design_act @ beta
        if definition == "true_coefficients":
            beta2 = _true_coefficient_fit(design_act, beta, design, perturbation)
            dw = b1 - beta2 @ design.T - b2_act
        else:
            beta1 = (b1 - w[:, index]) @ _pinv_checked(design, axis).T
            dw = b1 - beta1 @ design.T - b2_act
        errors.append(dw)
    return np.stack(errors, axis=-1)


@dataclass(frozen=True)
class RateErrorResult:
    """Rate-sensing errors of one orientation error (eqs. 7-14), with what produced them.

    Attributes:
        dpsi_rad, dtheta_rad, dgamma_rad: the orientation error, radians.
        exact: whether ``dR`` was the exact rotation (else eq. 7).
        definition: see :data:`DEFINITIONS`.
        latitude_rad, positions_name, n_positions: the test set-up.
        dwx_dph, dwy_dph: eq. 14 infinity norms, deg/h.
        dw_dph: (N, 2) per-position errors of the x and y axes, deg/h.
        beta1, beta2: ``{axis: (7,) or None}`` coefficients of eq. 6 (None when the positions do
            not determine them) and eq. 11.
        condition_numbers: ``{axis: cond(A)}`` of the ideal regressor matrices.
    """

    dpsi_rad: float
    dtheta_rad: float
    dgamma_rad: float
    exact: bool
    definition: str
    latitude_rad: float
    positions_name: str
    n_positions: int
    dwx_dph: float
    dwy_dph: float
    dw_dph: np.ndarray
    beta1: dict
    beta2: dict
    condition_numbers: dict

    def to_dict(self) -> dict:
        """The result as a JSON-ready dict (errors in deg/h, angles in arcsec and degrees)."""
        return {
            "dwx_dph": self.dwx_dph,
            "dwy_dph": self.dwy_dph,
            "dpsi_arcsec": rad_to_arcsec(self.dpsi_rad),
            "dtheta_arcsec": rad_to_arcsec(self.dtheta_rad),
            "dgamma_arcsec": rad_to_arcsec(self.dgamma_rad),
            "exact_rotation": self.exact,
            "definition": self.definition,
            "latitude_deg": float(np.degrees(self.latitude_rad)),
            "positions": self.positions_name,
            "n_positions": self.n_positions,
            "beta1": {k: None if v is None else list(v) for k, v in self.beta1.items()},
            "beta2": {k: list(v) for k, v in self.beta2.items()},
            "condition_number": self.condition_numbers,
        }


def rate_error(
    gyrowheel: GyroWheelModel,
    inputs: PositionInputs,
    dpsi_rad: float,
    dtheta_rad: float,
    dgamma_rad: float,
    *,
    exact: bool = False,
    definition: str = "true_coefficients",
) -> RateErrorResult:
    """Eqs. 7-14 for one orientation error, with beta1 and beta2 reported.

    Each angle must be finite and at most ``MAX_ANGULAR_ERROR_DEG`` (5 deg) in magnitude: the
    model is one of small orientation errors. The positions must turn gravity through all three
    payload axes (else :class:`IdentifiabilityError`, see
    :func:`~turntable_pin.calibration.drift_fit.require_identifiable`).
    """
    for name, value in (("dpsi", dpsi_rad), ("dtheta", dtheta_rad), ("dgamma", dgamma_rad)):
        if not np.isfinite(value):
            raise InputError(f"{name} must be a finite number, got {value!r}")
        if abs(value) > MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:
            raise InputError(
                f"{name} = {value:g} rad is not a small orientation error: it must be within "
                f"+-{MAX_ANGULAR_ERROR_DEG:g} deg ({MAX_ANGULAR_ERROR_DEG / DEG_PER_RAD:.6g} rad)"
            )
    require_identifiable(inputs, every_coefficient=False)
    rotation = orientation_error_rotation(dpsi_rad, dtheta_rad, dgamma_rad, exact=exact)
    dw = rate_error_vectors_dph(gyrowheel, inputs, rotation[None], definition=definition)
    norms = np.max(np.abs(dw), axis=-2)
    a, w = inputs.specific_force_g, inputs.earth_rate_dph
    a_act, w_act = a @ rotation, w @ rotation
    beta1, beta2, conds = {}, {}, {}
    for index, axis in enumerate(AXES):
        beta = gyrowheel.axis(axis).as_array()
        design, design_act = regressor_matrix(axis, a), regressor_matrix(axis, a_act)
        b1 = w_act[:, index] + design_act @ beta
        beta2[axis] = np.linalg.lstsq(design_act, b1 - w_act[:, index], rcond=None)[0]
        conds[axis] = float(np.linalg.cond(design))
        if np.linalg.matrix_rank(design) < N_COEFFICIENTS:
            beta1[axis] = None
        else:
            beta1[axis] = np.linalg.lstsq(design, b1 - w[:, index], rcond=None)[0]
    return RateErrorResult(
        dpsi_rad=float(dpsi_rad),
        dtheta_rad=float(dtheta_rad),
        dgamma_rad=float(dgamma_rad),
        exact=exact,
        definition=definition,
        latitude_rad=inputs.latitude_rad,
        positions_name=inputs.positions.name,
        n_positions=len(inputs),
        dwx_dph=float(norms[0, 0]),
        dwy_dph=float(norms[0, 1]),
        dw_dph=dw[0],
        beta1=beta1,
        beta2=beta2,
        condition_numbers=conds,
    )
