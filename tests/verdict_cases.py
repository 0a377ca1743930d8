"""The cases of issue 29's verdict rates, defined once: simulated calibration runs and orientation
sets with several simple causes, a true many-parameter effect, or nothing; the two real pointing
runs; and how a verdict is scored against what was planted.

Used by ``benchmarks/verdict_rates.py`` (the rates over many seeds) and by
``tests/stats/test_verdict_rates.py`` (a few seeds each). Everything runs in-process through the
Python API, with ``until_explained`` (every accepted effect is named, as ``--until-explained``).

Sizes follow the bundled examples: a run is the paper's table on ``grid:30`` (144 positions),
latitude 45.75 deg, noise 0.002 deg/h on both channels (given as ``sigma_dph``), 120 s per
position (``models/examples/runs/make_runs.sh``); an orientation set is the paper's table with
the errors of ``models/examples/errors_example.yaml``, the default 30-degree grid (144 positions,
60 s apart, each axis approached from a random side) and 1 arcsec noise
(``measurements_example.csv``). Amplitudes are the issue's (runs) or a few times the noise
(orientation sets), each named in the case's title. The issue's "orthogonality, intersection and
heading error" of R1 are ``deps_y``, ``dalpha_x1`` and the GyroWheel's heading ``mz``: the
paper's intersection error ``deta`` is a length that turns nothing a gyro senses, and the three
chosen lie in three different confounded groups (``deps_y``/``dphi_y1``,
``dalpha_x1``/``deps_x``, ``instrument_heading``/``dalpha_z1``/``dphi_z2``), so three causes
can be told apart at all. R1 puts the heading at 45", where on top of the other two it is at the
run's detection limit; R1b puts it at 60".

Scoring (:func:`score`): a named effect stands for its *group*, itself and the effects the verdict
lists as explaining the data equally well (the first effect's ``alternatives``; for a later step
the candidate's own ``alternatives``). Several simple causes are *named as such* when the named
effects and the planted ones pair off one to one, each named effect's group holding its planted
effect and the named effect having no more parameters than the planted one (a wobble named for
a single error is not the single error named). A true many-parameter effect is *named* when a
named effect is it, or holds it in its group with at least as many parameters. On clean data any
named effect is a false name. A named effect that the candidate table marks implausible is
counted apart. An implausible amplitude is handled right when the candidate table marks the
planted effect implausible and the verdict names neither it nor any other effect so marked.
"""

from __future__ import annotations

import itertools
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from turntable_pin import TurntableErrors
from turntable_pin.calibration.positions import PositionSet, position_inputs
from turntable_pin.calibration.run import CalibrationRun
from turntable_pin.core.units import arcsec_to_rad

ROOT = Path(__file__).resolve().parents[1]
MMT_RUN = ROOT / "models" / "examples" / "mmt_pointing" / "k_and_e.dat"
GEM_RUN = ROOT / "models" / "examples" / "gem_pointing" / "gem-28.dat"

RUN_LATITUDE_DEG = 45.75
"""Latitude of the simulated calibration runs, deg (the bundled runs')."""
RUN_NOISE_DPH = 0.002
"""1-sigma noise of both run channels, deg/h (the bundled runs')."""
RUN_DWELL_S = 120.0
"""Time per run position, s (the bundled runs')."""
ORIENTATION_NOISE_ARCSEC = 1.0
"""1-sigma noise of every measured angle, arcsec (``measurements_example.csv``)."""
EXAMPLE_ERRORS_ARCSEC = {
    "dphi_y1": 2.0, "dphi_z2": -1.5, "dalpha_x1": 3.0, "dalpha_z1": -2.5, "dalpha_x2": 1.8,
    "dalpha_y2": -2.2, "deps_x": 4.0, "deps_y": -3.0,
}  # fmt: skip
"""The table errors of ``models/examples/errors_example.yaml`` (with ``deta`` 0.2 mm), arcsec."""
TEMPERATURE_PROFILE = (20.0, 1.0, 2.5, 3.0)
"""``start_c, ramp_c_per_h, swing_c, period_h`` of the runs with a temperature column (the
bundled ``run_temperature``'s ``--temperature 20,1,2.5,3``)."""

SIMPLE, MANY, CLEAN, IMPLAUSIBLE = "simple", "many", "clean", "implausible"
"""What a case plants: several simple causes, one true many-parameter effect, nothing, or one
effect at an amplitude no mechanism of its kind reaches on a precision turntable."""


@dataclass(frozen=True)
class Case:
    """One simulated design of the rates.

    Attributes:
        name: short label (``R1``..``R6`` runs, ``O1``..``O6`` orientation sets, ``I1``, ``I2``
            implausible amplitudes).
        diagnosis: ``run`` (calibration run) or ``orientation``.
        kind: :data:`SIMPLE`, :data:`MANY`, :data:`CLEAN` or :data:`IMPLAUSIBLE`.
        title: what is planted, with its amplitudes.
        planted: the catalogue names of the planted causes.
        table_errors_arcsec: planted table errors (runs), arcsec.
        effects: planted effects ``{effect: {parameter: value in its user unit}}`` (table effects
            of a run by their table name, without ``table:``).
        instrument: planted instrument effects of a run, in their units.
        temperature: whether the run has a temperature column (``TEMPERATURE_PROFILE``).
    """

    name: str
    diagnosis: str
    kind: str
    title: str
    planted: tuple[str, ...] = ()
    table_errors_arcsec: dict[str, float] = field(default_factory=dict)
    effects: dict[str, dict[str, float]] = field(default_factory=dict)
    instrument: dict[str, dict[str, float]] = field(default_factory=dict)
    temperature: bool = False

    def simulate(self, seed: int):
        """The simulated data of this case at ``seed``: a ``CalibrationRun`` or the
        ``OrientationMeasurements``."""
        return _simulate_run(self, seed) if self.diagnosis == "run" else _simulate_set(self, seed)

    def diagnose(self, data) -> dict:
        """The diagnosis JSON (``Diagnosis.to_dict``) of ``data``, every accepted effect named."""
        if self.diagnosis == "run":
            from turntable_pin.instrument.diagnosis import diagnose_run

            return diagnose_run(data, until_explained=True).to_dict()
        from turntable_pin.measurement.diagnosis import diagnose_measurements

        return diagnose_measurements(data, until_explained=True).to_dict()


def _simulate_run(case: Case, seed: int) -> CalibrationRun:
    from turntable_pin.instrument.simulate import TemperatureProfile, simulate_calibration_run

    positions = PositionSet.grid(30)
    latitude_rad = np.radians(RUN_LATITUDE_DEG)
    sim = simulate_calibration_run(
        positions,
        latitude_rad,
        table_errors_rad={k: arcsec_to_rad(v) for k, v in case.table_errors_arcsec.items()},
        table_effects=case.effects,
        instrument=case.instrument,
        noise_dph=(RUN_NOISE_DPH, RUN_NOISE_DPH),
        dwell_s=RUN_DWELL_S,
        temperature_c=TemperatureProfile(*TEMPERATURE_PROFILE) if case.temperature else None,
        seed=seed,
    )
    extra = {} if sim.temperature_c is None else {"temperature_c": sim.temperature_c}
    return CalibrationRun(
        position_inputs(positions, latitude_rad),
        sim.outputs_dph,
        np.full(len(positions), RUN_NOISE_DPH),
        sim.time_s,
        extra,
    )


def _simulate_set(case: Case, seed: int):
    from turntable_pin.measurement.simulation import simulate_measurements

    errors = TurntableErrors.from_arcsec(**EXAMPLE_ERRORS_ARCSEC, deta_mm=0.2)
    return simulate_measurements(
        errors, case.effects, noise_arcsec=ORIENTATION_NOISE_ARCSEC, seed=seed
    ).data


BACKLASH = {"b1": 2.0, "b2": -1.5}
CASES: tuple[Case, ...] = (
    Case("R1", "run", SIMPLE,
         "three table singles: orthogonality deps_y 55\", outer-axis tilt at the intersection "
         "dalpha_x1 50\", heading mz 45\"",
         ("table:deps_y", "table:dalpha_x1", "instrument_heading"),
         table_errors_arcsec={"deps_y": 55.0, "dalpha_x1": 50.0},
         instrument={"instrument_heading": {"mz": 45.0}}),
    Case("R1b", "run", SIMPLE,
         "R1's singles with the heading at the top of the issue's range: deps_y 45\", "
         "dalpha_x1 50\", heading mz 60\"",
         ("table:deps_y", "table:dalpha_x1", "instrument_heading"),
         table_errors_arcsec={"deps_y": 45.0, "dalpha_x1": 50.0},
         instrument={"instrument_heading": {"mz": 60.0}}),
    Case("R2", "run", SIMPLE, "two table singles: deps_x 70\", dalpha_z1 60\"",
         ("table:deps_x", "table:dalpha_z1"),
         table_errors_arcsec={"deps_x": 70.0, "dalpha_z1": 60.0}),
    Case("R3", "run", SIMPLE, "table deps_x 60\" + bias drift x 0.004, y -0.003 deg/h/h",
         ("table:deps_x", "bias_drift"), table_errors_arcsec={"deps_x": 60.0},
         instrument={"bias_drift": {"x": 0.004, "y": -0.003}}),
    Case("R4", "run", SIMPLE,
         "g^2 term x_xz 0.03 deg/h/g^2 + temperature coefficient x 0.003 deg/h/degC",
         ("g_squared_terms", "temperature_coefficient"),
         instrument={"g_squared_terms": {"x_xz": 0.03},
                     "temperature_coefficient": {"x": 0.003}},
         temperature=True),
    Case("R5", "run", MANY, "inner-axis wobble x_c1 60\", y_s2 -30\"",
         ("table:inner_wobble_harmonics",),
         effects={"inner_wobble_harmonics": {"x_c1": 60.0, "y_s2": -30.0}}),
    Case("R6", "run", CLEAN, "clean run"),
    Case("O1", "orientation", SIMPLE, "gravity sag k 3\"/g + backlash b1 2\", b2 -1.5\"",
         ("gravity_sag", "backlash"), effects={"gravity_sag": {"k": 3.0}, "backlash": BACKLASH}),
    Case("O2", "orientation", SIMPLE, "thermal drift rz 4\"/h + backlash b1 2\", b2 -1.5\"",
         ("thermal_drift", "backlash"),
         effects={"thermal_drift": {"rz": 4.0}, "backlash": BACKLASH}),
    Case("O3", "orientation", SIMPLE, "base tilt tx 3\", tz -2\" + backlash b1 2\", b2 -1.5\"",
         ("base_tilt", "backlash"),
         effects={"base_tilt": {"tx": 3.0, "tz": -2.0}, "backlash": BACKLASH}),
    Case("O4", "orientation", SIMPLE, "gravity sag k 3\"/g + thermal drift rz 4\"/h",
         ("gravity_sag", "thermal_drift"),
         effects={"gravity_sag": {"k": 3.0}, "thermal_drift": {"rz": 4.0}}),
    Case("O5", "orientation", MANY, "inner encoder harmonics c1 3\", s1 -1.5\", s2 2\"",
         ("inner_encoder_harmonics",),
         effects={"inner_encoder_harmonics": {"c1": 3.0, "s1": -1.5, "s2": 2.0}}),
    Case("O6", "orientation", CLEAN, "clean set (the example's table errors only)"),
    Case("I1", "run", IMPLAUSIBLE, "inner-axis wobble x_c1 1800\" (half a degree)",
         ("table:inner_wobble_harmonics",),
         effects={"inner_wobble_harmonics": {"x_c1": 1800.0}}),
    Case("I2", "orientation", IMPLAUSIBLE,
         "inner encoder eccentricity c1 1800\" (half a degree)", ("inner_encoder_harmonics",),
         effects={"inner_encoder_harmonics": {"c1": 1800.0}}),
)  # fmt: skip
"""Every simulated case: runs, orientation sets, then the two implausible amplitudes."""
CASES_BY_NAME = {c.name: c for c in CASES}


# --- scoring -------------------------------------------------------------------------------------
def _candidate(d: dict, name: str) -> dict:
    return next((c for c in d["candidates"] if c["effect"] == name), {})


def n_parameters(d: dict, name: str) -> int:
    """Parameters of effect ``name`` in diagnosis ``d`` (its candidate entry's list, else its
    added rank; 0 when it is no candidate)."""
    entry = _candidate(d, name)
    return len(entry["parameters"]) if entry.get("parameters") else int(entry.get("added_rank", 0))


def named_effects(d: dict) -> list[str]:
    """The effects the verdict names (``until_explained``: every accepted one)."""
    return list(d["verdict"]["missing_effects"])


def group_of(d: dict, name: str) -> set[str]:
    """Named effect ``name`` and the effects the verdict says explain the data as well."""
    verdict = d["verdict"]
    if name == verdict.get("missing_effect"):
        return {name, *verdict.get("alternatives", [])}
    return {name, *_candidate(d, name).get("alternatives", [])}


def marked_implausible(entry: dict) -> bool:
    """Whether a candidate entry of the JSON marks its fitted amplitude implausible."""
    if entry.get("implausible"):
        return True
    if entry.get("plausible") is False:
        return True
    return str(entry.get("plausibility", "")).startswith("implausible")


def implausible_named(d: dict) -> list[str]:
    """Named effects the candidate table marks implausible."""
    return [n for n in named_effects(d) if marked_implausible(_candidate(d, n))]


def _names_as_such(d: dict, named: list[str], planted: tuple[str, ...]) -> bool:
    if len(named) != len(planted):
        return False
    groups = [group_of(d, n) for n in named]
    sizes = [n_parameters(d, n) for n in named]
    for order in itertools.permutations(planted):
        if all(
            p in g and size <= n_parameters(d, p)
            for p, g, size in zip(order, groups, sizes, strict=True)
        ):
            return True
    return False


def _names_many(d: dict, named: list[str], planted: str) -> bool:
    size = n_parameters(d, planted)
    return any(
        n == planted or (planted in group_of(d, n) and n_parameters(d, n) >= size) for n in named
    )


def score(case: Case, d: dict) -> dict:
    """How the verdict ``d`` fares on ``case`` (module docstring): ``named``, their ``groups``,
    ``ok`` (the case's target met), ``exact`` (the named set pairs off with the planted one),
    ``implausible_named``."""
    named = named_effects(d)
    if case.kind == SIMPLE:
        ok = _names_as_such(d, named, case.planted)
        exact = ok
    elif case.kind == MANY:
        ok = _names_many(d, named, case.planted[0])
        exact = ok and len(named) == 1
    elif case.kind == IMPLAUSIBLE:
        planted = case.planted[0]
        ok = exact = (
            planted not in named
            and marked_implausible(_candidate(d, planted))
            and not implausible_named(d)
        )
    else:
        ok = exact = not named
    return {
        "named": named,
        "groups": [sorted(group_of(d, n)) for n in named],
        "ok": bool(ok),
        "exact": bool(exact),
        "implausible_named": implausible_named(d),
    }


def run_case(case: Case, seed: int) -> dict:
    """Simulate ``case`` at ``seed``, diagnose it, score it: :func:`score`'s entries plus
    ``seed`` and the diagnosis' wall time ``seconds``."""
    data = case.simulate(seed)
    start = time.perf_counter()
    d = case.diagnose(data)
    seconds = time.perf_counter() - start
    return {"seed": seed, **score(case, d), "seconds": seconds}


# --- the real runs -------------------------------------------------------------------------------
@dataclass(frozen=True)
class RealRun:
    """A bundled TPOINT run, read as a user does (``import-tpoint``, then ``diagnose`` with the
    mount's URDF the import writes: the alt-az or the German-equatorial mount)."""

    name: str
    path: Path
    refraction: str | None  # None: the file type's default (README's commands)

    def diagnosis(self, until_explained: bool = True) -> dict:
        """The diagnosis JSON of the run."""
        from turntable_pin.measurement.data import read_measurements
        from turntable_pin.measurement.diagnosis import diagnose_measurements
        from turntable_pin.measurement.tpoint import convert_tpoint, read_tpoint
        from turntable_pin.model.generic_table import GenericTable

        conv = convert_tpoint(read_tpoint(self.path), refraction=self.refraction)
        with tempfile.TemporaryDirectory(prefix="verdict-rates-") as folder:
            csv = conv.write_csv(Path(folder) / f"{self.name}.csv")
            urdf = conv.write_urdf(Path(folder) / conv.urdf_name)
            data, table = read_measurements(csv), GenericTable(urdf)
            return diagnose_measurements(
                data, until_explained=until_explained, turntable=table
            ).to_dict()


REAL_RUNS = (
    RealRun("MMT", MMT_RUN, None),
    RealRun("GEM", GEM_RUN, "none"),
)
"""The two shared real runs (README: the MMT alt-az run, the German-equatorial gem-28 run with
``--refraction none``)."""


def _largest(parameters: list[dict]) -> dict:
    """The largest ``|value|`` of a candidate's parameters and its unit."""
    top = max(parameters, key=lambda p: abs(p["value"]), default=None)
    return {"largest": abs(top["value"]) if top else None, "unit": top.get("unit") if top else None}


def real_verdict(d: dict) -> dict:
    """The named effects of a real run's diagnosis with their fitted amplitudes (value, std,
    unit), the significant candidates with their largest parameter and implausibility, the
    candidates marked implausible, and the named ones among them."""
    named = named_effects(d)
    parameters = d["verdict"].get("named_parameters", {})
    return {
        "named": named,
        "alternatives": list(d["verdict"].get("alternatives", [])),
        "amplitudes": {
            n: [
                {k: p.get(k) for k in ("name", "value", "std", "unit")}
                for p in parameters.get(n, [])
            ]
            for n in named
        },
        "significant": [
            {
                "effect": c["effect"],
                "delta_bic": c["delta_bic"],
                **_largest(c.get("parameters", [])),
                "implausible": c.get("implausible") or None,
            }
            for c in d["candidates"]
            if c.get("significant")
        ],
        "marked_implausible": [c["effect"] for c in d["candidates"] if marked_implausible(c)],
        "implausible_named": implausible_named(d),
    }


def timed(function: Callable[[], dict]) -> tuple[dict, float]:
    """``function()`` and its wall time, s."""
    start = time.perf_counter()
    out = function()
    return out, time.perf_counter() - start
