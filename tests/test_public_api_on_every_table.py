"""Every public function and method of ``allocation/``, ``calibration/``, ``model/`` and
``measurement/`` that takes a table, on every bundled table (``models/*.urdf``, the paper's
included): the paper's table is data over the one table class, so nothing may work on it alone.

The walk finds the API by introspection (each module's ``__all__``, every function or method with a
``table``, ``turntable`` or ``model`` parameter) and requires a call of each in :func:`_calls` or a
reason in :data:`NOT_A_TABLE`, so a new one cannot slip past. Each call runs on every table, and
so does every public property and zero-argument method of what it returns (and of the table
itself). The contract: every call answers on every table; the only refusals are the physical
ones of :data:`MAY_REFUSE` (a table whose gravity never reaches every payload axis cannot
calibrate the GyroWheel), and a joint the table lacks (``PositionSet.joint_rad(2)`` of a one-joint
table) refuses in the package's own one line (:class:`TurntablePinError`) -- never an
``IndexError``, ``KeyError``, ``TypeError`` or a numpy error.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
from functools import cache

import numpy as np
import pytest

from conftest import REPO_DIR
from turntable_pin.core.exceptions import TurntablePinError

PACKAGES = ("allocation", "calibration", "model", "measurement")
TABLE_PARAMETERS = ("table", "turntable", "model")  # model: a façade, Pinocchio's or a fit's
TABLES = sorted(p.stem for p in (REPO_DIR / "models").glob("*.urdf"))
LIMITS_ARCMIN = (0.6, 0.25, 0.45)


def _public_table_api() -> set[str]:
    """``module.name`` / ``module.Class.method`` of every public callable taking a table."""
    found = set()
    for package in PACKAGES:
        root = importlib.import_module(f"turntable_pin.{package}")
        for info in pkgutil.walk_packages(root.__path__, f"{root.__name__}."):
            module = importlib.import_module(info.name)
            for name in getattr(module, "__all__", ()):
                obj = getattr(module, name)
                if getattr(obj, "__module__", None) != module.__name__:
                    continue  # re-exported: walked where it is defined
                members = [(name, obj)] if inspect.isfunction(obj) else []
                if inspect.isclass(obj):
                    for attr, member in vars(obj).items():
                        if attr.startswith("_") and attr != "__init__":
                            continue
                        member = getattr(member, "__func__", member)
                        if inspect.isfunction(member):
                            members.append((f"{name}.{attr}", member))
                for qualified, function in members:
                    if any(p in TABLE_PARAMETERS for p in inspect.signature(function).parameters):
                        found.add(f"{module.__name__.removeprefix('turntable_pin.')}.{qualified}")
    return found


# ---- one context per table ------------------------------------------------------------------
class Context:
    """What the calls need on one table, built once (coarse grids: the walk is about every
    table answering, the numbers are tested elsewhere)."""

    def __init__(self, name: str, tmp) -> None:
        from turntable_pin.allocation.solver import OrientationLimits
        from turntable_pin.calibration.positions import PositionSet
        from turntable_pin.model.paper_table import table_of

        self.name = name
        self.tmp = tmp
        self.table = table_of(REPO_DIR / "models" / f"{name}.urdf")
        rng = np.random.default_rng(7)
        self.values = self.table.values()
        angular = [self.table.parameter_names.index(n) for n in self.table.angular_names]
        self.values[angular] = np.radians(rng.uniform(-5.0, 5.0, len(angular)) / 3600.0)
        self.angles = tuple(np.radians([30.0, 45.0, 60.0][: len(self.table.joint_names)]))
        self.limits = OrientationLimits.from_arcmin(*LIMITS_ARCMIN)
        self.positions = PositionSet.grid(90.0, table=self.table)

    @property
    def allocation(self):
        from turntable_pin.allocation.solver import allocate_tolerances

        return _cached(self, "allocation", lambda: allocate_tolerances(
            self.limits, table=self.table, grid_step_deg=30.0))  # fmt: skip

    @property
    def simulated(self):
        from turntable_pin.measurement.simulation import Schedule, simulate_measurements

        return _cached(self, "simulated", lambda: simulate_measurements(
            self.values, schedule=Schedule(random_positions=96), noise_arcsec=0.5, seed=3,
            turntable=self.table))  # fmt: skip

    @property
    def data(self):
        return self.simulated.data

    @property
    def run_path(self):
        from turntable_pin.calibration.drift_fit import simulate_run
        from turntable_pin.calibration.gyrowheel import GyroWheelModel
        from turntable_pin.calibration.positions import position_inputs
        from turntable_pin.core.csv_table import write_csv_table

        def write():
            from turntable_pin.calibration.positions import PositionSet

            run = PositionSet.grid(45.0, table=self.table)
            inputs = position_inputs(run, np.radians(45.0))
            columns = simulate_run(GyroWheelModel.nominal(), inputs, noise_dph=0.002, seed=1)
            path = self.tmp / f"{self.name}_run.csv"
            write_csv_table(path, columns)
            return path

        return _cached(self, "run_path", write)

    @property
    def positions_csv(self):
        def write():
            path = self.tmp / f"{self.name}_positions.csv"
            names = [f"{a}_deg" for a in self.table.angle_names]
            rows = np.degrees(self.positions.angles_rad)
            path.write_text(",".join(names) + "\n" + "\n".join(
                ",".join(f"{v:g}" for v in row) for row in rows) + "\n")  # fmt: skip
            return path

        return _cached(self, "positions_csv", write)

    @property
    def lower_bounds_yaml(self):
        def write():
            path = self.tmp / f"{self.name}_lower.yaml"
            path.write_text(f"lower_bounds:\n  {self.table.angular_names[0]}: 0.5\n")
            return path

        return _cached(self, "lower_bounds_yaml", write)

    @property
    def effect(self):
        from turntable_pin.measurement.catalogue import catalogue

        return catalogue(self.table)[0]


def _cached(ctx, key, make):
    store = ctx.__dict__.setdefault("_cache", {})
    if key not in store:
        store[key] = make()
    return store[key]


@cache
def _context(name: str) -> Context:
    import tempfile
    from pathlib import Path

    return Context(name, Path(tempfile.mkdtemp(prefix=f"api_{name}_")))


# ---- one call of every public callable that takes a table -----------------------------------
def _calls():
    from turntable_pin.allocation import capability, monte_carlo, sensitivity, solver
    from turntable_pin.calibration import drift_fit, positions, run
    from turntable_pin.measurement import (
        catalogue,
        diagnosis,
        effect_model,
        effect_terms,
        fit,
        pointing_terms,
        simulation,
        table,
        user_effects,
    )
    from turntable_pin.measurement.effects import contract, pointing_flexure
    from turntable_pin.model import paper_table

    mc_options = {"grid_step_deg": 45.0, "progress": False}
    return {
        # allocation
        "allocation.capability.ManufacturingCapability.of_table": lambda c: (
            capability.ManufacturingCapability.of_table(c.table)),
        "allocation.capability.ManufacturingCapability.from_yaml": lambda c: (
            capability.ManufacturingCapability.from_yaml(c.lower_bounds_yaml, c.table)),
        "allocation.monte_carlo.run_monte_carlo": lambda c: monte_carlo.run_monte_carlo(
            c.allocation.upper_bounds_rad, c.limits, 20, 1, table=c.table, **mc_options),
        "allocation.sensitivity.default_grid_step_deg": lambda c: (
            sensitivity.default_grid_step_deg(c.table)),
        "allocation.sensitivity.check_grid_step": lambda c: sensitivity.check_grid_step(
            c.table, 30.0),
        "allocation.sensitivity.grid_axes_rad": lambda c: sensitivity.grid_axes_rad(c.table, 30.0),
        "allocation.sensitivity.sensitivities": lambda c: sensitivity.sensitivities(
            c.table, grid_step_deg=30.0, error_values=c.values),
        "allocation.solver.Allocation.__init__": lambda c: solver.Allocation(
            c.allocation.upper_bounds_rad, c.limits, "model", c.allocation.weights,
            c.allocation.subproblems, c.allocation.worst_case_rad,
            capability=c.allocation.capability, table=c.table,
            sensitivities=c.allocation.sensitivities),
        "allocation.solver.allocate_tolerances": lambda c: c.allocation,
        "allocation.solver.allocation_weights": lambda c: {
            s: solver.allocation_weights(s, c.allocation.sensitivities, c.table)
            for s in solver.WEIGHT_SCHEMES},
        "allocation.solver.angle_rows": lambda c: solver.angle_rows(c.table, 30.0),
        "allocation.solver.default_orientation_limits": lambda c: (
            solver.default_orientation_limits(positions="grid:45", table=c.table)),
        # calibration
        "calibration.drift_fit.calibrate_run": lambda c: drift_fit.calibrate_run(
            c.run_path, np.radians(45.0), c.table),
        "calibration.positions.PositionSet.__init__": lambda c: positions.PositionSet(
            c.positions.angles_rad, table=c.table),
        "calibration.positions.PositionSet.grid": lambda c: c.positions,
        "calibration.positions.PositionSet.from_csv": lambda c: (
            positions.PositionSet.from_csv(c.positions_csv, c.table)),
        "calibration.positions.PositionSet.from_csv_table": lambda c: (
            positions.PositionSet.from_csv_table(
                _csv(c),
                positions.PositionSet.columns_of(_csv(c), c.table),
                c.table, "file")),
        "calibration.positions.PositionSet.candidate_columns": lambda c: (
            positions.PositionSet.candidate_columns(c.table)),
        "calibration.positions.PositionSet.columns_of": lambda c: (
            positions.PositionSet.columns_of(_csv(c), c.table)),
        "calibration.positions.PositionSet.parse": lambda c: positions.PositionSet.parse(
            "grid:120", c.table),
        "calibration.positions.PositionSet.random": lambda c: positions.PositionSet.random(
            5, c.table, seed=1),
        "calibration.positions.check_commanded_angles": lambda c: (
            positions.check_commanded_angles(
                _csv(c),
                positions.PositionSet.columns_of(_csv(c), c.table))),
        "calibration.run.read_run": lambda c: run.read_run(c.run_path, np.radians(45.0), c.table),
        # model
        "model.paper_table.resolve_table": lambda c: paper_table.resolve_table(c.table),
        # measurement
        "measurement.catalogue.catalogue": lambda c: catalogue.catalogue(c.table),
        "measurement.catalogue.resolve_effect": lambda c: catalogue.resolve_effect(
            f"encoder_harmonics@{c.table.joint_names[-1]}", c.table),
        "measurement.diagnosis.OrientationFamily.__init__": lambda c: diagnosis.OrientationFamily(
            c.data, turntable=c.table),
        "measurement.diagnosis.diagnose_measurements": lambda c: (
            diagnosis.diagnose_measurements(c.data, turntable=c.table)),
        "measurement.diagnosis.dense_joint_grid": lambda c: diagnosis.dense_joint_grid(
            table.measured_table(c.table)),
        "measurement.diagnosis.mount_option": lambda c: diagnosis.mount_option(c.table),
        "measurement.diagnosis.urdf_option": lambda c: diagnosis.urdf_option(c.table),
        "measurement.effect_model.OrientationModel.__init__": lambda c: (
            effect_model.OrientationModel(
                c.data.variables(), [c.effect], c.table)),
        "measurement.effect_terms.EffectTerm.check": lambda c: effect_terms.parse_term(
            "post.x~h1(phi1)", table.measured_table(c.table)).check(
                table.measured_table(c.table)),
        "measurement.effect_terms.parse_term": lambda c: effect_terms.parse_term(
            "post.x~h1(phi1)", table.measured_table(c.table)),
        "measurement.effects.contract.check_effect_on_probe": lambda c: (
            contract.check_effect_on_probe(c.effect, table.measured_table(c.table))),
        "measurement.effects.pointing_flexure.PointingFlexure.__init__": lambda c: (
            pointing_flexure.pointing_flexures(table.measured_table(c.table))),
        "measurement.effects.pointing_flexure.pointing_flexures": lambda c: (
            pointing_flexure.pointing_flexures(table.measured_table(c.table))),
        "measurement.fit.fit_orientation": lambda c: fit.fit_orientation(
            c.data, [c.effect], turntable=c.table),
        "measurement.fit.orientation_zero_point": lambda c: fit.orientation_zero_point(
            c.data, turntable=c.table),
        "measurement.fit.refuse_repeated_shapes": lambda c: fit.refuse_repeated_shapes(
            c.data, [c.effect], c.table),
        "measurement.pointing_terms.mount_kind": lambda c: pointing_terms.mount_kind(c.table),
        "measurement.pointing_terms.rigid_term_map": lambda c: (
            pointing_terms.rigid_term_map(c.table)),
        "measurement.simulation.simulate_measurements": lambda c: c.simulated,
        "measurement.simulation.Schedule.rows": lambda c: simulation.Schedule(120.0).rows(
            np.random.default_rng(0), c.table),
        "measurement.table.measured_table": lambda c: table.measured_table(c.table),
        "measurement.user_effects.check_user_effect_names": lambda c: (
            user_effects.check_user_effect_names([], c.table)),
        "measurement.user_effects.check_user_effects": lambda c: (
            user_effects.check_user_effects([], c.table)),
        "measurement.user_effects.describe_effects": lambda c: user_effects.describe_effects(
            catalogue.catalogue(c.table), c.table),
        "measurement.user_effects.inline_effect": lambda c: user_effects.inline_effect(
            "post.x~h1(phi1)", c.table),
        "measurement.user_effects.load_catalogue": lambda c: user_effects.load_catalogue(
            [], c.table),
        "measurement.user_effects.load_effects_modules": lambda c: (
            user_effects.load_effects_modules([], c.table)),
        "measurement.user_effects.read_effect_file": lambda c: user_effects.read_effect_file(
            _effect_file(c), c.table),
        "measurement.user_effects.resolve_effects": lambda c: user_effects.resolve_effects(
            [c.effect.name], c.table),
    }  # fmt: skip


def _csv(c):
    from turntable_pin.calibration.positions import PositionSet
    from turntable_pin.core.csv_table import read_csv_table

    return read_csv_table(c.positions_csv, (), PositionSet.candidate_columns(c.table))


def _effect_file(c):
    path = c.tmp / f"{c.name}_effect.yaml"
    path.write_text(
        "name: my_tilt\ntitle: a tilt of the payload turning with the first joint\n"
        "terms:\n  - {site: post.x, harmonics: 1, of: phi1}\n"
    )
    return path


NOT_A_TABLE = {
    # These take the paper's angles phi1 and phi2 (a two-joint table under the paper's layout):
    # every table has the same through the table's own calls above (sensitivities(table, axes,
    # error_values=...)).
    "allocation.sensitivity.average_sensitivities",
    "allocation.sensitivity.sensitivity_matrix",
    # A Pinocchio model (not a table), the chain's own constructor, a fit's model.
    "model.chain.ErrorChain.from_pinocchio",
    "model.chain.apply_chain_errors",
    "model.chain.joint_axis",
    # Result objects holding what a call above made (walked through that call's result).
    "measurement.fit.OrientationFit.__init__",
    "measurement.fit.OrientationFitProblem.__init__",
    # `turntable=` here is a plausible scale on a precision turntable (a number), not a table.
    "measurement.effects.base.plausible",
}

MAY_REFUSE = {
    # name: the tables allowed to refuse it (with the package's own one-line error), and why
    "calibration.drift_fit.calibrate_run": {
        "altaz_mount",
        "single_axis_rate_table",
        "two_axis_vertical_outer",
    },  # gravity never reaches every payload axis: the GyroWheel cannot be calibrated on them
    "allocation.solver.default_orientation_limits": {
        "altaz_mount",
        "single_axis_rate_table",
        "two_axis_vertical_outer",
    },  # the same: no calibration requirement without a calibration
}


def test_every_public_callable_taking_a_table_is_walked():
    found = _public_table_api()
    calls = set(_calls())
    missing = sorted(found - calls - NOT_A_TABLE)
    assert not missing, f"public callables taking a table without a call here: {missing}"
    stale = sorted((calls | NOT_A_TABLE) - found - {
        "allocation.solver.default_orientation_limits",  # table= as a keyword of an lru_cache
    })  # fmt: skip
    assert not stale, f"calls of callables that no longer take a table: {stale}"


def _walk(obj, seen: set, depth: int = 0) -> None:
    """Read every public property and call every public zero-argument method of ``obj`` (and,
    one level down, of what they return when it is one of the package's objects)."""
    if (depth > 1 or id(obj) in seen or isinstance(obj, BaseException)
            or not type(obj).__module__.startswith("turntable_pin")):  # fmt: skip
        return
    seen.add(id(obj))
    for name in dir(type(obj)):
        if name.startswith("_") or name in ("replace", "with_errors", "plot"):  # plot: figures
            continue
        attr = inspect.getattr_static(obj, name)
        if isinstance(attr, (staticmethod, classmethod)):
            continue
        try:
            if isinstance(attr, (property,)) or not callable(attr):
                value = getattr(obj, name)
            else:
                positional = (inspect.Parameter.POSITIONAL_ONLY,
                              inspect.Parameter.POSITIONAL_OR_KEYWORD)  # fmt: skip
                required = [
                    p for p in list(inspect.signature(attr).parameters.values())[1:]
                    if p.default is p.empty and p.kind in positional
                ]  # fmt: skip
                if required:
                    continue
                value = getattr(obj, name)()
        except TurntablePinError:
            continue
        _walk(value, seen, depth + 1)


def _answers(name: str, table: str):
    try:
        return _calls()[name](_context(table))
    except TurntablePinError as exc:
        if table in MAY_REFUSE.get(name, ()):
            return exc
        raise AssertionError(f"{name} refused on {table}: {exc}") from exc


WALKED = sorted(set(_calls()))


@pytest.mark.parametrize("table", TABLES)
@pytest.mark.parametrize("name", WALKED)
def test_every_call_answers_on_every_table(name, table):
    result = _answers(name, table)
    _walk(result, set())


@pytest.mark.parametrize("table", TABLES)
def test_the_table_itself_answers_every_public_method(table):
    ctx = _context(table)
    _walk(ctx.table, set())
    t = ctx.table
    assert t.title and len(t.angle_names) == len(t.joint_names)
    assert np.all(np.isfinite(t.first_order_error_rad(ctx.values, ctx.angles)))
    exact = t.orientation_error(ctx.values, ctx.angles)
    np.testing.assert_allclose(
        t.first_order_error_rad(ctx.values, ctx.angles),
        [exact.dpsi_rad, exact.dtheta_rad, exact.dgamma_rad], rtol=0, atol=1e-8,
    )  # fmt: skip
    for angle in ("psi", "theta", "gamma"):
        assert set(t.angle_domains_rad(angle)) <= set(t.joint_names)


@pytest.mark.parametrize("table", TABLES)
def test_allocation_errors_is_the_tables_error_vector(table):
    """``Allocation.errors()`` on every table (it raised "expected 8 or 9 error values, got 12"
    on three_axis_imu_table): every angular error at its bound, lengths 0, what the table's own
    methods take."""
    ctx = _context(table)
    allocation = ctx.allocation
    values = allocation.errors()
    t = ctx.table
    assert values.shape == (len(t.parameter_names),)
    for name, bound in zip(allocation.error_names, allocation.upper_bounds_rad, strict=True):
        expected = bound if np.isfinite(bound) else 0.0
        assert values[t.parameter_names.index(name)] == expected
    assert all(values[t.parameter_names.index(n)] == 0.0 for n in t.length_names)
    assert np.isfinite(t.orientation_error(values, ctx.angles).dpsi_rad)


def test_the_three_axis_table_s_allocation_errors():
    ctx = _context("three_axis_imu_table")
    values = ctx.allocation.errors()
    assert values.size == 18 and np.count_nonzero(values) == 12


@pytest.mark.parametrize("command", ["allocate", "orientation", "montecarlo"])
def test_one_json_schema_for_every_table(command):
    """The JSON of a command has the same keys on every table (the paper's included)."""
    import json

    from conftest import cli

    keys = set()
    for name in TABLES:
        t = _context(name).table
        argv = [command, "--urdf", str(t.urdf_path), "--json"]
        if command == "orientation":
            argv += ["--angles-deg", ",".join(["10"] * len(t.joint_names))]
        else:
            argv += ["--limits-arcmin", "1", "--grid-step-deg", "45"]
        if command == "montecarlo":
            argv += ["-n", "20"]
        proc = cli(*argv)
        assert proc.returncode in (0, 1), proc.stderr
        keys.add(frozenset(json.loads(proc.stdout)))
    assert len(keys) == 1
