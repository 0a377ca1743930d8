"""Test helper: a TPOINT run (observed and raw angles) as a measurement CSV of a mount, and runs
made with TPOINT's first-order term formulas.

The conversion is the one of ``models/altaz_mount.urdf``'s header: the mount's nominal chain at
the raw angles is where the encoders say the tube points, at the observed angles where the star
is, ``dR = Rd(raw)^T Rd(obs)``, ``dtheta = dR[1,0]``, ``dpsi = -dR[2,0]`` (the boresight's own
component: the roll is not measured), ``dgamma`` not measured; the commanded angles are the raw
ones. (The package's importer, ``import-tpoint``, is
written separately; this helper is the tests' own reading.)
"""

from __future__ import annotations

import math
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
    return np.stack([-dR[:, 2, 0], dR[:, 1, 0]], axis=1) * ARCSEC_PER_RAD


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


# --- equatorial runs ----------------------------------------------------------------------------
def sexagesimal(value: float, hours: bool = False) -> str:
    """``+d m s`` (or ``h m s`` of an angle in degrees when ``hours``), seconds to 1e-9."""
    sign = "-" if value < 0 else "+"
    value = abs(float(value)) / (15.0 if hours else 1.0)
    d = int(value)
    m = int((value - d) * 60.0)
    s = (value - d - m / 60.0) * 3600.0
    if s >= 59.9999999995:  # keep the seconds below 60 once written with 9 places
        s = 0.0
        m += 1
        if m == 60:
            m, d = 0, d + 1
    return ("" if hours else sign) + f"{d:02d} {m:02d} {s:012.9f}"


def write_equatorial_indat(
    path: Path, star_deg: np.ndarray, raw_deg: np.ndarray, lst_deg: np.ndarray,
    latitude_deg: float, caption: str = "synthetic German-equatorial run",
) -> Path:  # fmt: skip
    """An INDAT file of an equatorial run: per row the star's (H, dec), the mount's raw (H,
    dec) (deg; the raw dec beyond +-90 on the far side of the pier) and the sidereal time (deg),
    written as ``RA h m s, Dec d m s, raw RA, raw Dec, LST h m`` with RA = LST - H."""
    lat = sexagesimal(latitude_deg)
    rows = [f"! {caption}", caption, ":NODA", ":EQUAT", f"{lat} 2024 3 1 10.0 1000.0 100.0 0.5"]
    for (h, d), (h_r, d_r), lst in zip(star_deg, raw_deg, lst_deg, strict=True):
        lst_h = (lst / 15.0) % 24.0
        hour = int(lst_h)
        minutes = float((lst_h - hour) * 60.0)
        rows.append(
            f"{sexagesimal((lst - h) % 360.0, True)} {sexagesimal(d)} "
            f"{sexagesimal((lst - h_r) % 360.0, True)} {sexagesimal(d_r)} {hour:02d} {minutes!r}"
        )
    Path(path).write_text("\n".join(rows) + "\nEND\n")
    return Path(path)


def read_equatorial_indat(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """``(star, raw)``: (N, 2) hour angle (LST - RA, positive West) and declination, deg, as the
    file has them (the raw declination beyond +-90 on the far side of the pier)."""

    def angle(tokens: list[str]) -> float:
        d, m, s = (abs(float(t)) for t in tokens)
        return (-1.0 if tokens[0].startswith("-") else 1.0) * (d + m / 60.0 + s / 3600.0)

    star, raw = [], []
    for line in Path(path).read_text().splitlines():
        parts = line.split()
        if len(parts) != 14 or line.startswith("!"):
            continue
        lst = 15.0 * (float(parts[12]) + float(parts[13]) / 60.0)
        star.append((lst - 15.0 * angle(parts[0:3]), angle(parts[3:6])))
        raw.append((lst - 15.0 * angle(parts[6:9]), angle(parts[9:12])))
    return np.array(star), np.array(raw)


def star_side(raw_deg: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The raw angles seen on the star's side of the pier, (N, 2) deg, and the pier sign (N,):
    +1 on the near side, -1 on the far side (raw dec beyond +-90: H - 180, +-180 - dec)."""
    h, d = np.asarray(raw_deg, dtype=float).T
    far = np.abs(d) > 90.0
    sky = np.c_[np.where(far, h - 180.0, h), np.where(far, np.sign(d) * 180.0 - d, d)]
    return sky, np.where(far, -1.0, 1.0)


EQUATORIAL_TERMS = ("IH", "ID", "CH", "NP", "MA", "ME", "TF")


def equatorial_term_columns(star_deg, pier, latitude_deg, names=EQUATORIAL_TERMS) -> np.ndarray:
    """TPOINT's first-order equatorial formulas, observed minus raw (obs = raw + D), per unit
    term: (2N, k), the rows ``dH cos dec`` then ``d dec``; ID, CH and NP change sign on the far
    side of the pier (``pier`` -1), TPOINT's rule. Evaluated at the star's (H, dec)."""
    h, d = np.radians(np.asarray(star_deg, dtype=float)).T
    lat = math.radians(latitude_deg)
    one, zero = np.ones_like(h), np.zeros_like(h)
    formulas = {
        "IH": (-one, zero),
        "ID": (zero, -pier * one),
        "CH": (-pier / np.cos(d), zero),
        "NP": (-pier * np.tan(d), zero),
        "MA": (-np.cos(h) * np.tan(d), np.sin(h)),
        "ME": (np.sin(h) * np.tan(d), np.cos(h)),
        "TF": (
            math.cos(lat) * np.sin(h) / np.cos(d),
            math.cos(lat) * np.cos(h) * np.sin(d) - math.sin(lat) * np.cos(d),
        ),
    }
    return np.stack([np.r_[formulas[n][0] * np.cos(d), formulas[n][1]] for n in names], axis=1)


def tpoint_equatorial_fit(path: Path, latitude_deg: float, names=EQUATORIAL_TERMS[:6]):
    """TPOINT's formulas fitted by linear least squares to an equatorial INDAT file (no
    refraction): ``({term: arcsec}, rms arcsec over the 2N values dH cos dec and d dec)``."""
    star, raw = read_equatorial_indat(path)
    sky, pier = star_side(raw)
    d_h = ((star[:, 0] - sky[:, 0] + 180.0) % 360.0 - 180.0) * 3600.0
    y = np.r_[d_h * np.cos(np.radians(star[:, 1])), (star[:, 1] - sky[:, 1]) * 3600.0]
    x = equatorial_term_columns(star, pier, latitude_deg, names)
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    return dict(zip(names, coef, strict=True)), float(np.sqrt(np.mean((y - x @ coef) ** 2)))
