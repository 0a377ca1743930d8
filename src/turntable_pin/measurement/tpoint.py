"""TPOINT pointing runs in: a telescope mount's star-pointing run as an orientation-measurement CSV.

A telescope mount is a two-axis table. A TPOINT run records, per star, where the star is (the
*observed* position) and where the encoders say the mount pointed (the *raw* position).
:func:`read_tpoint` reads it (a :class:`TpointRun`), :func:`convert_tpoint` makes the rows of the
measurement CSV (``docs/measurements.md``) for the bundled ``models/altaz_mount.urdf`` and
``models/german_equatorial_mount.urdf``.

Units: degrees in the file (sexagesimal h/d m s in equatorial records) and in ``phi1_deg,
phi2_deg``; arcsec in ``dpsi_arcsec, dtheta_arcsec``; temperature C, pressure mbar (hPa), height
m, humidity 0..1; radians inside.

The file (anything else is refused naming file and line):

- ``!`` starts a comment; blank lines are skipped; ``END`` ends the data. The first other line is
  the caption.
- Options ``: NAME`` (or ``:NAME``): ``ALTAZ``, ``EQUAT`` (the mount), ``NODA``, ``ALLSKY``
  (recorded only). ``J2000`` (mean places) is refused: no precession, nutation or aberration is
  done. Any other option is unknown.
- The run parameters: latitude ``+-d m s``, then optionally the date ``y m d``, temperature,
  pressure, height, humidity, wavelength (micron), lapse rate (K/m); 3, or 6 to 12 numbers.
- Alt-az data: ``az_obs el_obs az_raw el_raw``, decimal degrees (TPOINT's "format 4", as in the
  bundled MMT run and pytelpoint); TPOINT's azimuth (South = 0, East = 90) unless
  ``azimuth_origin``/``azimuth_direction`` say otherwise.
- Equatorial data: ``RA h m s, Dec +-d m s, raw RA h m s, raw Dec +-d m s, sidereal time h m``
  (14 numbers, as ACP's ModelToTpoint and RTS2's rts2-tpm write). Hour angles are ``LST - RA``
  (positive West), star and raw alike; star places are taken as apparent places of date.

The conversion (docs/model.md): ``dR = Rd(raw)^T Rt``, ``Rd`` the URDF's nominal chain and ``Rt =
Rd(observed)`` with the observed angles on the encoders' side of the pier (:func:`encoder_side`;
on the far side of a German-equatorial pier ``(H + 180 deg, +-180 deg - dec)``). A pointing run
measures the boresight's direction, not the roll about it, so the rows hold the boresight's own
components, exact whatever the roll: ``dtheta = dR[1,0]`` and ``dpsi = -dR[2,0]`` (``dR[0,2]`` of
``dR``'s swing); ``dgamma`` is left empty, and the fit compares such rows with the model's swing
likewise (``docs/measurements.md``, section 1).

Refraction: ``refraction="apply"`` lifts the observed position towards the zenith by Saemundsson's
refraction at the run's temperature and pressure before ``Rd(observed)`` is formed; ``"none"``
uses the positions as given. The default follows the file: ``none`` for alt-az runs (their
observed az/el are where the star is seen, refraction included, as in the MMT run and
pytelpoint), ``apply`` for equatorial runs (catalogue places, which TPOINT refracts).
"""

from __future__ import annotations

import itertools
import math
import re
import tempfile
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..core.csv_table import first_repeated_row
from ..core.exceptions import InputError
from ..core.files import read_text_file, write_text_atomic
from ..core.notebook import NotebookResult
from ..core.resources import models_dir
from ..core.sizes import MAX_TPOINT_FILE_BYTES, MAX_TPOINT_OBSERVATIONS
from ..core.units import ARCSEC_PER_RAD
from ..core.words import argument
from ..model.chain import compose_rotation
from ..model.generic_table import GenericTable
from .data import MAX_MEASURED_ANGLE_ARCSEC, OrientationMeasurements, read_measurements

__all__ = [
    "ALTAZ",
    "AZIMUTH_DIRECTIONS",
    "AZIMUTH_ORIGINS",
    "EQUATORIAL",
    "KNOWN_OPTIONS",
    "MOUNTS",
    "MOUNT_URDFS",
    "REFRACTION_MODES",
    "TpointConversion",
    "TpointRun",
    "convert_tpoint",
    "encoder_side",
    "far_side_rows",
    "mount_urdf_text",
    "read_tpoint",
    "refuse_repeated_positions",
    "saemundsson_refraction_arcsec",
]

ALTAZ = "altaz"
"""Mount type of an alt-azimuth run (``: ALTAZ``)."""
EQUATORIAL = "equatorial"
"""Mount type of an equatorial run (``: EQUAT``), converted on the German-equatorial URDF."""
MOUNTS = (ALTAZ, EQUATORIAL)
"""The mount types this module converts."""
MOUNT_URDFS = {ALTAZ: "altaz_mount.urdf", EQUATORIAL: "german_equatorial_mount.urdf"}
"""The bundled URDF (in the models folder) of each mount type."""
REFRACTION_MODES = ("apply", "none")
"""``apply``: refract the observed positions (Saemundsson); ``none``: use them as given."""
AZIMUTH_ORIGINS = ("south", "north")
"""Where the file's azimuth is 0."""
AZIMUTH_DIRECTIONS = ("east", "west")
"""Which side the file's azimuth 90 deg lies on."""
KNOWN_OPTIONS = ("ALTAZ", "EQUAT", "NODA", "ALLSKY", "J2000")
"""Option lines recognised (``J2000`` is recognised to be refused: mean places)."""

_OPTION_MOUNT = {"ALTAZ": ALTAZ, "EQUAT": EQUATORIAL}
_RECORD_NUMBERS = {ALTAZ: 4, EQUATORIAL: 14}
_RECORD_LAYOUT = {
    ALTAZ: "az_obs el_obs az_raw el_raw (decimal degrees)",
    EQUATORIAL: "RA h m s, Dec d m s, raw RA h m s, raw Dec d m s, sidereal time h m",
}
_RUN_FIELDS = (
    "temperature_c", "pressure_mbar", "height_m", "humidity", "wavelength_um", "lapse_rate_k_per_m",
)  # fmt: skip
_RUN_RANGES = {
    "temperature_c": (-100.0, 60.0),
    "pressure_mbar": (0.0, 1200.0),
    "height_m": (-500.0, 10000.0),
    "humidity": (0.0, 1.0),
}
"""Physical ranges of the run parameters (beyond them, refraction would be meaningless)."""
_NUMBER = re.compile(r"^[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?$")
_ORIGIN_NOTE = re.compile(r"\b(north|south)\s*=\s*0\b", re.I)
_DIRECTION_NOTE = re.compile(r"\b(east|west)\s*=\s*90\b", re.I)


@dataclass(frozen=True)
class TpointRun:
    """A TPOINT run as read (angles in degrees, in the table's conventions).

    Attributes:
        path, caption: the file and its caption line.
        options: the option names in file order (``ALTAZ``, ``NODA``, ...).
        mount: :data:`ALTAZ` or :data:`EQUATORIAL`; mount_line: the line of the option naming it
            (``None`` if given by the caller).
        latitude_deg: the site latitude (deg, North positive); latitude_text: as written.
        run_parameters: ``date`` (y, m, d) and the fields given of ``temperature_c`` (C),
            ``pressure_mbar``, ``height_m``, ``humidity`` (0..1), ``wavelength_um``,
            ``lapse_rate_k_per_m``.
        observed_deg, raw_deg: (N, 2) the star's and the encoders' angles (deg): azimuth (South
            = 0, East = 90) and elevation, or hour angle (positive West) and declination.
        lines: (N,) line number of each star's record (1 = first line of the file).
        azimuth_origin, azimuth_direction: the file's azimuth convention (alt-az), converted.
    """

    path: str
    caption: str
    options: tuple[str, ...]
    mount: str
    mount_line: int | None
    latitude_deg: float
    latitude_text: str
    run_parameters: dict = field(hash=False, compare=False)
    observed_deg: np.ndarray = field(hash=False, compare=False)
    raw_deg: np.ndarray = field(hash=False, compare=False)
    lines: tuple[int, ...] = ()
    azimuth_origin: str = "south"
    azimuth_direction: str = "east"

    @property
    def n_stars(self) -> int:
        """Number of data lines (stars)."""
        return len(self.lines)


@dataclass(frozen=True)
class TpointConversion(NotebookResult):
    """A run converted to measurement rows (definitions: the module docstring).

    Attributes:
        run: the :class:`TpointRun`.
        phi_deg: (N, 2) the raw (commanded) joint angles, ``phi1_deg, phi2_deg``.
        dpsi_arcsec, dtheta_arcsec: (N,) the measured orientation error angles.
        refraction: ``apply`` or ``none``; refraction_arcsec: (N,) what was added to each
            observed elevation (zeros for ``none``).
        latitude_deg: the latitude of the URDF's polar axis (equatorial; the file's for alt-az).
        urdf_name, urdf_text: the bundled URDF the rows belong to and its text (an equatorial
            run's tilted to ``latitude_deg``); urdf_written: where it was written, if it was.
    """

    run: TpointRun
    phi_deg: np.ndarray = field(hash=False, compare=False)
    dpsi_arcsec: np.ndarray = field(hash=False, compare=False)
    dtheta_arcsec: np.ndarray = field(hash=False, compare=False)
    refraction: str = "none"
    refraction_arcsec: np.ndarray = field(default=None, hash=False, compare=False)
    latitude_deg: float = 0.0
    urdf_name: str = ""
    urdf_text: str = ""
    urdf_written: str | None = None

    def comment_lines(self) -> list[str]:
        """The provenance written above the CSV header (each without its ``# ``)."""
        run = self.run
        p = run.run_parameters
        params = [f"latitude {run.latitude_text} ({run.latitude_deg:.6f} deg)"]
        if "date" in p:
            params.append("date {:04d}-{:02d}-{:02d}".format(*p["date"]))
        units = dict(zip(_RUN_FIELDS, (" C", " mbar", " m", "", " micron", " K/m"), strict=True))
        params += [f"{k.split('_')[0]} {p[k]:g}{units[k]}" for k in _RUN_FIELDS if k in p]
        first, second = ("azimuth", "elevation") if run.mount == ALTAZ else ("hour angle", "dec")
        if run.mount == ALTAZ:
            table = f"models/{self.urdf_name}"
        else:
            table = f"a copy of models/{self.urdf_name} with its polar axis at latitude " + (
                f"{self.latitude_deg:.6f} deg"
            )
        urdf = self.urdf_written or (f"models/{self.urdf_name}" if run.mount == ALTAZ else None)
        out = [
            f"imported by turntable-pin import-tpoint from {Path(run.path).name} (TPOINT run)",
            f"caption: {run.caption}",
            f"mount: {run.mount}, table {table}"
            + (f"; read with {argument('turntable')} {urdf}" if urdf else ""),
            "options: " + (" ".join(run.options) or "none"),
            "run parameters: " + ", ".join(params),
        ]
        if run.mount == ALTAZ:
            out.append(
                f"azimuth of the file: {run.azimuth_origin} = 0, {run.azimuth_direction} = 90; "
                "written in TPOINT's convention (South = 0, East = 90, right-handed about the "
                "upward vertical)"
            )
        else:
            out.append("hour angle = sidereal time - RA (positive West), star and raw alike; "
                       "star places taken as apparent places of date")  # fmt: skip
            far = int(far_side_rows(run).sum())
            out.append(
                f"pier sides: {run.n_stars - far} rows near, {far} far (raw dec beyond +-90 deg: "
                "the star taken at H + 180 deg, +-180 deg - dec, the encoders' side)"
            )
        if self.refraction == "apply":
            r = self.refraction_arcsec
            out.append(
                "refraction: applied (Saemundsson at the run's temperature and pressure; "
                f"{r.min():.2f} to {r.max():.2f} arcsec added to the observed elevations)"
            )
        else:
            out.append("refraction: none (the observed positions used as given)")
        out += [
            f"phi1_deg, phi2_deg = raw (encoder) {first} and {second}: the commanded angles",
            "dR = Rd(raw)^T Rd(observed) with the URDF's nominal chain; the boresight's own "
            "components, exact whatever the roll: dpsi_arcsec = -dR[2,0] (dR[0,2] of dR's swing), "
            "dtheta_arcsec = dR[1,0]; dgamma_arcsec empty (the roll is not measured); no sigma",
            "source lines of the rows, in order: " + _ranges(run.lines),
        ]
        return out

    def to_dict(self) -> dict:
        """The conversion as a JSON-ready dict: the run (file, caption, mount, stars, latitude),
        the refraction, the URDF the rows belong to, the rows (``phi1_deg, phi2_deg,
        dpsi_arcsec, dtheta_arcsec``) and the provenance lines of the CSV."""
        run = self.run
        return {
            "path": str(run.path),
            "caption": run.caption,
            "mount": run.mount,
            "n_stars": run.n_stars,
            "latitude_deg": self.latitude_deg,
            "refraction": self.refraction,
            "urdf_name": self.urdf_name,
            "rows": {
                "phi1_deg": self.phi_deg[:, 0].tolist(),
                "phi2_deg": self.phi_deg[:, 1].tolist(),
                "dpsi_arcsec": self.dpsi_arcsec.tolist(),
                "dtheta_arcsec": self.dtheta_arcsec.tolist(),
            },
            "comment_lines": self.comment_lines(),
        }

    def csv_text(self) -> str:
        """The measurement CSV (comment lines, header, one row per star)."""
        lines = [f"# {c}" for c in self.comment_lines()]
        lines.append("phi1_deg,phi2_deg,dpsi_arcsec,dtheta_arcsec,dgamma_arcsec")
        for (p1, p2), dpsi, dtheta in zip(
            self.phi_deg, self.dpsi_arcsec, self.dtheta_arcsec, strict=True
        ):
            lines.append(f"{_num(p1)},{_num(p2)},{dpsi:.12f},{dtheta:.12f},")
        return "\n".join(lines) + "\n"

    def write_csv(self, path: str | Path) -> Path:
        """Write :meth:`csv_text` to ``path`` atomically; returns the path."""
        return write_text_atomic(path, self.csv_text())

    def measurements(self) -> OrientationMeasurements:
        """The rows as measurements, read back from the CSV (written into a temporary folder,
        removed): what ``diagnose`` reads after ``import-tpoint``."""
        with tempfile.TemporaryDirectory(prefix="turntable-pin-tpoint-") as folder:
            path = self.write_csv(Path(folder) / f"{Path(self.run.path).stem}.csv")
            data = read_measurements(path)
        return data.replace(source=str(self.run.path))

    def write_urdf(self, path: str | Path) -> Path:
        """Write :attr:`urdf_text` to ``path`` atomically; returns the path."""
        return write_text_atomic(path, self.urdf_text)


def _num(value: float) -> str:
    """A float written so that it reads back exactly (shortest round-trip form)."""
    return repr(float(value))


def _ranges(lines) -> str:
    """``21-100, 104`` for the runs of consecutive numbers in the increasing ``lines``."""
    out = []
    for _, run in itertools.groupby(enumerate(lines), lambda pair: pair[1] - pair[0]):
        first, *rest = (n for _, n in run)
        out.append(f"{first}-{rest[-1]}" if rest else f"{first}")
    return ", ".join(out)


# --- reading ---------------------------------------------------------------------------------
def _numbers(tokens: list[str], path: Path, line: int, what: str) -> list[float]:
    """The tokens as floats, or :class:`InputError` naming the first that is not a number."""
    for tok in tokens:
        if not _NUMBER.match(tok):
            raise InputError(f"{what}: '{tok}' is not a number", path=path, line=line)
    return [float(t) for t in tokens]


def _sexagesimal(tokens: list[str], path: Path, line: int, what: str, limit: float) -> float:
    """``+-d m s`` (or ``h m s``) as a decimal number, sign from the first token's text."""
    d, m, s = _numbers(tokens, path, line, what)
    written = " ".join(tokens)
    if not (d == int(d) and 0 <= m < 60 and 0 <= s < 60):
        raise InputError(
            f"{what} '{written}': expected whole degrees (hours), minutes < 60 and seconds < 60",
            path=path,
            line=line,
        )
    value = abs(d) + m / 60.0 + s / 3600.0
    value = -value if tokens[0].startswith("-") else value
    if abs(value) > limit:
        raise InputError(f"{what} '{written}' is beyond +-{limit:g}", path=path, line=line)
    return value


def _azimuth_to_tpoint(az, origin: str, direction: str):
    """The file's azimuth (deg) in TPOINT's convention (South = 0, East = 90)."""
    if origin == "south":
        return az if direction == "east" else -az
    # North = 0: the right-handed (West = 90) one is TPOINT's turned by 180 deg; the common
    # North-through-East one is its mirror image.
    return az - 180.0 if direction == "west" else 180.0 - az


def read_tpoint(
    path: str | Path,
    *,
    mount: str | None = None,
    azimuth_origin: str = "south",
    azimuth_direction: str = "east",
) -> TpointRun:
    """Read a TPOINT run file (the layout of the module docstring).

    Args:
        path: the file.
        mount: :data:`ALTAZ` or :data:`EQUATORIAL` when the file has no mount option line; a file
            that states the other mount is refused.
        azimuth_origin, azimuth_direction: the azimuth convention of an alt-az file (default
            TPOINT's: South = 0, East = 90); converted to TPOINT's. A comment of the file that
            states another origin ("North = 0") or direction ("West = 90") is refused.

    Raises:
        InputError: naming the file and line of the first problem; a file that is not a regular
            one of at most ``MAX_TPOINT_FILE_BYTES`` (16 MB), or that holds more than
            ``MAX_TPOINT_OBSERVATIONS`` (200,000) observations.
    """
    path = Path(path)
    if mount is not None and mount not in MOUNTS:
        raise InputError(f"unknown mount '{mount}': expected one of {', '.join(MOUNTS)}")
    if azimuth_origin not in AZIMUTH_ORIGINS or azimuth_direction not in AZIMUTH_DIRECTIONS:
        raise InputError(
            f"azimuth convention '{azimuth_origin}, {azimuth_direction}': expected origin "
            f"{'|'.join(AZIMUTH_ORIGINS)} and direction {'|'.join(AZIMUTH_DIRECTIONS)}"
        )
    text = read_text_file(path, "TPOINT", encoding="utf-8-sig", max_bytes=MAX_TPOINT_FILE_BYTES)
    return _Reader(path, mount, azimuth_origin, azimuth_direction).read(text)


@dataclass
class _Reader:
    """What has been read of one TPOINT file so far (:func:`read_tpoint`)."""

    path: Path
    mount: str | None  # the caller's
    azimuth_origin: str
    azimuth_direction: str
    caption: str | None = None
    options: list[str] = field(default_factory=list)
    file_mount: str | None = None
    mount_line: int | None = None
    run_line: int | None = None
    latitude: float = 0.0
    latitude_text: str = ""
    params: dict = field(default_factory=dict)
    observed: list = field(default_factory=list)
    raw: list = field(default_factory=list)
    lines: list[int] = field(default_factory=list)
    notes: list = field(default_factory=list)  # (line, text) of the comments, for the azimuth

    def fail(self, message: str, line: int | None = None) -> InputError:
        """The error ``message`` about the file, at ``line``."""
        return InputError(message, path=self.path, line=line)

    @property
    def kind(self) -> str | None:
        """The mount: the file's, else the caller's."""
        return self.file_mount or self.mount

    def read(self, text: str) -> TpointRun:
        """The run the file's ``text`` holds."""
        for number, raw_line in enumerate(text.splitlines(), start=1):
            line = raw_line.strip()
            if not line:
                continue
            if line.startswith("!"):
                self.notes.append((number, line))
            elif self.caption is None:
                self.caption = line
            elif line.upper() == "END":
                break
            elif line.startswith(":"):
                self.option(line, number)
            elif self.run_line is None:
                self.run_parameters(line.split(), number)
            else:
                self.record(line.split(), number)
        return self.run()

    def option(self, line: str, number: int) -> None:
        """An option line ``: NAME``."""
        name = line[1:].strip().split()[0].upper() if line[1:].strip() else ""
        if self.run_line is not None:
            raise self.fail(
                f"option line '{line}' after the run-parameter line (line {self.run_line}): "
                "options come between the caption and the run parameters",
                number,
            )
        if name not in KNOWN_OPTIONS:
            known = ", ".join(f": {o}" for o in KNOWN_OPTIONS)
            raise self.fail(f"unknown option line '{line}': this importer knows {known}", number)
        if name == "J2000":
            raise self.fail(
                "': J2000' (mean J2000 star places) is not supported: the importer does no "
                "precession, nutation or aberration; give apparent places of date",
                number,
            )
        if name in _OPTION_MOUNT:
            if self.file_mount is not None and _OPTION_MOUNT[name] != self.file_mount:
                raise self.fail(
                    f"'{line}' contradicts the mount option on line {self.mount_line}", number
                )
            self.file_mount, self.mount_line = _OPTION_MOUNT[name], number
            if self.mount is not None and self.mount != self.file_mount:
                raise self.fail(
                    f"the file states an {self.file_mount} mount ('{line}'), but "
                    f"{argument('mount')} {self.mount} was given",
                    number,
                )
        self.options.append(name)

    def run_parameters(self, tokens: list[str], number: int) -> None:
        """The run-parameter line: latitude, then the date and the other fields if given."""
        if self.kind is None:
            raise self.fail(
                "the file states no mount (no ': ALTAZ' or ': EQUAT' option line before the run "
                f"parameters); give {argument('mount')} altaz|equatorial",
                number,
            )
        if len(tokens) == _RECORD_NUMBERS[self.kind] or len(tokens) not in (3, *range(6, 13)):
            raise self.fail(
                "expected the run-parameter line (latitude d m s [year month day temperature_C "
                "pressure_mbar height_m humidity ...]: 3 or 6 to 12 numbers), got "
                f"{len(tokens)} fields: the run-parameter line is missing",
                number,
            )
        self.latitude = _sexagesimal(tokens[:3], self.path, number, "latitude", 90.0)
        self.latitude_text = " ".join(tokens[:3])
        rest = _numbers(tokens[3:], self.path, number, "run parameter")
        if rest:
            y, mo, d = rest[:3]
            if not (y == int(y) and mo == int(mo) and d == int(d) and 1 <= mo <= 12
                    and 1 <= d <= 31):  # fmt: skip
                raise self.fail(f"date '{' '.join(tokens[3:6])}': expected year month day", number)
            self.params["date"] = (int(y), int(mo), int(d))
            self.params.update(zip(_RUN_FIELDS, rest[3:], strict=False))
        for key, (low, high) in _RUN_RANGES.items():
            value = self.params.get(key)
            if value is not None and not low <= value <= high:
                raise self.fail(
                    f"run parameter {key} = {value:g} is outside [{low:g}, {high:g}]", number
                )
        self.run_line = number

    def record(self, tokens: list[str], number: int) -> None:
        """A data line: one star's observed and raw position."""
        expected = _RECORD_NUMBERS[self.kind]
        if len(self.lines) >= MAX_TPOINT_OBSERVATIONS:
            raise self.fail(
                f"more than {MAX_TPOINT_OBSERVATIONS:,} observations; a TPOINT run is read up to "
                f"{MAX_TPOINT_OBSERVATIONS:,} (as many as a diagnosis takes rows)",
                number,
            )
        if len(tokens) != expected:
            raise self.fail(
                f"expected {expected} numbers ({_RECORD_LAYOUT[self.kind]}), got {len(tokens)} "
                "fields",
                number,
            )
        values = _numbers(tokens, self.path, number, "data")
        if self.kind == ALTAZ:
            observed, raw = self._altaz(values, number)
        else:
            observed, raw = self._equatorial(tokens, values, number)
        self.observed.append(observed)
        self.raw.append(raw)
        self.lines.append(number)

    def _altaz(self, values: list[float], number: int) -> tuple:
        """The observed and raw (azimuth, elevation) of an alt-az record, TPOINT's azimuth."""
        az_o, el_o, az_r, el_r = values
        for label, el in (("observed", el_o), ("raw", el_r)):
            if not -90.0 <= el <= 90.0:
                raise self.fail(f"{label} elevation {el:g} deg is outside [-90, 90]", number)
        for label, az in (("observed", az_o), ("raw", az_r)):
            if abs(az) > 720.0:
                raise self.fail(f"{label} azimuth {az:g} deg is beyond +-720 deg", number)
        o, d = self.azimuth_origin, self.azimuth_direction
        return (_azimuth_to_tpoint(az_o, o, d), el_o), (_azimuth_to_tpoint(az_r, o, d), el_r)

    def _equatorial(self, tokens: list[str], values: list[float], number: int) -> tuple:
        """The observed and raw (hour angle, declination) of an equatorial record."""
        path = self.path
        ra = _sexagesimal(tokens[0:3], path, number, "RA", 24.0)
        dec = _sexagesimal(tokens[3:6], path, number, "Dec", 90.0)
        ra_raw = _sexagesimal(tokens[6:9], path, number, "raw RA", 24.0)
        dec_raw = _sexagesimal(tokens[9:12], path, number, "raw Dec", 180.0)
        h, m = values[12:14]
        if not (h == int(h) and 0 <= h < 24 and 0 <= m < 60):
            raise self.fail(
                f"sidereal time '{tokens[12]} {tokens[13]}': expected hours < 24 and minutes < 60",
                number,
            )
        lst = h + m / 60.0
        return (15.0 * (lst - ra), dec), (15.0 * (lst - ra_raw), dec_raw)

    def run(self) -> TpointRun:
        """The run read, once the file is through: refused without a caption, run parameters or
        data, or when a comment states another azimuth convention than the one taken."""
        if self.caption is None:
            raise self.fail("no caption line, no run-parameter line and no data lines")
        if self.run_line is None:
            raise self.fail(
                "no run-parameter line (latitude d m s [date temperature pressure ...]) after the "
                "caption and options"
            )
        if not self.lines:
            raise self.fail(f"no data lines after the run-parameter line (line {self.run_line})")
        if self.kind == ALTAZ:
            self._check_azimuth_notes()
        return TpointRun(
            path=str(self.path),
            caption=self.caption,
            options=tuple(self.options),
            mount=self.kind,
            mount_line=self.mount_line,
            latitude_deg=float(self.latitude),
            latitude_text=self.latitude_text,
            run_parameters=self.params,
            observed_deg=np.array(self.observed, dtype=float),
            raw_deg=np.array(self.raw, dtype=float),
            lines=tuple(self.lines),
            azimuth_origin=self.azimuth_origin,
            azimuth_direction=self.azimuth_direction,
        )

    def _check_azimuth_notes(self) -> None:
        """Refuse an azimuth convention that a comment of the file contradicts."""
        checks = (
            (_ORIGIN_NOTE, self.azimuth_origin, "the azimuth origin is", "origin"),
            (_DIRECTION_NOTE, self.azimuth_direction, "azimuth 90 is", "direction"),
        )
        for number, text in self.notes:
            for pattern, taken, what, option in checks:
                found = pattern.search(text)
                if found and found.group(1).lower() != taken:
                    flag = argument(f"azimuth_{option}")
                    raise self.fail(
                        f"the file's comment states '{found.group(0)}', but {what} taken as "
                        f"{taken} ({flag}); give {flag} {found.group(1).lower()} or correct the "
                        "comment",
                        number,
                    )


# --- the mount URDFs --------------------------------------------------------------------------
def mount_urdf_text(mount: str, latitude_deg: float | None = None, note: str = "") -> str:
    """The bundled URDF of ``mount``; for :data:`EQUATORIAL` with the ``hour_angle`` joint's
    origin ``rpy`` set to ``(0, latitude - 90 deg, 0)`` (an XML edit; comments kept, a note added).
    """
    source = models_dir() / MOUNT_URDFS[mount]
    text = source.read_text(encoding="utf-8")
    if mount != EQUATORIAL:
        return text
    if latitude_deg is None or not -90.0 <= latitude_deg <= 90.0:
        raise InputError(f"latitude {latitude_deg!r}: expected a value in [-90, 90] deg")
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    root = ET.fromstring(text, parser=parser)
    joint = root.find("./joint[@name='hour_angle']")
    origin = None if joint is None else joint.find("origin")
    if origin is None:
        raise InputError(f"{source}: no origin of the joint 'hour_angle' to tilt")
    pitch = math.radians(latitude_deg - 90.0)
    origin.set("rpy", f"0 {pitch!r} 0")
    comment = ET.Comment(
        f" Copy tilted to latitude {latitude_deg!r} deg: hour_angle origin rpy = (0, latitude - "
        f"90 deg, 0) = (0, {pitch!r}, 0). {note}".rstrip()
        + " "
    )
    root.insert(0, comment)
    body = ET.tostring(root, encoding="unicode")
    # the XML declaration and the frames comment: up to the <robot> element's own line (the
    # comment may name the element too)
    header = text[: re.search(r"^\s*<robot\b", text, re.MULTILINE).start()]
    return header + body + "\n"


# --- refraction -------------------------------------------------------------------------------
def saemundsson_refraction_arcsec(elevation_deg, temperature_c: float, pressure_mbar: float):
    """Atmospheric refraction (arcsec) at the true (unrefracted) elevation ``elevation_deg``.

    Saemundsson's formula, ``R = 1.02' / tan(h + 10.3 / (h + 5.11))`` (h in degrees), scaled by
    ``(P / 1010 mbar) * (283 K / (273 K + T))``; good to a few arc seconds above ~5 deg elevation.
    """
    h = np.asarray(elevation_deg, dtype=float)
    r_arcmin = 1.02 / np.tan(np.radians(h + 10.3 / (h + 5.11)))
    return r_arcmin * 60.0 * (pressure_mbar / 1010.0) * (283.0 / (273.0 + temperature_c))


def _boresight(placements, q_rad) -> np.ndarray:
    """The payload's x axis in the base frame at joint angles ``q_rad`` (2, ...) -> (..., 3)."""
    return compose_rotation(placements, list(q_rad))[..., :, 0]


def _lift(v: np.ndarray, angle_rad: np.ndarray) -> np.ndarray:
    """Directions ``v`` (N, 3) turned towards the zenith (+z) by ``angle_rad`` (N,)."""
    up = np.array([0.0, 0.0, 1.0])
    across = up - v[:, 2:3] * v
    across /= np.linalg.norm(across, axis=1, keepdims=True)
    return np.cos(angle_rad)[:, None] * v + np.sin(angle_rad)[:, None] * across


def _angles_pointing_at(placements, target: np.ndarray, start_rad: np.ndarray) -> np.ndarray:
    """Joint angles (2, N) near ``start_rad`` whose boresight is ``target`` (N, 3): Gauss-Newton
    with the chain's own boresight, to 1e-13 rad."""
    q = np.array(start_rad, dtype=float)
    step = 1e-7
    for _ in range(20):
        f = _boresight(placements, q)
        jac = np.stack(
            [(_boresight(placements, q + step * e[:, None]) - f) / step for e in np.eye(2)], axis=-1
        )  # (N, 3, 2)
        dq = np.einsum("nij,nj->ni", np.linalg.pinv(jac), target - f).T
        q = q + dq
        if np.max(np.abs(dq)) < 1e-13:
            break
    return q


# --- conversion -------------------------------------------------------------------------------
def refuse_repeated_positions(run: TpointRun) -> None:
    """Refuse two records of ``run`` at the same raw position, naming both lines of the file.

    The CSV's rows are the raw positions, and its reader refuses two at one position unless they
    differ in ``time_s`` or approach direction (:func:`~.core.csv_table.refuse_repeated_rows`),
    which a TPOINT run does not record: the same rule here keeps the import from writing a file
    ``fit`` and ``diagnose`` refuse. The message tells a copied line (the same star) from two
    pointings that read the same encoder position.
    """
    found = first_repeated_row(list(run.raw_deg.T), run.n_stars)
    if found is None:
        return
    i, j = found
    first, second = run.lines[i], run.lines[j]
    axes = "azimuth, elevation" if run.mount == ALTAZ else "hour angle, declination"
    same_star = first_repeated_row(list(run.observed_deg[[i, j]].T), 2) is not None
    if same_star:
        what = (
            f"lines {first} and {second} are the same star at the same raw position: a copied "
            "line counts one pointing twice"
        )
    else:
        what = (
            f"lines {first} and {second} have the same raw position ({axes}) and different "
            "observed positions"
        )
    raise InputError(
        f"{what}; the measurement CSV holds one row per position (repeats there must differ in "
        "time_s or approach direction, which a TPOINT file does not record): keep one of them",
        path=run.path,
    )


def far_side_rows(run: TpointRun) -> np.ndarray:
    """(N,) True where an equatorial run's raw declination is beyond +-90 deg: the tube was on
    the far side of the pier (the mount turned past the pole); always False for alt-az runs."""
    if run.mount != EQUATORIAL:
        return np.zeros(run.n_stars, dtype=bool)
    return np.abs(run.raw_deg[:, 1]) > 90.0


def encoder_side(run: TpointRun) -> np.ndarray:
    """(N, 2) the observed (star) angles on the encoders' side of the pier (deg).

    On the far side of the pier the joint angles that point the tube at a star at (H, dec) are
    (H + 180 deg, +-180 deg - dec), the sign that of the raw declination: the same direction with
    the tube rolled 180 deg about it. The star's orientation is taken there, so that it is
    compared with the encoders' orientation on the same side, not across the pier.
    """
    observed = run.observed_deg.copy()
    far = far_side_rows(run)
    if far.any():
        sign = np.sign(run.raw_deg[far, 1])
        observed[far, 0] = observed[far, 0] + 180.0
        observed[far, 1] = sign * 180.0 - observed[far, 1]
    return observed


def convert_tpoint(
    run: TpointRun, *, refraction: str | None = None, latitude_deg: float | None = None
) -> TpointConversion:
    """The measurement rows of ``run`` (see the module docstring).

    Args:
        run: a :class:`TpointRun`.
        refraction: ``apply`` or ``none``; ``None``: the file type's default (``none`` for alt-az,
            ``apply`` for equatorial).
        latitude_deg: the polar axis' latitude of an equatorial run (default: the file's).

    Raises:
        InputError: two records at the same raw position (:func:`refuse_repeated_positions`,
            naming both lines); refraction requested without temperature and pressure, or at an
            observed elevation below 0 deg; an observed/raw pair farther apart on the sky than a
            measurement file may hold (``MAX_MEASURED_ANGLE_ARCSEC``: not a pointing error),
            naming the line.
    """
    refuse_repeated_positions(run)
    if refraction is None:
        refraction = "none" if run.mount == ALTAZ else "apply"
    if refraction not in REFRACTION_MODES:
        raise InputError(
            f"refraction '{refraction}': expected one of {', '.join(REFRACTION_MODES)}"
        )
    latitude = run.latitude_deg if latitude_deg is None else float(latitude_deg)
    urdf_text = mount_urdf_text(
        run.mount,
        latitude,
        note=f"Written for {Path(run.path).name}." if run.mount == EQUATORIAL else "",
    )
    with tempfile.TemporaryDirectory(prefix="turntable-pin-tpoint-") as folder:
        urdf = Path(folder) / MOUNT_URDFS[run.mount]
        urdf.write_text(urdf_text, encoding="utf-8")
        placements = GenericTable(urdf).chain.placements()
    raw = np.radians(run.raw_deg).T  # (2, N)
    obs = np.radians(encoder_side(run)).T
    refr = np.zeros(run.n_stars)
    if refraction == "apply":
        obs, refr = _refracted(run, placements, obs)
    d_r = np.swapaxes(compose_rotation(placements, list(raw)), -1, -2) @ compose_rotation(
        placements, list(obs)
    )
    _refuse_far_apart(run, d_r)
    return TpointConversion(
        run=run,
        phi_deg=run.raw_deg.copy(),
        dpsi_arcsec=-d_r[:, 2, 0] * ARCSEC_PER_RAD,
        dtheta_arcsec=d_r[:, 1, 0] * ARCSEC_PER_RAD,
        refraction=refraction,
        refraction_arcsec=refr,
        latitude_deg=latitude,
        urdf_name=MOUNT_URDFS[run.mount],
        urdf_text=urdf_text,
    )


def _refracted(run: TpointRun, placements, obs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The observed joint angles ``obs`` (2, N) lifted by the refraction at the run's temperature
    and pressure, and that refraction (N,) arcsec."""
    p = run.run_parameters
    if "temperature_c" not in p or "pressure_mbar" not in p:
        flag = argument("refraction")
        raise InputError(
            f"{flag} apply needs the temperature and pressure of the run-parameter line, which "
            f"gives none; use {flag} none or complete the line",
            path=run.path,
        )
    v = _boresight(placements, obs)
    elevation = np.degrees(np.arcsin(np.clip(v[:, 2], -1.0, 1.0)))
    low = np.flatnonzero(elevation < 0.0)
    if low.size:
        raise InputError(
            f"observed elevation {elevation[low[0]]:.3f} deg is below the horizon: refraction "
            "is not defined there",
            path=run.path,
            line=run.lines[low[0]],
        )
    refr = saemundsson_refraction_arcsec(elevation, p["temperature_c"], p["pressure_mbar"])
    return _angles_pointing_at(placements, _lift(v, refr / ARCSEC_PER_RAD), obs), refr


def _refuse_far_apart(run: TpointRun, d_r: np.ndarray) -> None:
    """Refuse the first star whose observed and raw positions (``d_r`` (N, 3, 3) between them)
    are farther apart on the sky than a measurement file may hold: not a pointing error."""
    separation = np.degrees(np.arccos(np.clip(d_r[:, 0, 0], -1.0, 1.0))) * 3600.0
    far = np.flatnonzero(separation > MAX_MEASURED_ANGLE_ARCSEC)
    if far.size:
        i = far[0]
        raise InputError(
            f"the observed and raw positions are {separation[i] / 3600.0:.3f} deg apart on the "
            f"sky (observed {run.observed_deg[i, 0]:g}, {run.observed_deg[i, 1]:g}; raw "
            f"{run.raw_deg[i, 0]:g}, {run.raw_deg[i, 1]:g} deg): more than "
            f"{MAX_MEASURED_ANGLE_ARCSEC / 3600.0:g} deg is not a pointing error (a column or "
            "convention mix-up?)",
            path=run.path,
            line=run.lines[i],
        )
