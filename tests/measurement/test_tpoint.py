"""TPOINT runs in (measurement/tpoint.py): parsing, the conversion's conventions against an
independent reading of the mount URDFs' frames, round trips exact to rounding, wrapped azimuths,
refraction, the tilted equatorial URDF, the bundled MMT run and bad files."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import EXAMPLES_DIR, write_file
from rounding import chain_rounding
from turntable_pin.core.exceptions import InputError
from turntable_pin.core.rotations import rot_x, rot_y, rot_z
from turntable_pin.core.units import ARCSEC_PER_RAD
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.tpoint import (
    ALTAZ,
    EQUATORIAL,
    convert_tpoint,
    mount_urdf_text,
    read_tpoint,
    saemundsson_refraction_arcsec,
)
from turntable_pin.model.generic_table import GenericTable

MMT = EXAMPLES_DIR / "mmt_pointing" / "k_and_e.dat"
HEADER = "! a synthetic run\nSynthetic run\n: ALTAZ\n+31 41 19.6 2021 8 21 13.0 741 2608.0 0.75\n"
S = 1.0 / ARCSEC_PER_RAD


def trip_arcsec(largest_deg, chains, truth=0, highest_el_deg=0.0):
    """How far a round trip through a run's angles may be from the truth, arcsec (rounding only):
    each angle (up to ``largest_deg``) rounds by an ulp in each of about four conversions; angles
    read off a truth of ``truth`` rotations (arcsin, arctan2 of its boresight) carry its rounding
    over cos(el), their condition number; each chain of ``chains`` rotations rounds dR's entries."""
    read = chain_rounding(truth) / np.cos(np.radians(highest_el_deg)) if truth else 0.0
    angles = 4 * np.spacing(np.radians(largest_deg)) + read
    return (angles + sum(chain_rounding(n) for n in chains)) * ARCSEC_PER_RAD


def altaz_rd(az, el):
    """The alt-az URDF's nominal chain written out from its header: Rz(az) R_{-y}(el)."""
    return rot_z(az) @ rot_y(-np.asarray(el))


def equatorial_rd(ha, dec, latitude_deg):
    """The German-equatorial URDF's chain: Ry(lat - 90) Rz(-ha) R_{-y}(dec)."""
    return (
        rot_y(math.radians(latitude_deg - 90.0)) @ rot_z(-np.asarray(ha)) @ rot_y(-np.asarray(dec))
    )


def azel_of(rotation):
    """Azimuth (South = 0, East = 90) and elevation (deg) of a rotation's boresight (x axis)."""
    v = rotation[..., :, 0]
    return np.degrees(np.arctan2(v[..., 1], v[..., 0])), np.degrees(np.arcsin(v[..., 2]))


def altaz_file(folder, observed, raw, header=HEADER, name="run.dat"):
    lines = [" ".join(repr(float(x)) for x in (*o, *r)) for o, r in zip(observed, raw, strict=True)]
    return write_file(folder, header + "\n".join(lines) + "\n", name)


def _dms(value, hours=False):
    sign = "-" if value < 0 else "+"
    value = abs(float(value)) / (15.0 if hours else 1.0)
    d = math.floor(value)
    m = math.floor((value - d) * 60.0)
    s = (value - d - m / 60.0) * 3600.0
    return ("" if hours else sign) + f"{d} {m} {s!r}"


def equatorial_file(folder, observed, raw, lst_deg, latitude="+45 45 00", name="eq.dat"):
    """Equatorial records: RA = LST - HA (hours), sidereal time h m."""
    h = math.floor(lst_deg / 15.0)
    m = float((lst_deg / 15.0 - h) * 60.0)
    lst = (h + m / 60.0) * 15.0
    rows = []
    for (ha, dec), (ha_r, dec_r) in zip(observed, raw, strict=True):
        rows.append(f"{_dms((lst - ha) % 360.0, True)}  {_dms(dec)}  "
                    f"{_dms((lst - ha_r) % 360.0, True)}  {_dms(dec_r)}  {h} {m!r}")  # fmt: skip
    text = f"Equatorial run\n: EQUAT\n: NODA\n{latitude} 2024 3 1 10.0 1000.0 100.0 0.5\n"
    return write_file(folder, text + "\n".join(rows) + "\nEND\n", name)


# --- the conventions, against the URDFs' headers ------------------------------------------------
def test_the_chain_is_the_one_the_urdf_headers_describe():
    rng = np.random.default_rng(1)
    q = np.radians(rng.uniform(-180, 180, (2, 20)))
    for mount, rd in ((ALTAZ, altaz_rd), (EQUATORIAL, lambda a, b: equatorial_rd(a, b, 31.5))):
        import tempfile
        from pathlib import Path

        from turntable_pin.model.chain import compose_rotation

        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "m.urdf"
            path.write_text(mount_urdf_text(mount, 31.5))
            placements = GenericTable(path).chain.placements()
        assert np.allclose(compose_rotation(placements, list(q)), rd(*q), atol=1e-14)


def test_tilted_urdf_points_the_polar_axis_at_the_pole_and_keeps_the_comments():
    text = mount_urdf_text(EQUATORIAL, -33.8, note="Written for x.dat.")
    assert "x South, y East, z up" in text and "Copy tilted to latitude -33.8 deg" in text
    import tempfile
    from pathlib import Path

    from turntable_pin.model.chain import compose_rotation

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "m.urdf"
        path.write_text(text)
        placements = GenericTable(path).chain.placements()
    boresight = compose_rotation(placements, [0.3, math.pi / 2])[:, 0]
    lat = math.radians(-33.8)  # the north celestial pole: North (-x), altitude = latitude
    assert np.allclose(boresight, [-math.cos(lat), 0.0, math.sin(lat)], atol=1e-14)
    assert mount_urdf_text(ALTAZ) == (EXAMPLES_DIR.parent / "altaz_mount.urdf").read_text()


# --- round trips ---------------------------------------------------------------------------------
def _altaz_round_trip(tmp_path, raw_deg, rt, wrap=0.0):
    """Write the file for true orientations ``rt`` at ``raw_deg``, import, return (conv, dR)."""
    az, el = azel_of(rt)
    observed = np.c_[az + wrap, el]
    path = altaz_file(tmp_path, observed, raw_deg)
    conv = convert_tpoint(read_tpoint(path))
    d_r = np.swapaxes(altaz_rd(*np.radians(raw_deg.T)), -1, -2) @ rt
    return conv, d_r


def test_altaz_round_trip_is_exact_for_orientations_the_nominal_chain_reaches(tmp_path):
    rng = np.random.default_rng(7)
    raw = np.c_[rng.uniform(-270, 450, 40), rng.uniform(3, 87, 40)]
    obs = np.radians(raw) + rng.uniform(-1500, 1500, (40, 2)) * S
    rt = altaz_rd(obs[:, 0], obs[:, 1])  # a roll-free truth: the chain at the observed angles
    conv, d_r = _altaz_round_trip(tmp_path, raw, rt, wrap=360.0)
    # angles up to 810 deg, read off a truth of 2 rotations up to 87.4 deg; the importer's dR of
    # 12 rotations, the test's of 4
    trip = trip_arcsec(810.0, (12, 4), truth=2, highest_el_deg=87.0 + 1500 / 3600)
    assert np.abs(conv.dtheta_arcsec - d_r[:, 1, 0] * ARCSEC_PER_RAD).max() < trip
    assert np.abs(conv.dpsi_arcsec + d_r[:, 2, 0] * ARCSEC_PER_RAD).max() < trip
    assert np.array_equal(conv.phi_deg, raw)
    # first order: dtheta ~ dA cos E, dpsi ~ -dE
    d_a = (obs[:, 0] - np.radians(raw[:, 0])) * ARCSEC_PER_RAD
    d_e = (obs[:, 1] - np.radians(raw[:, 1])) * ARCSEC_PER_RAD
    second = 2.0 * (np.abs(d_a) + np.abs(d_e)) ** 2 / ARCSEC_PER_RAD * (1 + np.tan(obs[:, 1]))
    assert np.all(np.abs(conv.dtheta_arcsec - d_a * np.cos(np.radians(raw[:, 1]))) < second)
    assert np.all(np.abs(conv.dpsi_arcsec + d_e) < second)


def test_a_roll_the_run_cannot_see_changes_neither_angle(tmp_path):
    # dpsi and dtheta are the boresight's own components (the swing of dR): a roll about the
    # boresight, which a pointing run cannot see, leaves both exact
    rng = np.random.default_rng(8)
    raw = np.c_[rng.uniform(-180, 180, 30), rng.uniform(10, 80, 30)]
    obs = np.radians(raw) + rng.uniform(-1200, 1200, (30, 2)) * S
    roll = rng.uniform(-150, 150, 30) * S
    rt = altaz_rd(obs[:, 0], obs[:, 1]) @ rot_x(roll)
    conv, d_r = _altaz_round_trip(tmp_path, raw, rt)
    trip = trip_arcsec(181.0, (12, 5), truth=3, highest_el_deg=80.0 + 1200 / 3600)
    assert np.abs(conv.dtheta_arcsec - d_r[:, 1, 0] * ARCSEC_PER_RAD).max() < trip
    assert np.abs(conv.dpsi_arcsec + d_r[:, 2, 0] * ARCSEC_PER_RAD).max() < trip
    # ... while the whole rotation's entry (0, 2) moves with the roll (second order)
    assert np.abs(conv.dpsi_arcsec - d_r[:, 0, 2] * ARCSEC_PER_RAD).max() > 1e-2


@given(
    az=st.floats(-359.0, 359.0),
    el=st.floats(2.0, 88.0),
    d_a=st.floats(-3000.0, 3000.0),
    d_e=st.floats(-3000.0, 3000.0),
    turns=st.integers(-1, 1),
    raw_turns=st.integers(-1, 1),
)
def test_property_wrapped_azimuths_are_differences_on_the_circle(
    tmp_path_factory, az, el, d_a, d_e, turns, raw_turns
):
    folder = tmp_path_factory.mktemp("prop")
    raw = np.array([[az + 360.0 * raw_turns, el]])
    obs = np.array([[az + d_a / 3600.0 + 360.0 * turns, el + d_e / 3600.0]])
    conv = convert_tpoint(read_tpoint(altaz_file(folder, obs, raw)))
    d_r = np.swapaxes(altaz_rd(*np.radians(raw.T)), -1, -2) @ altaz_rd(*np.radians(obs.T))
    trip = trip_arcsec(721.0, (12, 4))  # the file's angles are the truth's, up to 721 deg
    assert abs(conv.dtheta_arcsec[0] - d_r[0, 1, 0] * ARCSEC_PER_RAD) < trip
    assert abs(conv.dpsi_arcsec[0] + d_r[0, 2, 0] * ARCSEC_PER_RAD) < trip
    second = 2.0 * (abs(d_a) + abs(d_e)) ** 2 / ARCSEC_PER_RAD * (1 + math.tan(math.radians(el)))
    assert abs(conv.dtheta_arcsec[0] - d_a * math.cos(math.radians(el))) <= second + trip
    assert abs(conv.dpsi_arcsec[0] + d_e) <= second + trip


def test_equatorial_round_trip_and_signs(tmp_path):
    rng = np.random.default_rng(9)
    raw = np.c_[rng.uniform(-80, 80, 25), rng.uniform(-60, 85, 25)]
    obs = raw + rng.uniform(-900, 900, (25, 2)) / 3600.0
    path = equatorial_file(tmp_path, obs, raw, lst_deg=123.456)
    run = read_tpoint(path)
    assert run.mount == EQUATORIAL and run.options == ("EQUAT", "NODA")
    assert np.allclose(run.raw_deg, raw, atol=1e-9) and np.allclose(
        run.observed_deg, obs, atol=1e-9
    )
    conv = convert_tpoint(run, refraction="none")
    lat = run.latitude_deg
    o, r = np.radians(run.observed_deg.T), np.radians(run.raw_deg.T)
    d_r = np.swapaxes(equatorial_rd(*r, lat), -1, -2) @ equatorial_rd(*o, lat)
    assert np.abs(conv.dtheta_arcsec - d_r[:, 1, 0] * ARCSEC_PER_RAD).max() < 1e-9
    assert np.abs(conv.dpsi_arcsec + d_r[:, 2, 0] * ARCSEC_PER_RAD).max() < 1e-9
    d_h = (obs[:, 0] - raw[:, 0]) * 3600.0
    assert np.allclose(conv.dtheta_arcsec, -d_h * np.cos(np.radians(raw[:, 1])), rtol=0.03, atol=2)
    assert np.allclose(conv.dpsi_arcsec, -(obs[:, 1] - raw[:, 1]) * 3600.0, rtol=0.03, atol=2)
    assert 'rpy="0 ' in conv.urdf_text and f"{lat!r}" in conv.urdf_text


def test_equatorial_refraction_lifts_the_boresight_by_saemundsson(tmp_path):
    raw = np.array([[-30.0, 20.0], [20.0, 60.0], [40.0, 40.0]])
    path = equatorial_file(tmp_path, raw + 0.01, raw, lst_deg=50.0, latitude="+45 45 00")
    run = read_tpoint(path)
    assert run.run_parameters["temperature_c"] == 10.0
    refracted = convert_tpoint(run)  # the default of an equatorial file: apply
    assert (
        refracted.refraction == "apply"
        and convert_tpoint(run, refraction="none").refraction == "none"
    )
    lat = run.latitude_deg
    before = equatorial_rd(*np.radians(run.observed_deg.T), lat)
    v = before[:, :, 0]
    el = np.arcsin(v[:, 2])
    r = saemundsson_refraction_arcsec(np.degrees(el), 10.0, 1000.0)
    assert np.allclose(refracted.refraction_arcsec, r, atol=1e-9) and r.min() > 10.0
    # the lifted boresight, turned back into hour angle and declination by hand
    across = np.array([0.0, 0.0, 1.0]) - v[:, 2:3] * v
    across /= np.linalg.norm(across, axis=1, keepdims=True)
    lifted = np.cos(r * S)[:, None] * v + np.sin(r * S)[:, None] * across
    w = lifted @ rot_y(math.radians(lat - 90.0))  # = B^T v for each row
    dec, ha = np.arcsin(w[:, 2]), np.arctan2(-w[:, 1], w[:, 0])
    assert np.allclose(np.degrees(np.arcsin(lifted[:, 2]) - el) * 3600.0, r, atol=1e-9)
    d_r = np.swapaxes(equatorial_rd(*np.radians(run.raw_deg.T), lat), -1, -2) @ equatorial_rd(
        ha, dec, lat
    )
    assert np.abs(refracted.dtheta_arcsec - d_r[:, 1, 0] * ARCSEC_PER_RAD).max() < 1e-6
    assert np.abs(refracted.dpsi_arcsec + d_r[:, 2, 0] * ARCSEC_PER_RAD).max() < 1e-6


def test_altaz_refraction_adds_saemundsson_to_the_observed_elevation(tmp_path):
    raw = np.array([[10.0, 20.0], [200.0, 45.0], [-100.0, 80.0]])
    obs = raw + 0.005
    conv = convert_tpoint(read_tpoint(altaz_file(tmp_path, obs, raw)), refraction="apply")
    r = saemundsson_refraction_arcsec(obs[:, 1], 13.0, 741.0)
    lifted = altaz_rd(np.radians(obs[:, 0]), np.radians(obs[:, 1]) + r * S)
    d_r = np.swapaxes(altaz_rd(*np.radians(raw.T)), -1, -2) @ lifted
    assert np.abs(conv.dpsi_arcsec + d_r[:, 2, 0] * ARCSEC_PER_RAD).max() < 1e-6
    assert np.abs(conv.dtheta_arcsec - d_r[:, 1, 0] * ARCSEC_PER_RAD).max() < 1e-6
    # Saemundsson's scale: about 1 arcmin at 45 deg, nothing at the zenith
    assert saemundsson_refraction_arcsec(45.0, 10.0, 1010.0) == pytest.approx(60.0, abs=1.5)
    assert abs(saemundsson_refraction_arcsec(90.0, 10.0, 1010.0)) < 0.2


def test_north_based_azimuths_are_converted(tmp_path):
    raw = np.array([[10.0, 20.0], [200.0, 45.0], [-100.0, 70.0]])
    obs = raw + [0.01, -0.002]
    south = convert_tpoint(read_tpoint(altaz_file(tmp_path, obs, raw, name="s.dat")))
    header = HEADER.replace("! a synthetic run", "! azimuth North = 0, East = 90")
    north = altaz_file(
        tmp_path, np.c_[180.0 - obs[:, 0], obs[:, 1]], np.c_[180.0 - raw[:, 0], raw[:, 1]],
        header=header, name="n.dat",
    )  # fmt: skip
    with pytest.raises(InputError, match=r"line 1: .*'North = 0'.*azimuth_origin north"):
        read_tpoint(north)
    converted = convert_tpoint(read_tpoint(north, azimuth_origin="north"))
    assert np.allclose(converted.dtheta_arcsec, south.dtheta_arcsec, atol=1e-9)
    assert np.allclose(converted.dpsi_arcsec, south.dpsi_arcsec, atol=1e-9)
    right = altaz_file(tmp_path, obs + [180.0, 0], raw + [180.0, 0], name="r.dat")
    rh = convert_tpoint(read_tpoint(right, azimuth_origin="north", azimuth_direction="west"))
    assert np.allclose(rh.dtheta_arcsec, south.dtheta_arcsec, atol=1e-9)


# --- the bundled MMT run -------------------------------------------------------------------------
@pytest.fixture(scope="module")
def mmt():
    return convert_tpoint(read_tpoint(MMT))


def _eight_term_fit(conv):
    """TPOINT's eight alt-az formulas fitted to the CSV's two angles: (terms, rms arcsec)."""
    a, e = np.radians(conv.phi_deg.T)
    one, zero = np.ones_like(a), np.zeros_like(a)
    on_sky = np.c_[-np.cos(e), zero, -np.sin(e), -one, -np.sin(a) * np.sin(e),
                   -np.cos(a) * np.sin(e), zero, zero]  # fmt: skip
    elev = np.c_[zero, one, zero, zero, -np.cos(a), np.sin(a), -np.cos(e), -1.0 / np.tan(e)]
    x = np.r_[on_sky, elev]
    y = np.r_[conv.dtheta_arcsec, -conv.dpsi_arcsec]
    p = np.linalg.lstsq(x, y, rcond=None)[0]
    return dict(zip("IA IE NPAE CA AN AW TF TX".split(), p, strict=True)), np.sqrt(
        np.mean((y - x @ p) ** 2)
    )


def test_mmt_run_reads_back_and_reproduces_the_published_fit(mmt, tmp_path):
    assert mmt.run.n_stars == 80 and mmt.refraction == "none" and mmt.run.mount == ALTAZ
    assert mmt.run.latitude_deg == pytest.approx(31 + 41 / 60 + 19.6 / 3600)
    csv = mmt.write_csv(tmp_path / "mmt.csv")
    data = read_measurements(csv, ("azimuth", "elevation"))
    assert data.n_positions == 80 and not data.extra
    text = csv.read_text()
    assert "# refraction: none" in text and "source lines of the rows, in order: 21-100" in text
    terms, rms = _eight_term_fit(mmt)
    assert rms == pytest.approx(0.66, abs=0.02)  # published 0.66 arcsec
    for name, published in (("IA", 1209.26), ("NPAE", -3.47), ("CA", -5.95), ("AW", -10.33)):
        assert terms[name] == pytest.approx(published, abs=0.2)
    refracted = convert_tpoint(mmt.run, refraction="apply")
    terms_r, _ = _eight_term_fit(refracted)
    assert terms_r["TX"] < -40.0  # refraction applied twice shows as a cot(el) term


def test_mmt_rigid_mount_is_seen_exactly_whatever_its_roll(mmt):
    # a rigid mount with the published geometric terms rolls the tube by up to ~140 arcsec near
    # the zenith; the swing the importer writes is the boresight's and does not see it
    a, e = np.radians(mmt.phi_deg.T)
    ia, an, aw, npae, ca = -1209.26 * S, 2.50 * S, -10.33 * S, -3.47 * S, -5.95 * S
    rt = rot_x(aw) @ rot_y(an) @ rot_z(a - ia) @ rot_x(npae) @ rot_y(-e) @ rot_z(ca)
    az, el = azel_of(rt)
    true = np.swapaxes(altaz_rd(a, e), -1, -2) @ rt
    seen = np.swapaxes(altaz_rd(a, e), -1, -2) @ altaz_rd(np.radians(az), np.radians(el))
    trip = trip_arcsec(181.0, (8, 4), truth=6, highest_el_deg=float(el.max()))
    assert np.abs(seen[:, 1, 0] - true[:, 1, 0]).max() * ARCSEC_PER_RAD < trip
    assert np.abs(seen[:, 2, 0] - true[:, 2, 0]).max() * ARCSEC_PER_RAD < trip
    # the whole rotation's entry (0, 2) would have carried the roll: 0.04-0.1 arcsec rms
    twist = (seen[:, 0, 2] - true[:, 0, 2]) * ARCSEC_PER_RAD
    assert 0.01 < np.sqrt(np.mean(twist**2)) < 0.15


# --- bad files -----------------------------------------------------------------------------------
BAD = {
    "unknown option": (HEADER.replace(": ALTAZ", ": ALTAZ\n: GIMBAL"), "line 4: unknown option"),
    "mount contradiction": (HEADER.replace(": ALTAZ", ": ALTAZ\n: EQUAT"), "line 4: ': EQUAT'"),
    "j2000": (HEADER.replace(": ALTAZ", ": ALTAZ\n:J2000"), "line 4: ': J2000'"),
    "missing field": (HEADER + "1 2 3\n", "line 5: expected 4 numbers"),
    "not a number": (HEADER + "1 2 3 x\n", "line 5: data: 'x' is not a number"),
    "no run parameters": (HEADER.split("+31")[0] + "1 2 3 4\n", "line 4: expected the run-param"),
    "no data": (HEADER, "no data lines"),
    "empty": ("! nothing\n", "no caption line"),
    "no mount": (HEADER.replace(": ALTAZ\n", ""), "line 3: the file states no mount"),
    "bad minutes": (HEADER.replace("41 19.6", "61 19.6") + "1 2 3 4\n", "line 4: latitude"),
    "far apart": (HEADER + "10 20 60 20\n", "line 5: the observed and raw positions are"),
    "elevation": (HEADER + "10 95 10 20\n", "line 5: observed elevation 95"),
    "option late": (HEADER + "1 2 1 2\n: NODA\n", "line 6: option line"),
    # issue 27: the CSV would hold one position twice, which fit and diagnose refuse
    "copied line": (HEADER + "1 2 1.01 2\n3 4 3 4\n1 2 1.01 2\n",
                    "lines 5 and 7 are the same star at the same raw position"),
    "same raw position": (HEADER + "1 2 1.01 2\n3 4 3 4\n1.02 2 1.01 2\n",
                          "lines 5 and 7 have the same raw position (azimuth, elevation)"),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_files_are_refused_naming_the_line(case, tmp_path):
    text, fragment = BAD[case]
    path = write_file(tmp_path, text, "bad.dat")
    with pytest.raises(InputError) as info:
        convert_tpoint(read_tpoint(path))
    assert fragment in str(info.value) and str(path) in str(info.value)
    assert "\n" not in str(info.value)


def test_repeated_raw_positions_are_refused_by_the_rule_the_measurement_reader_applies(tmp_path):
    """The import compares raw positions as the reader compares the CSV's phi columns (to
    1e-9 deg): what it writes, fit and diagnose read; what it refuses, they would refuse."""
    for delta, refused in ((4e-10, True), (2e-9, False)):
        text = HEADER + f"1 2 1.01 2\n3 4 3 4\n1 2 {1.01 + delta!r} 2\n"
        run = read_tpoint(write_file(tmp_path, text, "run.dat"))
        if refused:
            with pytest.raises(InputError, match="lines 5 and 7 are the same star"):
                convert_tpoint(run)
            continue
        out = convert_tpoint(run).write_csv(tmp_path / "run.csv")
        assert read_measurements(out, ("azimuth", "elevation")).n_positions == 3


def test_mount_option_contradicting_the_file_and_refraction_without_weather(tmp_path):
    path = write_file(tmp_path, HEADER + "1 2 1 2\n", "run.dat")
    with pytest.raises(InputError, match="line 3: the file states an altaz mount"):
        read_tpoint(path, mount=EQUATORIAL)
    bare = write_file(tmp_path, HEADER.replace(" 2021 8 21 13.0 741 2608.0 0.75", "") + "1 2 1 2\n")
    run = read_tpoint(bare)
    assert run.run_parameters == {}
    with pytest.raises(InputError, match="needs the temperature and pressure"):
        convert_tpoint(run, refraction="apply")
    south = write_file(
        tmp_path, HEADER.replace("+31", "-00").replace("41 19.6", "30 0") + "1 2 1 2\n"
    )
    assert read_tpoint(south).latitude_deg == -0.5
