"""Test helper: a TPOINT run (observed and raw angles) as a measurement CSV of a mount, and runs
made with TPOINT's first-order term formulas.

The conversion is the one of ``models/altaz_mount.urdf``'s header: the mount's nominal chain at
the raw angles is where the encoders say the tube points, at the observed angles where the star
is, ``dR = Rd(raw)^T Rd(obs)``, ``dtheta = dR[1,0]``, ``dpsi = dR[0,2]``, ``dgamma`` not
measured; the commanded angles are the raw ones. (The package's importer, ``import-tpoint``, is
written separately; this helper is the tests' own reading.)
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.model.chain import compose_rotation
from turntable_pin.model.generic_table import GenericTable

ROOT = Path(__file__).resolve().parents[1]
ALTAZ_URDF = ROOT / "models" / "altaz_mount.urdf"
EQUATORIAL_URDF = ROOT / "models" / "german_equatorial_mount.urdf"
MMT_RUN = ROOT.parent / "shared" / "data" / "mmt_pointing" / "k_and_e.dat"
MMT_BUNDLED = ROOT / "models" / "examples" / "mmt_pointing" / "k_and_e.dat"

MMT_PUBLISHED_ARCSEC = {
    "IA": 1209.26, "IE": -2.99, "NPAE": -3.47, "CA": -5.95, "AN": 2.50, "AW": -10.33,
    "TF": 21.41, "TX": -2.72,
}  # fmt: skip
"""The published 8-term fit of the MMT run (pytelpoint's notebook; ../shared README)."""


def mmt_run_path() -> Path:
    """The MMT run: the bundled copy when the importer's developer has added it, else the shared
    one."""
    return MMT_BUNDLED if MMT_BUNDLED.is_file() else MMT_RUN


def read_tpoint_altaz(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """``(observed, raw)`` azimuth/elevation of a TPOINT format-4 alt-az run, deg (N, 2) each."""
    rows = []
    seen_option = False
    for line in Path(path).read_text().splitlines():
        text = line.strip()
        if not text or text.startswith("!"):
            continue
        if text.startswith(":"):
            seen_option = True
            continue
        parts = text.split()
        if not seen_option or len(parts) < 4:
            continue
        try:
            values = [float(p) for p in parts[:4]]
        except ValueError:
            continue
        if len(parts) >= 10 and not rows and parts[0].startswith(("+", "-")):
            continue  # the run-parameter line (latitude d m s, date, ...)
        rows.append(values)
    data = np.array(rows)
    return data[:, :2], data[:, 2:4]


def measured_angles(urdf: Path, raw_deg: np.ndarray, obs_deg: np.ndarray) -> np.ndarray:
    """``dpsi, dtheta`` (arcsec, (N, 2)) of a mount pointing at ``obs`` when its encoders read
    ``raw`` (angles in the mount's joint order, deg)."""
    placements = GenericTable(urdf).chain.placements()
    rd_raw = compose_rotation(placements, list(np.radians(raw_deg).T))
    rd_obs = compose_rotation(placements, list(np.radians(obs_deg).T))
    dR = np.swapaxes(rd_raw, -1, -2) @ rd_obs
    return np.stack([dR[:, 0, 2], dR[:, 1, 0]], axis=1) * ARCSEC_PER_RAD


def write_pointing_csv(path: Path, raw_deg: np.ndarray, angles_arcsec: np.ndarray) -> Path:
    """A measurement CSV: commanded (raw) angles, ``dpsi, dtheta``, ``dgamma`` empty."""
    lines = ["phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec"]
    for (p1, p2), (dpsi, dtheta) in zip(raw_deg, angles_arcsec, strict=True):
        lines.append(f"{float(p1)!r},{float(p2)!r},{dpsi:.9f},{dtheta:.9f},")
    Path(path).write_text("\n".join(lines) + "\n")
    return Path(path)


def mmt_csv(path: Path) -> Path:
    """The MMT run as a measurement CSV of ``models/altaz_mount.urdf`` at ``path``."""
    obs, raw = read_tpoint_altaz(mmt_run_path())
    return write_pointing_csv(path, raw, measured_angles(ALTAZ_URDF, raw, obs))
