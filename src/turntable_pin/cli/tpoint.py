"""``import-tpoint``: a TPOINT pointing run (a telescope mount's star pointings) as a measurement
CSV of the bundled mount URDFs."""

from __future__ import annotations

# The library is imported inside the functions that use it, deliberately: start-up time.
import argparse
from pathlib import Path

from ..core.exceptions import InputError
from .common import input_path, latitude_deg, one_line_errors

__all__ = ["register"]

# The conversion (numpy, Pinocchio) is imported inside the command.
MOUNTS = ("altaz", "equatorial")
REFRACTION = ("apply", "none")


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add ``import-tpoint`` to ``subparsers``."""
    p = subparsers.add_parser(
        "import-tpoint",
        description="Convert a TPOINT run file (per star: observed and raw mount angles) into the "
        "orientation-measurement CSV of models/altaz_mount.urdf or "
        "models/german_equatorial_mount.urdf: phi1_deg, phi2_deg = the raw angles, dpsi_arcsec "
        "and dtheta_arcsec from dR = Rd(raw)^T Rd(observed) on the URDF's chain, dgamma_arcsec "
        "empty (the roll is not measured). Provenance goes into # comment lines. See "
        "docs/measurements.md, 'Pointing runs (TPOINT files)'.",
    )
    one_line_errors(p)
    p.add_argument("data", type=input_path, metavar="RUN.dat", help="the TPOINT file")
    p.add_argument("-o", "--output", type=Path, required=True, metavar="OUT.csv",
                   help="the measurement CSV to write")  # fmt: skip
    p.add_argument(
        "--mount",
        choices=MOUNTS,
        help="the mount, when the file has no ': ALTAZ' / ': EQUAT' line (a file that states "
        "the other one is refused; default: the file's)",
    )
    p.add_argument(
        "--refraction",
        choices=REFRACTION,
        help="apply: lift the observed positions by the Saemundsson refraction at the run's "
        "temperature and pressure; none: use them as given. Default: none for alt-az files "
        "(their observed az/el include refraction), apply for equatorial files (catalogue places)",
    )
    p.add_argument(
        "--latitude-deg",
        type=latitude_deg,
        help="the polar axis' latitude of an equatorial mount (default: the file's)",
    )
    p.add_argument(
        "--azimuth-origin",
        choices=("south", "north"),
        default="south",
        help="where the file's azimuth is 0 (south: TPOINT's convention)",
    )
    p.add_argument(
        "--azimuth-direction",
        choices=("east", "west"),
        default="east",
        help="on which side the file's azimuth 90 lies (east: TPOINT's convention); north,east is "
        "the common north-through-east azimuth (converted as 180 - az)",
    )
    p.add_argument(
        "--write-urdf",
        type=Path,
        metavar="OUT.urdf",
        help="write the mount's URDF the CSV belongs to (required for an equatorial run: a copy "
        "of the bundled one with its polar axis tilted to the run's latitude; default: none)",
    )
    p.set_defaults(func=run_import_tpoint)


def run_import_tpoint(args: argparse.Namespace) -> int:
    import dataclasses

    from ..measurement.tpoint import EQUATORIAL, convert_tpoint, read_tpoint

    urdf_out = args.write_urdf  # never an input nor -o: the commands' shared output guard
    run = read_tpoint(
        args.data,
        mount=args.mount,
        azimuth_origin=args.azimuth_origin,
        azimuth_direction=args.azimuth_direction,
    )
    if run.mount == EQUATORIAL and urdf_out is None:
        raise InputError(
            f"{args.data}: an equatorial run needs --write-urdf OUT.urdf: the rows belong to a "
            "copy of models/german_equatorial_mount.urdf tilted to the run's latitude"
        )
    conversion = convert_tpoint(run, refraction=args.refraction, latitude_deg=args.latitude_deg)
    if urdf_out is not None:
        conversion = dataclasses.replace(conversion, urdf_written=str(urdf_out))
    csv_path = conversion.write_csv(args.output)
    urdf_path = conversion.write_urdf(urdf_out) if urdf_out is not None else None

    where = f" ({', '.join(': ' + o for o in run.options)})" if run.options else ""
    print(
        f"read {args.data}: {run.n_stars} stars, {run.mount} mount{where}, latitude "
        f"{run.latitude_deg:+.6f} deg"
        + (f" (polar axis at {conversion.latitude_deg:+.6f} deg)" if args.latitude_deg else "")
    )
    if conversion.refraction == "apply":
        r = conversion.refraction_arcsec
        print(
            f"refraction: applied (Saemundsson, {run.run_parameters['temperature_c']:g} C, "
            f"{run.run_parameters['pressure_mbar']:g} mbar): {r.min():.2f} to {r.max():.2f} "
            "arcsec added to the observed elevations"
        )
    else:
        print("refraction: none (the observed positions used as given)")
    first = "azimuth, elevation" if run.mount != EQUATORIAL else "hour angle, declination"
    print(
        f"wrote {csv_path}: {run.n_stars} rows; phi1_deg, phi2_deg = raw {first}; dpsi_arcsec, "
        "dtheta_arcsec measured, dgamma_arcsec empty (roll not measured)"
    )
    urdf = urdf_path or f"models/{conversion.urdf_name}"
    if urdf_path is not None:
        print(f"wrote {urdf_path}")
    print(f"next: turntable-pin diagnose {csv_path} --urdf {urdf}")
    return 0
