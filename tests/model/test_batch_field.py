"""The batch path equals per-call Pinocchio forward kinematics to 1e-12 rad."""

import numpy as np
import pytest

from conftest import random_errors
from turntable_pin import OrientationErrorField, TurntableModel
from turntable_pin.model.batch_field import trig_basis


def test_batch_equals_per_call_pinocchio(rng):
    for scale in (10.0, 3000.0):
        model = TurntableModel(random_errors(rng, scale_arcsec=scale))
        field = OrientationErrorField.from_model(model)
        phi1, phi2 = rng.uniform(-20, 20, size=(2, 500))
        per_call = np.array(
            [model.orientation_error(a, b).dR for a, b in zip(phi1, phi2, strict=True)]
        )
        np.testing.assert_allclose(field.rotation(phi1, phi2)[0], per_call, atol=1e-12, rtol=0)
        angles = field.angles(phi1, phi2)[0]
        np.testing.assert_allclose(angles, per_call[:, [0, 1, 2], [2, 0, 1]], atol=1e-12, rtol=0)


def test_many_error_sets_equal_their_own_models(rng):
    sets = [random_errors(rng, scale_arcsec=100.0) for _ in range(6)]
    values = np.array([e.as_array() for e in sets])
    field = OrientationErrorField.from_error_values(values)
    phi1, phi2 = rng.uniform(-7, 7, size=(2, 40))
    angles = field.angles(phi1, phi2)
    grid = np.linspace(0, 2 * np.pi, 17)
    on_grid = field.angles_on_phi2_grid(0.7, grid)
    for k, errors in enumerate(sets):
        model = TurntableModel(errors)
        np.testing.assert_allclose(
            field.coefficients[k],
            OrientationErrorField.from_model(model).coefficients[0],
            atol=1e-15,
        )
        for n in range(phi1.size):
            r = model.orientation_error(phi1[n], phi2[n])
            np.testing.assert_allclose(
                angles[k, n], [r.dpsi_rad, r.dtheta_rad, r.dgamma_rad], atol=1e-12, rtol=0
            )
        r = model.orientation_error(0.7, grid[5])
        np.testing.assert_allclose(
            on_grid[k, :, 5], [r.dpsi_rad, r.dtheta_rad, r.dgamma_rad], atol=1e-12
        )


def test_trig_basis_matches_numpy(rng):
    a = np.concatenate([rng.uniform(-100, 100, 1000), [0.0, np.pi, -np.pi, np.pi / 2, 2 * np.pi]])
    u = trig_basis(a)
    expected = np.stack([np.ones_like(a), np.cos(a), np.sin(a), np.cos(2 * a), np.sin(2 * a)], -1)
    np.testing.assert_allclose(u, expected, atol=2e-15, rtol=0)
    assert trig_basis(0.5).shape == (5,)


def test_broadcast_and_shapes(rng):
    field = OrientationErrorField.from_model(TurntableModel(random_errors(rng)))
    out = field.angles(0.3, np.linspace(0, 1, 7))
    assert out.shape == (1, 7, 3)
    with pytest.raises(ValueError):
        field.angles(np.zeros(3), np.zeros(4))
