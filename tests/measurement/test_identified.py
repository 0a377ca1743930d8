"""The identified table written back: plain Pinocchio on the written URDF reproduces the fitted
dR at every measured position, on the paper's table and on every bundled table."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from conftest import REPO_DIR
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.fit import fit_orientation
from turntable_pin.measurement.identified import SPLIT_RULE, write_identified_urdf
from turntable_pin.measurement.simulation import Schedule, simulate_measurements
from turntable_pin.model.generic_table import GenericTable
from turntable_pin.model.paper_table import paper_table

MODELS = REPO_DIR / "models"


def _payload_rotations(urdf, frame: str, q_rad: np.ndarray) -> np.ndarray:
    """Payload orientation in the base at each row of joint angles, by plain Pinocchio."""
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    fid = model.getFrameId(frame)
    out = []
    for q in q_rad:
        config = pin.neutral(model)
        k = 0
        for j in range(1, model.njoints):
            if model.joints[j].nq == 2:  # continuous joint: (cos, sin)
                config[model.idx_qs[j] : model.idx_qs[j] + 2] = np.cos(q[k]), np.sin(q[k])
            else:
                config[model.idx_qs[j]] = q[k]
            k += 1
        pin.framesForwardKinematics(model, data, config)
        out.append(np.array(data.oMf[fid].rotation))
    return np.array(out)


@pytest.mark.parametrize(
    "urdf, frame",
    [("turntable.urdf", "gyrowheel"), ("two_axis_vertical_outer.urdf", "imu"),
     ("three_axis_imu_table.urdf", "imu"), ("single_axis_rate_table.urdf", "gyro")],
)  # fmt: skip
def test_plain_pinocchio_on_the_written_urdf_reproduces_the_fit(tmp_path, urdf, frame):
    path = MODELS / urdf
    paper = urdf == "turntable.urdf"
    table = paper_table(path) if paper else GenericTable(path)
    rng = np.random.default_rng(3)
    if not paper:
        errors = rng.normal(0, 20, len(table.parameter_names)) / ARCSEC_PER_RAD
        schedule = Schedule(45, 45, 90)
    else:
        errors, schedule = None, Schedule()
    sim = simulate_measurements(errors, schedule=schedule, seed=4, turntable=table)
    fit = fit_orientation(sim.data, turntable=table)
    out = write_identified_urdf(fit, tmp_path / "identified.urdf")
    assert (
        out["rule"] == SPLIT_RULE and out["undetermined"] == fit.result.undetermined_combinations()
    )
    q = sim.data.joint_rad
    rt = _payload_rotations(out["path"], frame, q)
    rd = _payload_rotations(path, frame, q)
    dr = np.swapaxes(rd, -1, -2) @ rt
    written = np.stack([dr[:, 0, 2], dr[:, 1, 0], dr[:, 2, 1]], axis=1)
    np.testing.assert_allclose(written, fit.fitted_rad(), atol=1e-12)
    assert path.read_text() != (tmp_path / "identified.urdf").read_text()
