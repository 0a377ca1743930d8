# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # The user's loop on a bundled table
#
# Load the paper's two-axis turntable, look at it, simulate a measurement run with an effect the
# base error model does not have, fit, see where the fit fails, let the diagnosis name the
# missing effect, add it and watch the error fall; then choose the positions of the next run.
#
# Everything is `import turntable_pin as tp`: no deep import. Whatever the notebook writes goes
# into a temporary folder, removed at the end.

# %%
import shutil
import tempfile
from pathlib import Path

import turntable_pin as tp

out = Path(tempfile.mkdtemp(prefix="turntable-pin-notebook-"))

# %% [markdown]
# ## 1. The table
#
# A bundled table by name (or any URDF path). Its errors are the joint placements' small
# rotations (and offsets); the Pinocchio model and data are one attribute away.

# %%
table = tp.load_table("turntable")
print(table.title, table.joint_names)
print(table.parameter_names)
model, data = table.nominal_pin_model, table.nominal_pin_data
print(f"Pinocchio: {model.njoints - 1} joints, nq {model.nq}, nv {model.nv}")
assert table.joint_names == ("outer_axis", "inner_axis")

# %% [markdown]
# ## 2. Look at it
#
# A snapshot of the table at phi1 = 30 deg, phi2 = 45 deg, with the errors simulated below
# magnified (meshcat rendered in headless Chromium): the ideal and the actual payload frames.
# Without Chromium or meshcat the snapshot is skipped, with the reason.

# %%
import numpy as np
from IPython.display import Image, display

errors_arcsec = {"dphi_y1": 20, "dalpha_x1": 15}
scene = tp.SetupScene(table.errors_from_user_units(errors_arcsec), table=table)
try:
    angles_rad = np.radians([30, 45])
    snapshot = tp.render_snapshot(scene, angles_rad, out / "setup.png", width=480, height=360)
    display(Image(filename=str(snapshot.path)))
except tp.TurntablePinError as exc:
    print(f"no snapshot: {exc}")

# %% [markdown]
# ## 3. Measurements
#
# A simulated run on the 30-degree grid (144 positions, 1 arcsec noise): an outer-axis position
# error of 20 arcsec and, hidden from the base model, a once-per-revolution error of the inner
# encoder. `tp.read_measurements("your.csv", table=table)` reads a measured run the same way.

# %%
sim = tp.simulate(
    table,
    errors=errors_arcsec,
    effects={"inner_encoder_harmonics": {"c1": 4, "s1": -3}},
    seed=7,
)
assert sim.data.n_positions == 144
sim

# %% [markdown]
# ## 4. Fit the base model and see where it fails

# %%
before = tp.fit(sim, table=table)
print(
    f"base fit: rms {before.result.rms_user:.2f} arcsec, chi2_reduced "
    f"{before.result.chi2_reduced:.2f}"
)
assert before.result.chi2_reduced > 3  # the base model does not explain the data
before

# %%
figures = before.plot()  # residuals against each angle, their harmonics, their map
figures[0]

# %% [markdown]
# ## 5. Diagnose: which effect is missing?

# %%
diagnosis = tp.diagnose(sim, table=table)
print(diagnosis.to_dict()["verdict"]["missing_effect"])
assert diagnosis.missing_effect == "inner_encoder_harmonics"
diagnosis

# %% [markdown]
# ## 6. Add the named effect: the error falls

# %%
after = tp.fit(sim, diagnosis.missing_effect, table=table)
print(
    f"rms {before.result.rms_user:.2f} -> {after.result.rms_user:.2f} arcsec, chi2_reduced "
    f"{before.result.chi2_reduced:.2f} -> {after.result.chi2_reduced:.2f}"
)
assert after.result.rms_user < 0.6 * before.result.rms_user
assert 0.7 < after.result.chi2_reduced < 1.3  # down to the noise
after

# %% [markdown]
# ## 7. The next run: positions that identify the model with the effect
#
# Twelve D-optimal positions for the base errors plus the effect, added to the run already
# made; the CSV is what `turntable-pin simulate --positions` and the test crew read.

# %%
plan = tp.design(table, 12, effects=diagnosis.missing_effect, from_data=sim, candidates=2000)
written = plan.plan.write_csv(out / "next_positions.csv")
print(written.read_text().splitlines()[-1])
assert plan.n_positions == 12
plan

# %%
shutil.rmtree(out)
