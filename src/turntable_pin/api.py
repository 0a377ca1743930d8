"""The flat Python API: ``import turntable_pin as tp`` and the user's loop in a few lines.

Each function takes paths (a bundled name such as ``"altaz_mount"`` or
``"measurements_example.csv"`` is found in the package's models) or objects, makes the calls the
command line makes, and returns the result object the command line renders: it shows itself in
a notebook (``_repr_html_``), plots itself (``.plot()``: matplotlib figures) and serialises itself
(``.to_dict()``, ``.to_json()``). Inside, angles are radians and lengths metres; arguments and
results in other units say so in their names (``noise_arcsec``, ``latitude_deg``).

Example
-------
>>> import turntable_pin as tp
>>> table = tp.load_table("turntable")
>>> sim = tp.simulate(table, errors={"dphi_y1": 20}, effects={"inner_encoder_harmonics": {"c1": 3}})
>>> before = tp.fit(sim, table=table)
>>> name = tp.diagnose(sim, table=table).missing_effect
>>> after = tp.fit(sim, name, table=table)
>>> after.result.rms_user < before.result.rms_user
True
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from .core.exceptions import InputError
from .core.resources import bundled_path
from .report import notebook as _views  # noqa: F401  (registers the results' notebook views)

# Each function imports the layer it calls when called: deliberately lazy, so that one flat call
# pays only for its own layer (tp.load_table never loads scipy.optimize or the design search).

__all__ = [
    "allocate",
    "calibrate",
    "design",
    "diagnose",
    "fit",
    "import_tpoint",
    "load_table",
    "read_measurements",
    "simulate",
]


# ---- tables ---------------------------------------------------------------------------------
def load_table(name_or_path=None, mount: str | None = None, *, payload_frame: str | None = None):
    """The turntable (or telescope mount) of a URDF, with its error model.

    Parameters
    ----------
    name_or_path : str, path, TpointConversion or table, optional
        A bundled table by name (``"turntable"``, the paper's; ``"altaz_mount"``,
        ``"german_equatorial_mount"``, ``"two_axis_vertical_outer"``, ``"three_axis_imu_table"``,
        ``"single_axis_rate_table"``), a URDF path (1 to 3 revolute joints in a chain), the
        result of :func:`import_tpoint` (the bundled mount its rows belong to) or a table
        (returned as is). Default: the paper's table.
    mount : {"altaz", "equatorial", "none"}, optional
        What the table is, overriding what its URDF declares: a telescope mount (TPOINT terms
        and flexure candidates) or a turntable.
    payload_frame : str, optional
        The payload frame of the URDF (default: the only leaf of its chain).

    Returns
    -------
    GenericTable
        The table: ``.joint_names``, ``.parameter_names`` (its errors; angles in rad, lengths in
        m inside), ``.nominal_pin_model`` and ``.nominal_pin_data`` (Pinocchio's model and data
        of the nominal table), ``.pinocchio_model(errors)`` (a model with errors),
        ``.orientation_error(errors, angles_rad)``.

    Raises
    ------
    InputError, ModelError
        No such file, or a URDF that is not a turntable (the message says why).

    Examples
    --------
    >>> import turntable_pin as tp
    >>> table = tp.load_table("altaz_mount")
    >>> table.joint_names
    ('azimuth', 'elevation')
    >>> table.nominal_pin_model.nv
    2
    """
    from .measurement.checked_table import checked_table
    from .measurement.tpoint import EQUATORIAL, TpointConversion

    if hasattr(name_or_path, "parameter_names"):  # a table already
        return name_or_path
    if isinstance(name_or_path, TpointConversion):
        if name_or_path.run.mount == EQUATORIAL:
            raise InputError(
                "an equatorial run's rows belong to a copy of german_equatorial_mount tilted to "
                "the run's latitude: write it with run.write_urdf(path), then load_table(path)"
            )
        name_or_path = name_or_path.urdf_name
    path = None if name_or_path is None else bundled_path(name_or_path)
    return checked_table(path, payload_frame, mount)


def _table_of(data, table):
    """The table of ``data``: ``table`` when given, else the mount a converted TPOINT run belongs
    to, else the paper's (:func:`load_table`)."""
    from .measurement.tpoint import TpointConversion

    if table is None and isinstance(data, TpointConversion):
        return load_table(data)
    return load_table(table)


def _joint_columns(table) -> tuple[str, ...] | None:
    """The joints ``table``'s data files name (``phiK_deg`` or ``<joint>_deg``), or ``None``
    for the paper's ``phi1_deg, phi2_deg``."""
    from .measurement.table import measured_table

    return measured_table(table).data_joint_names or None


# ---- measurements ---------------------------------------------------------------------------
def read_measurements(source, table=None):
    """Orientation measurements, checked (the CSV of ``docs/measurements.md``).

    Parameters
    ----------
    source : str, path, DataFrame or result
        A measurement CSV (a bundled example by name, e.g. ``"measurements_example.csv"``); a
        pandas ``DataFrame`` with the CSV's columns (``phi1_deg``, ..., ``dpsi_arcsec``,
        ``dtheta_arcsec``, ``dgamma_arcsec``, optional ``sigma_arcsec``, ``time_s``,
        ``dir1``...; read through the same checks as a file); the result of :func:`simulate`
        or :func:`import_tpoint`; or measurements (returned as is).
    table : str, path or table, optional
        The table the data belong to (:func:`load_table`; default the paper's): it names the
        angle columns (``phiK_deg`` or ``<joint>_deg``).

    Returns
    -------
    OrientationMeasurements
        ``.joint_rad`` (N, joints), ``.angles_rad`` (N, 3: dpsi, dtheta, dgamma; NaN where not
        measured), ``.sigma_rad``, ``.time_s``, ``.dirs``; ``.columns()`` in user units.

    Raises
    ------
    InputError
        Naming the file, row and column of the first problem.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> data = tp.read_measurements("measurements_example.csv")
    >>> data.n_positions
    144
    """
    from .measurement.data import OrientationMeasurements
    from .measurement.data import read_measurements as read_csv
    from .measurement.simulation import SimulatedMeasurements
    from .measurement.tpoint import TpointConversion

    if isinstance(source, OrientationMeasurements):
        return source
    if isinstance(source, SimulatedMeasurements):
        return source.data
    if isinstance(source, TpointConversion):
        return source.measurements()
    joints = _joint_columns(load_table(table))
    if hasattr(source, "to_csv"):  # a DataFrame: the one reader checks it as a file
        with tempfile.TemporaryDirectory(prefix="turntable-pin-frame-") as folder:
            path = Path(folder) / "frame.csv"
            source.to_csv(path, index=False)
            return read_csv(path, joints).replace(source="a DataFrame")
    return read_csv(bundled_path(source), joints)


def simulate(
    table=None,
    *,
    errors=None,
    effects: Mapping[str, Mapping[str, float]] | None = None,
    noise_arcsec: float | Sequence[float] = 1.0,
    seed: int = 0,
    step_deg: float = 30.0,
    random_positions: int | None = None,
    schedule=None,
    not_measured: Sequence[str] = (),
    catalogue: Sequence = (),
):
    """Simulate a measurement run: the table's errors, hidden effects, a position schedule and
    noise (what ``turntable-pin simulate`` writes).

    Parameters
    ----------
    table : str, path or table, optional
        The table (:func:`load_table`; default the paper's).
    errors : dict, path or array, optional
        The table's errors: ``{name: value}`` in arcsec for angles and mm for lengths (a unit
        suffix such as ``dphi_y1_arcmin`` or ``deta_m`` is understood), a YAML file of them, or
        the error vector (rad, m) in ``table.parameter_names`` order. Default: none.
    effects : dict, optional
        Hidden effects, ``{effect: {parameter: value}}`` in the effect's user unit (arcsec,
        arcsec/g, arcsec/h), e.g. ``{"inner_encoder_harmonics": {"c1": 3, "s2": -2}}``.
    noise_arcsec : float or (3,) floats, default 1.0
        1-sigma noise of each angle (one per dpsi, dtheta, dgamma if three).
    seed : int, default 0
        Seed of every random choice (order, directions, noise), recorded in the result.
    step_deg : float, default 30.0
        Grid step of every joint, degrees.
    random_positions : int, optional
        N positions uniform over every joint's turn (seeded) instead of the grid.
    schedule : Schedule, optional
        Full control of positions, order, repeats, passes, time and approach directions
        (``tp.Schedule(30, 30, order="random", repeats=2, passes=1, dwell_s=60)``); replaces
        ``step_deg`` and ``random_positions``.
    not_measured : sequence of str, optional
        Angles left empty at every position (``("dgamma",)``: a pointing run).
    catalogue : sequence of Effect, optional
        Your effects besides the table's catalogue that ``effects`` may name.

    Returns
    -------
    SimulatedMeasurements
        ``.data`` (the measurements), ``.errors`` and ``.effects`` (the truth, user units),
        ``.seed``; ``.write_csv(path)`` writes the CSV.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> sim = tp.simulate("turntable", errors={"dphi_y1": 20}, seed=1)
    >>> sim.data.n_positions, sim.seed
    (144, 1)
    """
    from .measurement.simulation import Schedule, simulate_measurements

    table = load_table(table)
    vector = _error_vector(table, errors)
    if schedule is None:
        design = {"random_positions": random_positions} if random_positions else {}
        schedule = Schedule(step_deg, step_deg, step_deg, **design)
    return simulate_measurements(
        vector,
        dict(effects or {}),
        schedule=schedule,
        noise_arcsec=noise_arcsec,
        seed=seed,
        turntable=table,
        catalogue=tuple(catalogue),
        not_measured=tuple(not_measured),
    )


def _error_vector(table, errors) -> np.ndarray:
    """The table's error vector (rad, m) of :func:`simulate`'s ``errors``: None (its URDF's),
    ``{name: value}`` in user units, a YAML file, or the vector itself."""
    from .model.errors import MAX_ORIENTATION_ERROR_DEG

    if errors is None:
        return table.values()
    if isinstance(errors, Mapping):
        return table.errors_from_user_units(errors, max_angle_deg=MAX_ORIENTATION_ERROR_DEG)
    if isinstance(errors, (str, Path)):
        return table.errors_from_yaml(bundled_path(errors), max_angle_deg=MAX_ORIENTATION_ERROR_DEG)
    return np.asarray(errors, dtype=float)


def _effects(effects, table, extra: Sequence = ()) -> tuple:
    """Effect objects of ``effects``: a name or comma-separated names (catalogue names, effect
    files, inline terms such as ``dphi_z2~h3(phi2)``), a sequence of them, or Effect objects."""
    from .measurement.user_effects import resolve_effects

    if effects is None:
        return ()
    if isinstance(effects, str):
        effects = [effects]
    given = list(effects)
    objects = [e for e in given if not isinstance(e, str)]
    names = resolve_effects([e for e in given if isinstance(e, str)], table, tuple(extra))
    return (*names, *objects)


def fit(data, effects=(), *, table=None, ignore_sigma: bool = False):
    """Weighted least squares of the table's base errors plus ``effects`` (``turntable-pin
    fit``).

    Parameters
    ----------
    data : path, DataFrame or measurements
        What :func:`read_measurements` reads.
    effects : str or sequence, optional
        Effects to add to the base: catalogue names (``"inner_encoder_harmonics"``),
        comma-separated names, effect files (``.yaml``), inline terms
        (``"dphi_z2~h3(phi2)"``) or Effect objects.
    table : str, path or table, optional
        The table (:func:`load_table`; default: the mount of a TPOINT run given as ``data``,
        else the paper's).
    ignore_sigma : bool, default False
        Estimate the noise from the fit even if the data have sigmas.

    Returns
    -------
    OrientationFit
        ``.result`` (``.params`` rad/m, ``.rms_user`` arcsec, ``.chi2_reduced``, ``.rank``,
        ``.combinations()``: the determined combinations with standard errors), ``.effects``,
        ``.residuals_rad`` (N, 3).

    Examples
    --------
    >>> import turntable_pin as tp
    >>> result = tp.fit("measurements_example.csv")
    >>> result.result.rank
    5
    """
    from .measurement.fit import fit_orientation, refuse_repeated_shapes

    table = _table_of(data, table)
    data = read_measurements(data, table)
    if ignore_sigma:
        data = data.without_sigma()
    chosen = _effects(effects, table)
    refuse_repeated_shapes(data, chosen, turntable=table)
    return fit_orientation(data, chosen, turntable=table)


def diagnose(
    data,
    *,
    table=None,
    until_explained: bool = False,
    catalogue: Sequence = (),
    outliers: bool = True,
    ignore_sigma: bool = False,
):
    """Test every catalogued effect against the base fit and name the missing one
    (``turntable-pin diagnose``).

    Parameters
    ----------
    data : path, DataFrame or measurements
        What :func:`read_measurements` reads.
    table : str, path or table, optional
        The table (:func:`load_table`; default: the mount of a TPOINT run given as ``data``,
        else the paper's).
    until_explained : bool, default False
        Add effects while one is significant.
    catalogue : sequence of path or Effect, optional
        Your effects (``.yaml`` effect files, ``.py`` modules, Effect objects) join the
        table's candidates. A ``.py`` module is code that runs: give only files you trust.
    outliers : bool, default True
        Find gross outliers by the stated robust rule and leave them out (False: keep every
        measured angle).
    ignore_sigma : bool, default False
        Estimate the noise from the fits even if the data have sigmas.

    Returns
    -------
    Diagnosis
        ``.missing_effect`` (the name, or ``None``), ``.base_fit``, ``.best_fit``, ``.steps``,
        ``.candidates``; ``.to_dict()["verdict"]`` the verdict in words.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> tp.diagnose("measurements_unknown_effect.csv").missing_effect is None
    True
    """
    from .measurement.catalogue import catalogue as table_catalogue
    from .measurement.diagnosis import diagnose_measurements
    from .measurement.user_effects import load_catalogue

    table = _table_of(data, table)
    data = read_measurements(data, table)
    if ignore_sigma:
        data = data.without_sigma()
    files = [c for c in catalogue if isinstance(c, (str, Path))]
    user = (
        *load_catalogue(files, table),
        *(c for c in catalogue if not isinstance(c, (str, Path))),
    )
    return diagnose_measurements(
        data,
        until_explained=until_explained,
        catalogue=(*table_catalogue(table), *user) if user else None,
        turntable=table,
        outliers=outliers,
    )


# ---- designs --------------------------------------------------------------------------------
def _design_effects(table, effects, separate, calibrate, from_data, noise_arcsec) -> tuple:
    """The effects a :func:`design` mode plans for (the two of ``separate``, none to
    ``calibrate``, else ``effects``), refusing arguments of another mode."""
    modes = [
        m for m, given in (("separate", separate is not None), ("calibrate", calibrate)) if given
    ]
    if len(modes) > 1:
        raise InputError("design: give separate or calibrate, not both")
    if separate is not None:
        pair = separate.split(",") if isinstance(separate, str) else list(separate)
        if len(pair) != 2:
            raise InputError(f"separate takes two effects, got {pair}")
        if effects:
            raise InputError(
                "separate names the two effects to tell apart; effects is for identify"
            )
        return _effects([p.strip() for p in pair], table)
    if calibrate:
        if effects or from_data is not None or noise_arcsec is not None:
            raise InputError(
                "design(calibrate=True) needs the table, its limits and n_positions only "
                "(effects, from_data and noise_arcsec are for identify and separate)"
            )
        return ()
    return _effects(effects, table)


def _space_and_count(table, chosen, limits_deg, candidates, seed, n_positions):
    """:func:`design`'s candidate space and its checked number of positions (the defaults of
    ``design.space`` where None)."""
    from .core.sizes import check_positions_count
    from .design.space import DEFAULT_CANDIDATES, DEFAULT_POSITIONS, design_space

    space = design_space(
        table,
        chosen,
        limits_deg=limits_deg,
        candidates=DEFAULT_CANDIDATES if candidates is None else candidates,
        seed=seed,
    )
    count = check_positions_count(
        DEFAULT_POSITIONS if n_positions is None else n_positions,
        space.candidates_deg.shape[0],
        "n_positions",
        "more candidates",
    )
    return space, count


def design(
    table=None,
    n_positions: int | None = None,
    *,
    effects=(),
    from_data=None,
    separate: Sequence[str] | str | None = None,
    amplitudes: Mapping[str, Mapping[str, float]] | None = None,
    calibrate: bool = False,
    accuracy_dph: float = 0.01,
    noise_arcsec: float | None = None,
    dwell_s: float = 60.0,
    limits_deg=None,
    candidates: int | None = None,
    seed: int = 0,
):
    """Which positions to measure next (``turntable-pin design``): to identify the base errors
    and ``effects`` (D-optimal), to tell two apart (``separate``) or to ``calibrate``.

    Parameters
    ----------
    table : str, path or table, optional
        The table (:func:`load_table`; default the paper's).
    n_positions : int, optional
        Positions to choose (default 24, ``design.space.DEFAULT_POSITIONS``).
    effects : str or sequence, optional
        Effects to identify besides the base errors (as in :func:`fit`).
    from_data : path, DataFrame or measurements, optional
        Measurements already made: the design adds to them (their noise and amplitudes fitted).
    separate : (str, str) or "A,B", optional
        Two effects to tell apart (T-optimal positions).
    amplitudes : dict, optional
        With ``separate``: each effect's parameters, user units (default: fitted on from_data).
    calibrate : bool, default False
        GyroWheel calibration positions least sensitive to the table's errors.
    accuracy_dph : float, default 0.01
        With ``calibrate``: the required calibration accuracy, deg/h.
    noise_arcsec : float, optional
        1-sigma noise of a measured angle (default: fitted on ``from_data``, else 1).
    dwell_s : float, default 60.0
        Time per measurement, seconds.
    limits_deg : str or dict, optional
        The joints' ranges: ``"phi2=0:180"`` or ``{joint: (low, high)}``, degrees.
    candidates : int, optional
        Random candidate positions within the limits (seeded; default 10000).
    seed : int, default 0
        Seed of the candidates.

    Returns
    -------
    IdentifyDesign, SeparationDesign or CalibrationDesign
        ``.plan`` (the positions; ``.plan.write_csv(path)``), ``.report()`` (text).

    Examples
    --------
    >>> import turntable_pin as tp
    >>> plan = tp.design("turntable", 12, effects="inner_encoder_harmonics", candidates=500)
    >>> plan.n_positions
    12
    """
    table = load_table(table)
    chosen = _design_effects(table, effects, separate, calibrate, from_data, noise_arcsec)
    space, count = _space_and_count(table, chosen, limits_deg, candidates, seed, n_positions)
    if calibrate:
        from .design.calibrate import design_calibration

        return design_calibration(space, count, accuracy_dph=accuracy_dph)
    data = None if from_data is None else read_measurements(from_data, table)
    if separate is None:
        from .design.identify import design_identify

        return design_identify(
            space, count, from_data=data, noise_arcsec=noise_arcsec, dwell_s=dwell_s
        )
    from .design.separate import design_separate

    return design_separate(
        space, count, from_data=data, amplitudes=dict(amplitudes or {}),
        noise_arcsec=noise_arcsec, dwell_s=dwell_s,
    )  # fmt: skip


# ---- allocation and calibration -------------------------------------------------------------
def allocate(
    table=None,
    *,
    limits_arcmin: Sequence[float] | None = None,
    weights: str = "model",
    lower_bounds=None,
    grid_step_deg: float | None = None,
):
    """Allocate the table's angular error tolerances to meet orientation limits
    (``turntable-pin allocate``; the paper's eqs. 29-34).

    Parameters
    ----------
    table : str, path or table, optional
        The table (:func:`load_table`; default the paper's).
    limits_arcmin : (3,) floats, optional
        Limits of |dpsi|, |dtheta|, |dgamma|, arcmin (default: the calibration layer's
        orientation requirement for 0.01 deg/h).
    weights : {"model", "paper", "equal"}, default "model"
        W = 1/sensitivity from the exact model, the paper's Figure 8, or equal.
    lower_bounds : path, optional
        Manufacturing lower bounds (YAML) in the table's error names (default: the table's
        bundled ones, else none).
    grid_step_deg : float, optional
        Grid of the sensitivities, degrees (default by table: 1, 5, 15 for 1, 2, 3 joints).

    Returns
    -------
    Allocation
        ``.upper_bounds_rad`` (the tolerances, in ``.error_names`` order), ``.report()``,
        ``.sensitivities``, ``.worst_case_rad``.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> allocation = tp.allocate(limits_arcmin=(0.6, 0.25, 0.45))
    >>> len(allocation.error_names) == len(allocation.upper_bounds_rad)
    True
    """
    from .allocation.capability import ManufacturingCapability
    from .allocation.solver import OrientationLimits, allocate_tolerances

    table = load_table(table)
    limits = None if limits_arcmin is None else OrientationLimits.from_arcmin(*limits_arcmin)
    capability = (
        None
        if lower_bounds is None
        else ManufacturingCapability.from_yaml(bundled_path(lower_bounds), table)
    )
    return allocate_tolerances(
        limits, weights, capability, table=table, grid_step_deg=grid_step_deg
    )


def calibrate(
    run,
    *,
    table=None,
    latitude_deg: float | None = None,
    diagnose: bool = False,
    until_explained: bool = False,
    outliers: bool = True,
):
    """Fit a GyroWheel calibration run's drift coefficients, or diagnose the run
    (``turntable-pin calibrate``, ``calibrate --diagnose``).

    Parameters
    ----------
    run : path
        The calibration run CSV (``docs/measurements.md``; a bundled example by name, e.g.
        ``"gyrowheel_run_example.csv"``).
    table : str, path or table, optional
        The table the run was made on (:func:`load_table`; default the paper's).
    latitude_deg : float, optional
        The site's latitude, degrees (default the package's site).
    diagnose : bool, default False
        Instead of the fit, the run's diagnosis: the table or the GyroWheel?
    until_explained, outliers : bool
        With ``diagnose``: as in :func:`diagnose`.

    Returns
    -------
    CalibrationResult or Diagnosis
        The seven coefficients of both axes with standard errors (``.x``, ``.y``,
        ``.report()``), or with ``diagnose`` the run's :class:`Diagnosis`.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> result = tp.calibrate("gyrowheel_run_example.csv")
    >>> result.x.rank
    7
    """
    from .calibration.drift_fit import calibrate_read_run
    from .calibration.run import read_run, refuse_copied_rows
    from .calibration.site import DEFAULT_LATITUDE_DEG
    from .core.units import deg_to_rad

    table = load_table(table)
    latitude = DEFAULT_LATITUDE_DEG if latitude_deg is None else latitude_deg
    data = read_run(bundled_path(run), deg_to_rad(latitude), table)
    if not diagnose:
        return calibrate_read_run(data)
    from .instrument.diagnosis import diagnose_run
    from .instrument.effects import run_catalogue

    refuse_copied_rows(data)
    return diagnose_run(
        data, until_explained=until_explained, outliers=outliers, catalogue=run_catalogue(table)
    )


# ---- TPOINT runs ----------------------------------------------------------------------------
def import_tpoint(
    path,
    *,
    mount: str | None = None,
    refraction: str | None = None,
    latitude_deg: float | None = None,
    azimuth_origin: str = "south",
    azimuth_direction: str = "east",
):
    """A TPOINT pointing run converted to orientation measurements of the bundled mount
    (``turntable-pin import-tpoint``).

    Parameters
    ----------
    path : str or path
        The TPOINT file (bundled: ``"mmt_pointing/k_and_e.dat"``).
    mount : {"altaz", "equatorial"}, optional
        The mount, when the file has no ``: ALTAZ`` / ``: EQUAT`` line.
    refraction : {"apply", "none"}, optional
        Lift the observed positions by the Saemundsson refraction (default: none for alt-az
        files, apply for equatorial ones).
    latitude_deg : float, optional
        The polar axis' latitude of an equatorial mount, degrees (default: the file's).
    azimuth_origin : {"south", "north"}, default "south"
        Where the file's azimuth is 0 (TPOINT's: south).
    azimuth_direction : {"east", "west"}, default "east"
        On which side the file's azimuth 90 lies (TPOINT's: east).

    Returns
    -------
    TpointConversion
        ``.run`` (the file read), the rows (``.phi_deg``, ``.dpsi_arcsec``,
        ``.dtheta_arcsec``); :func:`read_measurements` and :func:`load_table` take it.

    Examples
    --------
    >>> import turntable_pin as tp
    >>> run = tp.import_tpoint("mmt_pointing/k_and_e.dat")
    >>> run.run.n_stars, run.urdf_name
    (80, 'altaz_mount.urdf')
    """
    from .measurement.tpoint import convert_tpoint, read_tpoint

    run = read_tpoint(
        bundled_path(path),
        mount=mount,
        azimuth_origin=azimuth_origin,
        azimuth_direction=azimuth_direction,
    )
    return convert_tpoint(run, refraction=refraction, latitude_deg=latitude_deg)
