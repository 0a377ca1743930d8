"""What a candidate physical effect is: parameters, how it changes the kinematic chain, its story.

An effect changes the exact rotation chain of ``docs/model.md``, *linearly in its parameters* (the
angles it adds are ``sum_k weight_k(position) * p_k``), through terms:

- ``ChainTerm(site=<error name>, ...)``: added to one of the table's error angles, per position
  (encoder harmonics, wobble harmonics, backlash);
- ``ChainTerm(site="pre" | "post", axis=...)``: a rotation *before* ``Rt`` (base frame: base
  tilt) or *after* it (payload frame: gravity sag, thermal drift, payload mount);
- ``ChainTerm(site="measured", axis="dpsi"|"dtheta"|"dgamma")``: added to that measured angle
  itself, after the chain (a term of the instrument's reading, not of the table).

Terms of one site apply in order; :class:`OrientationModel` makes them factors of the chain and
differentiates them analytically.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Mapping, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from ...core.csv_table import missing_columns_words
from ...core.exceptions import InputError
from ...core.units import ARCSEC_PER_RAD
from ...model.named_effects import EffectText, Labels
from ...stats.candidate_effect import ANY_MACHINE, CandidateEffect, Plausibility

__all__ = [
    "ANY_MACHINE",
    "ARCSEC",
    "MOUNT",
    "Plausibility",
    "TURNTABLE",
    "angle_words",
    "plausible",
    "MEASURED",
    "POST",
    "PRE",
    "ChainTerm",
    "Effect",
    "EffectText",
    "Labels",
    "ParameterSpec",
    "PositionVariables",
    "harmonic_parameters",
    "harmonic_weights",
]

PRE = "pre"
"""Site of a :class:`ChainTerm` applied before ``Rt`` (in the base frame)."""
POST = "post"
"""Site of a :class:`ChainTerm` applied after ``Rt`` (in the payload frame)."""
MEASURED = "measured"
"""Site of a :class:`ChainTerm` added to a measured angle itself (``axis``: ``dpsi``, ...)."""


@dataclass(frozen=True)
class ParameterSpec:
    """One parameter of an effect.

    Attributes:
        name: short name, unique within the effect (``c1``, ``k``, ``rz``).
        unit: the user unit it is reported in (``arcsec``, ``arcsec/g``, ``arcsec/h``).
        per_user_unit: internal value (rad, rad/g, rad/s) of one user unit.
        description: what it is.
    """

    name: str
    unit: str
    per_user_unit: float
    description: str


ARCSEC = 1.0 / ARCSEC_PER_RAD
"""One arc second in radians."""

TURNTABLE = "turntable"
"""The machine kind of a precision turntable (the key of its plausible scales)."""
MOUNT = "telescope mount"
"""The machine kind of a telescope mount (the key of its plausible scales)."""


def plausible(
    parameters, belief: str, unit: str = "arcsec", *, turntable=None, mount=None, any_machine=None
) -> Plausibility:
    """A :class:`~turntable_pin.stats.candidate_effect.Plausibility` of ``parameters`` (names)
    with its scale on a precision turntable and on a telescope mount (or on any machine), in
    ``unit``; a kind given None is not judged (``docs/plausibility.md``)."""
    scale = {TURNTABLE: turntable, MOUNT: mount, ANY_MACHINE: any_machine}
    return Plausibility(
        tuple(parameters), {k: float(v) for k, v in scale.items() if v is not None}, belief, unit
    )


def angle_words(value: float, unit: str) -> str:
    """An amplitude in words: arc seconds (``arcsec``, ``arcsec/g``...) of a degree or more in
    degrees, of an arc minute or more in arc minutes."""
    if unit.startswith("arcsec"):
        rest = unit[len("arcsec") :]
        if abs(value) >= 3600.0:
            return f"{value / 3600.0:.3g} deg{rest}"
        if abs(value) >= 60.0:
            return f"{value / 60.0:.3g} arcmin{rest}"
    return f"{value:.3g} {unit}".strip()


@dataclass(frozen=True)
class ChainTerm:
    """An angle added to the chain: ``sum_k weights[k] * p_k`` (radians) at each position.

    Attributes:
        site: a base error name of the table, ``"pre"`` / ``"post"`` or ``"measured"``.
        axis: ``"x"``, ``"y"`` or ``"z"`` for ``pre`` / ``post`` terms, the measured angle
            (``"dpsi"``, ``"dtheta"``, ``"dgamma"``) for ``measured`` ones (unused otherwise).
        weights: ``{parameter name: array (N,)}`` multiplying that parameter per position.
    """

    site: str
    axis: str | None
    weights: dict[str, np.ndarray] = field(default_factory=dict)


@dataclass(frozen=True)
class PositionVariables:
    """What an effect may depend on at each of N positions (commanded values).

    Attributes:
        joint_rad: commanded joint angles (N, J), one column per revolute joint in chain order
            from the base (``phi1 .. phiJ``).
        time_s: time of each measurement (N,), or ``None`` when the data have no ``time_s``.
        dirs: per joint, the approach direction (N,) of ``dirK`` (+1/-1), or ``None``.
        extra: other numeric columns of the data file (``temperature_c``, ...), ``{name: (N,)}``.
        boresight_only: (N,) bool, or ``None`` (no such row): the rows whose roll about the
            payload's x axis (``dgamma``) is not measured while ``dpsi`` is. Such a row measures
            the direction of the x axis (a star's, an autocollimator's mirror normal), not a
            whole rotation, so its ``dpsi`` is compared without the twist about x: ``dR``'s
            swing, whose entry (0, 2) is ``-dR[2, 0]`` (``docs/measurements.md``, section 1).
        ignored_columns: columns of the data file left out as not numbers (text or empty
            throughout): present, so an effect that needs one is told so, not that it is absent.
    """

    joint_rad: np.ndarray
    time_s: np.ndarray | None = None
    dirs: tuple[np.ndarray | None, ...] = ()
    extra: Mapping[str, np.ndarray] = field(default_factory=dict)
    boresight_only: np.ndarray | None = None
    ignored_columns: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        joints = np.asarray(self.joint_rad, dtype=float)  # no copy of read-only data arrays
        if joints.ndim == 1:
            joints = joints[:, None]
        if joints.flags.writeable:
            joints = joints.copy()
            joints.setflags(write=False)
        object.__setattr__(self, "joint_rad", joints)
        dirs = tuple(self.dirs) + (None,) * (joints.shape[1] - len(self.dirs))
        object.__setattr__(self, "dirs", dirs[: joints.shape[1]])
        if self.boresight_only is not None:
            rows = np.array(self.boresight_only, dtype=bool).reshape(-1)
            if rows.shape[0] != joints.shape[0]:
                raise ValueError(
                    f"boresight_only has {rows.shape[0]} rows, the positions {joints.shape[0]}"
                )
            rows.setflags(write=False)
            object.__setattr__(self, "boresight_only", rows if rows.any() else None)

    def memo(
        self, key: tuple, keep: tuple, compute: Callable[[], Any], *, weak: bool = False
    ) -> Any:
        """``compute()``, once for these variables: the models built on one data set (the base
        and every candidate of a diagnosis) share what they compute from it (the stacked gains
        of their effects' terms). ``key`` names the value, with the ``id`` of the objects ``keep``
        it depends on; the memo holds those objects, and a key whose objects are not the same
        ones (by identity) is computed anew. With ``weak`` the memo holds the value only while
        something else does (a value only some models use goes with them)."""
        store = self.__dict__.setdefault("_memo", {})
        found = store.get(key)
        if found is not None and len(found[0]) == len(keep):
            if all(a is b for a, b in zip(found[0], keep, strict=True)):
                value = found[1]() if weak else found[1]
                if value is not None:
                    return value
        value = compute()
        store[key] = (tuple(keep), weakref.ref(value) if weak else value)
        return value

    def __getstate__(self) -> dict:
        """The fields (for pickle and copy): the memo stays behind."""
        return {k: v for k, v in self.__dict__.items() if k != "_memo"}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)

    @classmethod
    def of(cls, positions, extra=None, boresight_only=None) -> PositionVariables:
        """The variables of a :class:`~turntable_pin.calibration.positions.PositionSet`: its
        angles, ``time_s`` and approach directions, with the ``extra`` columns."""
        return cls(
            positions.angles_rad, positions.time_s, positions.dirs, dict(extra or {}),
            boresight_only,
        )  # fmt: skip

    @property
    def n(self) -> int:
        """Number of positions N."""
        return int(self.joint_rad.shape[0])

    @property
    def n_joints(self) -> int:
        """Number of joints J."""
        return int(self.joint_rad.shape[1])

    def angle(self, k: int) -> np.ndarray:
        """The commanded angle of joint ``k`` (1 = the base-most joint), rad (N,); refused
        (:class:`InputError`) when the positions have no joint ``k`` (``phi2_rad`` of a one-joint
        table)."""
        if not 1 <= k <= self.n_joints:
            raise InputError(f"these positions have {self.n_joints} joint(s), no joint {k}")
        return self.joint_rad[:, k - 1]

    def column(self, name: str) -> np.ndarray | None:
        """The data column ``name``: ``time_s``, ``dirK``, ``phiK`` (rad) or an extra column."""
        if name == "time_s":
            return self.time_s
        for prefix, values in (("dir", self.dirs), ("phi", tuple(self.joint_rad.T))):
            if name.startswith(prefix) and name[len(prefix) :].isdigit():
                k = int(name[len(prefix) :])
                return values[k - 1] if 1 <= k <= len(values) else None
        return self.extra.get(name)

    def has(self, column: str) -> bool:
        """Whether the data column ``column`` (``time_s``, ``dirK``, an extra one) is present."""
        return self.column(column) is not None

    def missing_columns_words(self, missing: Sequence[str]) -> str:
        """Why the columns ``missing`` cannot be used: absent from the data, or present but not
        numbers (:func:`~turntable_pin.core.csv_table.missing_columns_words`)."""
        return missing_columns_words(missing, self.ignored_columns, "the data")


def harmonic_weights(angle_rad: np.ndarray, prefix: str = "") -> dict[str, np.ndarray]:
    """Weights of ``h(a) = c1 cos a + s1 sin a + c2 cos 2a + s2 sin 2a`` (``prefix + c1``...)."""
    a = np.asarray(angle_rad, dtype=float)
    return {
        f"{prefix}c1": np.cos(a),
        f"{prefix}s1": np.sin(a),
        f"{prefix}c2": np.cos(2 * a),
        f"{prefix}s2": np.sin(2 * a),
    }


def harmonic_parameters(prefix: str, what: str, angle: str) -> tuple[ParameterSpec, ...]:
    """The four :class:`ParameterSpec` of a harmonic series of ``what`` in ``angle`` (arcsec)."""
    return (
        ParameterSpec(f"{prefix}c1", "arcsec", ARCSEC, f"{what}: cos({angle}) coefficient"),
        ParameterSpec(f"{prefix}s1", "arcsec", ARCSEC, f"{what}: sin({angle}) coefficient"),
        ParameterSpec(f"{prefix}c2", "arcsec", ARCSEC, f"{what}: cos(2 {angle}) coefficient"),
        ParameterSpec(f"{prefix}s2", "arcsec", ARCSEC, f"{what}: sin(2 {angle}) coefficient"),
    )


class Effect(CandidateEffect):
    """Base class of a candidate physical effect of orientation data: a
    :class:`~turntable_pin.stats.candidate_effect.CandidateEffect` (name, story, required
    columns, parameters) that changes the kinematic chain. Subclasses set the class attributes
    and implement :meth:`parameters` and :meth:`chain_terms`.

    Args:
        name, text: the name and story a table gives this effect instead of the class's.
        default: the class's story (the class attributes otherwise).

    Attributes:
        name: the catalogue name (``inner_encoder_harmonics``; ``docs/measurements.md``, section 4).
        kind: the physical effect (``encoder_harmonics``...); a per-joint one is named
            ``<kind>@<joint>`` unless its table names it otherwise.
        joints: the joints it is an effect of (per-joint kinds; empty for table-wide ones).
        title: a few words for people.
        definition: how it changes the chain, as ``docs/measurements.md`` defines it.
        explanation: one paragraph of physics.
        confirm: how to confirm it on the machine.
        required_columns: data columns it needs; with ``any_column=True`` one of them suffices.
    """

    kind: str = ""
    joints: tuple[str, ...] = ()

    def __init__(self, name=None, text: EffectText | None = None, default=None) -> None:
        self.name = name or self.name
        for story in (default, text):
            for key, value in asdict(story or EffectText()).items():
                if value is not None:
                    setattr(self, key, value)

    def parameters(self, variables: PositionVariables) -> tuple[ParameterSpec, ...]:
        """The parameters this effect has on a data set with these variables."""
        raise NotImplementedError

    def amount_words(self, value: float, unit: str) -> str:
        """An amplitude in words (:func:`angle_words`)."""
        return angle_words(value, unit)

    def chain_terms(self, variables: PositionVariables) -> tuple[ChainTerm, ...]:
        """How it changes the chain at each position (see the module docstring).

        A function of ``variables`` alone: the models built on one data set share the gains of
        an effect's terms (:meth:`PositionVariables.memo`), so the same effect object must give
        the same terms for the same variables."""
        raise NotImplementedError
