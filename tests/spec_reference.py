"""An independent reading of spec/model.md and spec/measurements.md: orientation data from scratch.

Nothing here comes from ``turntable_pin``: the elementary rotations, the Table 3 chain (factor by
factor, post-multiplied, as the spec lists them), ``dR = Rd^T Rt`` with ``dpsi = dR[0,2]``,
``dtheta = dR[1,0]``, ``dgamma = dR[2,1]``, every catalogued effect and the CSV writer are written
out again with plain numpy, so that a misreading shared by the project's simulator and its fitter
shows up as a disagreement with this file.

Units here: radians, rad/g (gravity sag), rad/s (thermal drift rates, since ``t = time_s``),
metres are not needed (``deta`` never changes the orientation). The CSV is in the spec's units.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

ARCSEC = np.pi / (180.0 * 3600.0)  # one arc second in radians

ERROR_NAMES = (
    "dphi_y1",
    "dphi_z2",
    "dalpha_x1",
    "dalpha_z1",
    "dalpha_x2",
    "dalpha_y2",
    "deps_x",
    "deps_y",
)

# Parameters of each catalogued effect (the spec's letters; the two series of a wobble effect are
# prefixed by the axis of the angle they add to).
EFFECT_PARAMETERS = {
    "outer_encoder_harmonics": ("c1", "s1", "c2", "s2"),
    "inner_encoder_harmonics": ("c1", "s1", "c2", "s2"),
    "outer_wobble_harmonics": tuple(f"{a}_{c}" for a in "xz" for c in ("c1", "s1", "c2", "s2")),
    "inner_wobble_harmonics": tuple(f"{a}_{c}" for a in "xy" for c in ("c1", "s1", "c2", "s2")),
    "gravity_sag": ("k",),
    "base_tilt": ("tx", "tz"),
    "thermal_drift": ("rz", "ry", "rx"),
    "backlash": ("b1", "b2"),
    "payload_mount": ("mz", "my", "mx"),
}


def Rx(a):
    """Rotation by a (rad, array (N,)) about x, (N, 3, 3)."""
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([o, z, z, z, c, -s, z, s, c], axis=-1).reshape(a.shape + (3, 3))


def Ry(a):
    """Rotation by a (rad) about y, (N, 3, 3)."""
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, z, s, z, o, z, -s, z, c], axis=-1).reshape(a.shape + (3, 3))


def Rz(a):
    """Rotation by a (rad) about z, (N, 3, 3)."""
    a = np.asarray(a, dtype=float)
    c, s, o, z = np.cos(a), np.sin(a), np.ones_like(a), np.zeros_like(a)
    return np.stack([c, -s, z, s, c, z, z, z, o], axis=-1).reshape(a.shape + (3, 3))


def h(angle, c1=0.0, s1=0.0, c2=0.0, s2=0.0):
    """The spec's harmonic series ``c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a``."""
    return c1 * np.cos(angle) + s1 * np.sin(angle) + c2 * np.cos(2 * angle) + s2 * np.sin(2 * angle)


def _series(params, prefix=""):
    return {k: params.get(prefix + k, 0.0) for k in ("c1", "s1", "c2", "s2")}


def reference_rotation_error(
    phi1_rad, phi2_rad, errors=None, effects=None, time_s=None, dir1=None, dir2=None
):
    """``dR = Rd^T Rt`` (N, 3, 3) from the spec, with effects applied as its table says.

    Args:
        phi1_rad, phi2_rad: commanded angles (N,).
        errors: ``{error name: rad}`` (missing names are zero).
        effects: ``{effect name: {parameter: value}}`` in rad, rad/g, rad/s.
        time_s, dir1, dir2: the optional columns (N,), needed by their effects.
    """
    phi1 = np.asarray(phi1_rad, dtype=float)
    phi2 = np.asarray(phi2_rad, dtype=float)
    n = phi1.size
    e = {name: np.full(n, float((errors or {}).get(name, 0.0))) for name in ERROR_NAMES}
    effects = effects or {}
    zero = np.zeros(n)

    p = effects.get("outer_encoder_harmonics")
    if p is not None:
        e["dphi_y1"] = e["dphi_y1"] + h(phi1, **_series(p))
    p = effects.get("inner_encoder_harmonics")
    if p is not None:
        e["dphi_z2"] = e["dphi_z2"] + h(phi2, **_series(p))
    p = effects.get("outer_wobble_harmonics")
    if p is not None:
        e["dalpha_x1"] = e["dalpha_x1"] + h(phi1, **_series(p, "x_"))
        e["dalpha_z1"] = e["dalpha_z1"] + h(phi1, **_series(p, "z_"))
    p = effects.get("inner_wobble_harmonics")
    if p is not None:
        e["dalpha_x2"] = e["dalpha_x2"] + h(phi2, **_series(p, "x_"))
        e["dalpha_y2"] = e["dalpha_y2"] + h(phi2, **_series(p, "y_"))
    p = effects.get("backlash")
    if p is not None:
        if dir1 is not None:
            e["dphi_y1"] = e["dphi_y1"] + p.get("b1", 0.0) * np.asarray(dir1, float) / 2
        if dir2 is not None:
            e["dphi_z2"] = e["dphi_z2"] + p.get("b2", 0.0) * np.asarray(dir2, float) / 2

    # Table 3, each factor post-multiplied in the order listed (Tx(deta) changes no rotation).
    Rt = (
        Ry(phi1)
        @ Ry(e["dphi_y1"])
        @ Rz(e["dalpha_z1"])
        @ Rx(e["dalpha_x1"])
        @ Ry(e["deps_y"])
        @ Rx(e["deps_x"])
        @ Rz(phi2)
        @ Ry(e["dalpha_y2"])
        @ Rz(e["dphi_z2"])
        @ Rx(e["dalpha_x2"])
    )
    p = effects.get("gravity_sag")
    if p is not None:
        ax = -np.sin(phi1) * np.cos(phi2)
        ay = np.sin(phi1) * np.sin(phi2)
        k = p.get("k", 0.0)
        Rt = Rt @ Rx(-k * ay) @ Ry(k * ax)
    p = effects.get("base_tilt")
    if p is not None:
        Rt = Rx(zero + p.get("tx", 0.0)) @ Rz(zero + p.get("tz", 0.0)) @ Rt
    p = effects.get("thermal_drift")
    if p is not None:
        t = np.asarray(time_s, dtype=float)
        Rt = Rt @ Rz(p.get("rz", 0.0) * t) @ Ry(p.get("ry", 0.0) * t) @ Rx(p.get("rx", 0.0) * t)
    p = effects.get("payload_mount")
    if p is not None:
        Rt = (
            Rt
            @ Rz(zero + p.get("mz", 0.0))
            @ Ry(zero + p.get("my", 0.0))
            @ Rx(zero + p.get("mx", 0.0))
        )
    Rd = Ry(phi1) @ Rz(phi2)
    return np.swapaxes(Rd, -1, -2) @ Rt


def reference_angles(phi1_rad, phi2_rad, errors=None, effects=None, **columns):
    """``[dpsi, dtheta, dgamma]`` (rad, (N, 3)) = ``dR[0,2], dR[1,0], dR[2,1]``."""
    dR = reference_rotation_error(phi1_rad, phi2_rad, errors, effects, **columns)
    return np.stack([dR[:, 0, 2], dR[:, 1, 0], dR[:, 2, 1]], axis=1)


# --- position designs (degrees, in measurement order) ---------------------------------------


def _grid(step1, step2):
    a1 = np.arange(0.0, 360.0 - 1e-9, step1)
    a2 = np.arange(0.0, 360.0 - 1e-9, step2)
    g1, g2 = np.meshgrid(a1, a2, indexing="ij")
    return g1.ravel(), g2.ravel()


def design(name, rng):
    """Commanded (phi1_deg, phi2_deg) of a named design, in the order they are measured.

    ``grid30`` (144), ``grid45`` (64), ``inner15_outer45`` (8 x 24), ``random`` (150 positions
    uniform in [-180, 180) with 3 decimals), ``repeated`` (the 30-degree grid twice, the second
    pass in random order: the same positions at different times).
    """
    if name == "grid30":
        return _grid(30.0, 30.0)
    if name == "grid45":
        return _grid(45.0, 45.0)
    if name == "inner15_outer45":
        return _grid(45.0, 15.0)
    if name == "random":
        return tuple(np.round(rng.uniform(-180.0, 180.0, (2, 150)), 3))
    if name == "repeated":
        p1, p2 = _grid(30.0, 30.0)
        perm = rng.permutation(p1.size)
        return np.concatenate([p1, p1[perm]]), np.concatenate([p2, p2[perm]])
    raise ValueError(f"unknown design {name}")


DESIGNS = ("grid30", "grid45", "inner15_outer45", "random", "repeated")


def random_effect_parameters(name, rng, scale_arcsec=3.0):
    """Random parameters of an effect at a realistic size, in rad, rad/g or rad/s.

    Angles: each coefficient +-scale (sign random, magnitude in [0.6, 1] x scale); gravity sag k
    about 2 x scale per g; thermal drift about 1.5 x scale per hour on each axis.
    """
    out = {}
    for p in EFFECT_PARAMETERS[name]:
        value = rng.choice([-1.0, 1.0]) * rng.uniform(0.6, 1.0) * scale_arcsec * ARCSEC
        if name == "gravity_sag":
            value *= 2.0
        if name == "thermal_drift":
            value *= 1.5 / 3600.0
        out[p] = value
    return out


def make_run(
    rng,
    design_name="grid30",
    errors=None,
    effects=None,
    noise_arcsec=1.0,
    dwell_s=60.0,
):
    """A measurement run: columns in the spec's units (degrees, arcsec, s, +-1), measurement order.

    Returns ``{column: array}`` with phi1_deg, phi2_deg, the three angles, sigma_arcsec, time_s,
    dir1, dir2 (time from the measurement order; directions random).
    """
    phi1_deg, phi2_deg = design(design_name, rng)
    n = phi1_deg.size
    time_s = np.arange(n) * dwell_s + rng.uniform(0.0, 5.0)
    dir1 = rng.choice([-1.0, 1.0], n)
    dir2 = rng.choice([-1.0, 1.0], n)
    angles = reference_angles(
        np.deg2rad(phi1_deg),
        np.deg2rad(phi2_deg),
        errors,
        effects,
        time_s=time_s,
        dir1=dir1,
        dir2=dir2,
    )
    angles_arcsec = angles / ARCSEC + rng.normal(0.0, noise_arcsec, angles.shape)
    return {
        "phi1_deg": phi1_deg,
        "phi2_deg": phi2_deg,
        "dpsi_arcsec": angles_arcsec[:, 0],
        "dtheta_arcsec": angles_arcsec[:, 1],
        "dgamma_arcsec": angles_arcsec[:, 2],
        "sigma_arcsec": np.full(n, float(noise_arcsec)),
        "time_s": time_s,
        "dir1": dir1,
        "dir2": dir2,
    }


def write_csv(
    path,
    columns,
    rng=None,
    *,
    drop=(),
    shuffle_rows=False,
    shuffle_columns=False,
    extra_column=False,
):
    """Write ``columns`` as a CSV the way another tool might: plain ``csv`` module, no comments.

    Args:
        drop: column names to leave out (e.g. ``sigma_arcsec``, ``time_s``).
        shuffle_rows, shuffle_columns: permute the rows / the column order (needs ``rng``).
        extra_column: add unknown columns (an operator note and a temperature).
    """
    names = [c for c in columns if c not in drop]
    n = len(columns["phi1_deg"])
    order = rng.permutation(n) if shuffle_rows else np.arange(n)
    if shuffle_columns:
        names = [names[i] for i in rng.permutation(len(names))]
    header = list(names)
    if extra_column:
        header = ["operator_note", *header, "temperature_degC"]
    path = Path(path)
    with path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(header)
        for i in order:
            row = []
            for name in header:
                if name == "operator_note":
                    row.append(f"pos{i}")
                elif name == "temperature_degC":
                    row.append(f"{21.0 + 0.001 * i:.3f}")
                elif name in ("dir1", "dir2"):
                    row.append(str(int(columns[name][i])))
                else:
                    row.append(repr(float(columns[name][i])))
            writer.writerow(row)
    return path
