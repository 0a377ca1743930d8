"""Effects the user brings without editing the package: effect files, modules, plug-ins, terms.

- An **effect file** (YAML, ``docs/measurements.md`` section 4b) declares one effect as a list of
  terms (:mod:`~turntable_pin.measurement.effect_terms`) with its story: :func:`read_effect_file`.
- A **Python module** (``FILE.py``) defines :class:`Effect` subclasses (built without arguments)
  or instances: :func:`load_effects_module` loads it from its path.
- An installed package may declare effects in the entry point group ``turntable_pin.effects``
  (each entry an ``Effect`` subclass or instance, or a sequence of them): :func:`installed_effects`
  loads them, only when called.
- An **inline term** (``dphi_z2~h3(phi2)``) is an effect of one term named by its text.

:func:`resolve_effects` turns the items of a fit's ``effects`` (catalogue names, effect files and
inline terms) into effects; :func:`load_catalogue` reads the ``catalogue`` files. Every
problem is an :class:`InputError` of one line naming the file, the line or key, and what is wrong.
"""

from __future__ import annotations

import importlib.metadata
import math
import re
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path

import numpy as np

from ..core.exceptions import InputError
from ..core.files import read_yaml_lines
from ..core.user_code import call_user, class_file, import_module_file, is_user_code
from ..core.words import argument
from .catalogue import catalogue, resolve_effect
from .effect_terms import (
    MAX_HARMONIC_ORDER,
    MAX_POLYNOMIAL_DEGREE,
    EffectTerm,
    parse_orders,
    parse_term,
)
from .effects.base import ANY_MACHINE, MOUNT, TURNTABLE, Effect, Plausibility, PositionVariables
from .effects.contract import check_effect_on_probe, check_story, checked_parameters
from .effects.declared import DeclaredEffect
from .table import measured_table

__all__ = [
    "ENTRY_POINT_GROUP",
    "EFFECT_FILE_KEYS",
    "PLAUSIBLE_KEYS",
    "TERM_KEYS",
    "check_user_effect_names",
    "check_user_effects",
    "describe_effects",
    "effect_definition",
    "effect_files_named",
    "inline_effect",
    "installed_effects",
    "load_catalogue",
    "load_effects_module",
    "MAX_EFFECT_TERMS",
    "load_effects_modules",
    "read_effect_file",
    "resolve_effects",
]

ENTRY_POINT_GROUP = "turntable_pin.effects"
"""The entry point group where installed packages declare effects."""
EFFECT_FILE_KEYS = ("format", "name", "title", "explanation", "confirm", "terms", "plausible")
"""The keys of an effect file (``name`` and ``terms`` required)."""
TERM_KEYS = ("site", "harmonics", "polynomial", "sign", "of", "prefix")
"""The keys of a term of an effect file (``site`` and one of harmonics/polynomial/sign)."""
EFFECT_FILE_SUFFIXES = (".yaml", ".yml")
MAX_EFFECT_TERMS = 100
"""Most terms of one effect file. An effect is one physical story (a few terms: a harmonic of
two sites, a drift and its sign); each term may bring up to 200 parameters, and every fit and
diagnosis carries them all."""
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.@-]*$")


def _key_text(where: tuple) -> str:
    out = ""
    for part in where:
        out += f"[{part + 1}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def read_effect_file(path: str | Path, turntable=None) -> Effect:
    """The effect declared in the YAML file ``path`` for ``turntable`` (default: the paper's).

    Raises:
        InputError: unreadable or invalid YAML (:func:`~turntable_pin.core.files.read_yaml`:
            a file of at most 1 MB), a key given twice, an unknown or missing key, a bad value,
            more than :data:`MAX_EFFECT_TERMS` terms; one line naming the file, the line and the
            key.
    """
    path = Path(path)
    table = measured_table(turntable)
    doc, lines = read_yaml_lines(path)

    def fail(where: tuple, message: str):
        key = _key_text(where)
        line = lines.get(where)
        return InputError(f"{key}: {message}" if key else message, path=path, line=line)

    story = _effect_story(doc, fail)
    items = doc["terms"]
    if not isinstance(items, list) or not items:
        raise fail(("terms",), "expected a list of at least one term")
    if len(items) > MAX_EFFECT_TERMS:
        raise fail(("terms",), f"{len(items):,} terms; an effect file holds at most "
                               f"{MAX_EFFECT_TERMS} (one physical effect; write several files "
                               "for several effects)")  # fmt: skip
    terms = []
    for i, item in enumerate(items):
        term = _file_term(item, ("terms", i), fail)
        try:
            terms.append(parse_term(term, table) if isinstance(term, str) else term.check(table))
        except InputError as exc:
            raise fail(("terms", i), exc.detail) from None
    twice = _repeated(s.name for t in terms for s in t.parameters())
    if twice:
        raise fail(("terms",), f"parameter(s) {', '.join(twice)} would be defined twice; give "
                               "the terms different 'prefix' values (e.g. x_, z_)")  # fmt: skip
    units = dict.fromkeys(s.unit for t in terms for s in t.parameters())
    plausibility = _file_plausibility(doc.get("plausible"), story["name"], units, fail)
    return DeclaredEffect(story["name"], terms, title=story["title"],
                          explanation=story["explanation"], confirm=story["confirm"],
                          source=str(path), plausibility=plausibility)  # fmt: skip


PLAUSIBLE_KEYS = {"turntable": TURNTABLE, "telescope_mount": MOUNT, "any": ANY_MACHINE}
"""The machine keys of an effect file's ``plausible`` (its ``belief`` besides)."""


def _file_plausibility(value, name: str, units, fail) -> tuple[Plausibility, ...]:
    """The :class:`Plausibility` of an effect file's ``plausible`` mapping (none without one):
    the root-sum-square of all its parameters may reach ``turntable`` / ``telescope_mount`` /
    ``any`` (numbers > 0, in the parameters' one unit); ``belief`` a text with ``{amplitude}``."""
    if value is None:
        return ()
    keys = ", ".join([*PLAUSIBLE_KEYS, "belief"])
    if not isinstance(value, dict) or not value:
        raise fail(("plausible",), f"expected a mapping of {keys}")
    scale = {}
    for key, number in value.items():
        if key == "belief":
            continue
        if key not in PLAUSIBLE_KEYS:
            raise fail(("plausible", key), f"unknown key; the keys of plausible: {keys}")
        if isinstance(number, bool) or not isinstance(number, int | float) or not (
            math.isfinite(number) and number > 0
        ):  # fmt: skip
            raise fail(("plausible", key), f"expected a number > 0, got {number!r}")
        scale[PLAUSIBLE_KEYS[key]] = float(number)
    if not scale:
        raise fail(("plausible",), f"no scale given; give one of {', '.join(PLAUSIBLE_KEYS)}")
    if len(units) > 1:
        raise fail(("plausible",), f"its parameters have several units ({', '.join(units)}); "
                                   "one scale needs one unit")  # fmt: skip
    belief = value.get("belief", f"{name} of {{amplitude}}")
    if not isinstance(belief, str) or "{amplitude}" not in belief or belief.count("{") != 1:
        raise fail(("plausible", "belief"), "expected a text with {amplitude} once (and no "
                                            "other braces)")  # fmt: skip
    return (Plausibility((), scale, " ".join(belief.split()), next(iter(units), "")),)


def _effect_story(doc, fail) -> dict[str, str]:
    """The ``name, title, explanation, confirm`` of an effect file's ``doc``, its keys checked;
    ``fail(where, message)`` makes the error."""
    if not isinstance(doc, dict):
        raise fail((), "expected a mapping with the keys name, terms (and title, explanation, "
                       "confirm)")  # fmt: skip
    for key in doc:
        if key not in EFFECT_FILE_KEYS:
            raise fail((key,), f"unknown key; the keys of an effect file: "
                               f"{', '.join(EFFECT_FILE_KEYS)}")  # fmt: skip
    for key in ("name", "terms"):
        if key not in doc:
            raise fail((), f"the key '{key}' is missing")
    if "format" in doc and doc["format"] != 1:
        raise fail(("format",), f"format {doc['format']!r} is not known; this version reads 1")
    story = {}
    for key in ("name", "title", "explanation", "confirm"):
        value = doc.get(key, "")
        if not isinstance(value, str) or (key == "name" and not value.strip()):
            raise fail((key,), "expected a text" + (" (not empty)" if key == "name" else ""))
        story[key] = " ".join(value.split())
    if not _NAME.match(story["name"]):
        raise fail(("name",), f"'{story['name']}': use letters, digits and _ . @ - (no spaces, "
                              "commas or '~'), starting with a letter")  # fmt: skip
    return story


def _file_term(item, where: tuple, fail) -> EffectTerm | str:
    """The term ``item`` of an effect file at ``where``: an inline term as given, a mapping of
    :data:`TERM_KEYS` as an unchecked :class:`EffectTerm`; ``fail(where, message)`` makes the
    error."""
    if isinstance(item, str):
        return item
    if not isinstance(item, dict):
        raise fail(where, "expected a term: a mapping (site, harmonics|polynomial|sign, of) "
                          "or an inline term such as dphi_z2~h3(phi2)")  # fmt: skip
    for key in item:
        if key not in TERM_KEYS:
            raise fail((*where, key), f"unknown key; the keys of a term: {', '.join(TERM_KEYS)}")
    shapes = [k for k in ("harmonics", "polynomial", "sign") if k in item]
    if "site" not in item or len(shapes) != 1:
        raise fail(where, "a term needs 'site' and exactly one of harmonics, polynomial, sign")
    shape = shapes[0]
    for key in ("site", "prefix", *(("sign",) if shape == "sign" else ("of",))):
        if key in item and not isinstance(item[key], str):
            raise fail((*where, key), "expected a text")
    if shape == "sign":
        if "of" in item:
            raise fail((*where, "of"), "a sign term names its column in 'sign' (sign: dir1)")
        variable, orders = item["sign"], ()
    else:
        if "of" not in item:
            raise fail(where, f"a {shape} term needs 'of' (the variable: "
                              + ("phi1, phi2, phi1+phi2, ...)" if shape == "harmonics"
                                 else "a column such as temperature_c)"))  # fmt: skip
        variable = item["of"]
        orders = _file_orders(item[shape], shape)
        if isinstance(orders, str):
            raise fail((*where, shape), orders)
    return EffectTerm(item["site"].strip(), shape, variable.strip(), orders,
                      item.get("prefix", "").strip())  # fmt: skip


def _repeated(names: Iterable[str]) -> list[str]:
    """The names that occur more than once, sorted (in time linear in their number)."""
    seen: set[str] = set()
    twice: set[str] = set()
    for name in names:
        (twice if name in seen else seen).add(name)
    return sorted(twice)


def _file_orders(value, shape: str) -> tuple[int, ...] | str:
    """The orders of ``harmonics:`` (an order, a list, ``"A..B"``) or the powers of a
    ``polynomial:`` degree; a message when ``value`` is not one."""
    if shape == "polynomial":
        if isinstance(value, bool) or not isinstance(value, int):
            return f"expected the degree, a whole number 1..{MAX_POLYNOMIAL_DEGREE}"
        if value < 1:
            return "the degree must be >= 1"
        if value > MAX_POLYNOMIAL_DEGREE:  # before a range of that many powers
            return f"polynomial degree {value}: expected 1..{MAX_POLYNOMIAL_DEGREE}"
        return tuple(range(1, value + 1))
    if isinstance(value, str):
        try:
            return parse_orders(value.strip(), "orders")
        except InputError as exc:
            return exc.detail
    values = value if isinstance(value, list) else [value]
    if not values or any(isinstance(v, bool) or not isinstance(v, int) for v in values):
        return (f"expected an order, a list of orders or a range 'A..B' (whole numbers "
                f"1..{MAX_HARMONIC_ORDER})")  # fmt: skip
    return tuple(values)


def inline_effect(text: str, turntable=None) -> Effect:
    """The effect of one inline term (``dphi_z2~h3(phi2)``), named by its text."""
    term = parse_term(text, measured_table(turntable))
    return DeclaredEffect(term.spec(), [term], source="inline term")


def _effects_in(objects: Iterable, where: str, base: type = Effect, path=None) -> list:
    """The effects among ``objects``: instances of ``base``, and its subclasses built without
    arguments (the user's code: a failure is reported as theirs, :func:`call_user`)."""
    out = []
    for obj in objects:
        if isinstance(obj, type) and issubclass(obj, base) and obj is not base:
            what = f"class {obj.__qualname__}: {obj.__qualname__}() (built without arguments)"
            obj = call_user(what if path else f"{where}: {what}", obj, path=path)
        if isinstance(obj, base):
            out.append(obj)
    return out


def load_effects_module(path: str | Path, base: type = Effect) -> tuple:
    """The effects a Python file defines, in order: instances of :class:`Effect` (or of ``base``:
    a run's ``RunEffect``) and the subclasses defined there (built without arguments), each
    with the file as its ``source``. Importing the file runs its top level
    (:func:`~turntable_pin.core.user_code.import_module_file`); the effects are checked by
    :func:`check_user_effects` (orientation) or ``check_user_run_effects`` (runs), not here.

    Raises:
        InputError: the file cannot be read or defines no effect.
        UserCodeError: importing it, or building an effect, raised an exception or called
            ``sys.exit`` (the file, the line and the message).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError("no such Python file", path=path)
    module_name = f"turntable_pin_user_effects_{abs(hash(str(path.resolve())))}"
    module = import_module_file(path, module_name)
    objects = [
        obj for obj in vars(module).values()
        if not (isinstance(obj, type) and obj.__module__ != module_name)
    ]  # fmt: skip
    effects = _effects_in(objects, str(path), base, path)
    if not effects:
        where = f"{base.__module__.replace('.base', '')}.{base.__name__}"
        raise InputError(
            f"defines no effect (expected subclasses of {where} or instances of them)", path=path
        )
    for effect in effects:
        _set_source(effect, str(path))
    return tuple(effects)


def _set_source(effect, source: str) -> None:
    """Record where ``effect`` came from (for messages and listings), unless it says so itself."""
    if not isinstance(getattr(effect, "source", None), str) or not effect.source:
        try:
            effect.source = source
        except AttributeError:  # a read-only object: named by its class alone
            pass


def load_effects_modules(paths: Sequence[str | Path], turntable=None) -> tuple[Effect, ...]:
    """The orientation effects of the Python files ``paths`` (:func:`load_effects_module`),
    checked by :func:`check_user_effects` (names, and the contract on a probe)."""
    effects = [e for path in paths for e in load_effects_module(path)]
    return check_user_effects(effects, turntable)


def installed_effects() -> tuple[Effect, ...]:
    """The effects installed packages declare in the entry point group ``turntable_pin.effects``
    (loaded now; nothing is loaded before this is called).

    Raises:
        InputError: an entry point that holds no effect.
        UserCodeError: an entry point that fails to load (its code raised).
    """
    out: list[Effect] = []
    for ep in importlib.metadata.entry_points(group=ENTRY_POINT_GROUP):
        where = f"entry point '{ep.name}' ({ep.value}) of {ENTRY_POINT_GROUP}"
        obj = call_user(f"{where}: loading it", ep.load)
        objects = obj if isinstance(obj, list | tuple) else [obj]
        found = _effects_in(objects, where)
        if not found:
            raise InputError(f"{where}: holds no Effect subclass or instance")
        for effect in found:
            _set_source(effect, f"entry point {ep.name}")
        out += found
    return tuple(out)


def effect_definition(effect) -> str:
    """Where ``effect`` is defined, for messages: ``FILE, line L`` (the ``name`` of an effect
    file), ``FILE (class C)`` (a class of a module or plug-in), ``the inline term T`` or
    ``module.Class`` (the package's own)."""
    source = getattr(effect, "source", "")
    source = source if isinstance(source, str) else ""
    if isinstance(effect, DeclaredEffect):
        if source.lower().endswith(EFFECT_FILE_SUFFIXES):
            line = _name_line(Path(source))
            return f"{source}, line {line}" if line else source
        if source == "inline term":
            return f"the inline term {effect.name}"
        return source or argument("effects")
    cls = type(effect)
    if is_user_code(effect):
        return f"{source or class_file(cls) or 'Python'} (class {cls.__qualname__})"
    return f"{cls.__module__}.{cls.__qualname__}"


def _name_line(path: Path) -> int | None:
    """The line of an effect file's top-level ``name:`` key (for a message: no YAML is parsed;
    ``None`` when it is not written so, in a flow mapping for instance)."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    for number, line in enumerate(text.splitlines(), 1):
        if re.match(r"""^["']?name["']?\s*:""", line):
            return number
    return None


def check_user_effect_names(
    effects: Sequence, turntable=None, others: Sequence = (), taken: Mapping | None = None
) -> tuple:
    """``effects`` if each has a usable name (letters, digits and ``_ . @ -``), taken neither by
    the catalogue nor by another of ``effects`` or of ``others`` (user effects already
    accepted). ``taken``: ``{name: effect}`` of the catalogue (default: the table's orientation
    catalogue; a run's diagnosis passes its own).

    Raises:
        InputError: a bad name, or a name taken: naming both definitions (file and line of an
            effect file, file and class of a module's effect).
    """
    if taken is None:
        taken = {e.name: e for e in catalogue(turntable)}
    seen: dict[str, Effect] = {e.name: e for e in others}
    for effect in effects:
        where = effect_definition(effect)
        name = getattr(effect, "name", "")
        if not isinstance(name, str) or not _NAME.match(name):
            shown = f"'{name}'" if isinstance(name, str) else f"{type(name).__name__} {name!r}"
            raise InputError(f"{where}: an effect needs a name (its 'name'): letters, digits and "
                             f"_ . @ - (no spaces, commas or '~'), starting with a letter; got "
                             f"{shown}")  # fmt: skip
        if name in taken:
            raise InputError(f"{where}: effect '{name}' is already in the catalogue "
                             f"({effect_definition(taken[name])}); give yours another "
                             "name")  # fmt: skip
        if name in seen:
            raise InputError(f"{where}: effect '{name}' is also defined by "
                             f"{effect_definition(seen[name])}; give one of them another "
                             "name")  # fmt: skip
        seen[name] = effect
    return tuple(effects)


def check_user_effects(effects: Sequence[Effect], turntable=None) -> tuple[Effect, ...]:
    """``effects`` if their names pass :func:`check_user_effect_names` and each effect of the
    user's code (a module's, a plug-in's, an object from Python) keeps its contract on a probe
    (:func:`~.effects.contract.check_effect_on_probe`); the data are checked where they meet
    the effects (:class:`~.effect_model.OrientationModel`).

    Raises:
        InputError: a bad or taken name.
        UserCodeError: an effect that raises or breaks its contract (one line: file, effect,
            method, what it returned and what was expected).
    """
    table = measured_table(turntable)
    for effect in effects:
        if is_user_code(effect):
            check_story(effect, Effect)
    check_user_effect_names(effects, table)
    for effect in effects:
        if is_user_code(effect):
            check_effect_on_probe(effect, table)
    return tuple(effects)


def load_catalogue(paths: Sequence[str | Path], turntable=None) -> tuple[Effect, ...]:
    """The effects of ``catalogue`` files (``.yaml``/``.yml`` effect files, ``.py`` modules)
    followed by the installed ones (:func:`installed_effects`), checked by
    :func:`check_user_effects`."""
    effects: list[Effect] = []
    for path in map(Path, paths):
        if path.suffix.lower() in EFFECT_FILE_SUFFIXES:
            effects.append(read_effect_file(path, turntable))
        elif path.suffix.lower() == ".py":
            effects += load_effects_module(path)
        else:
            raise InputError("an effect catalogue is a .yaml/.yml effect file or a .py module",
                             path=path)  # fmt: skip
    return check_user_effects([*effects, *installed_effects()], turntable)


def _effect_items(text: str) -> list[str]:
    """The items of one ``effects`` text: comma-separated, stripped, empty ones left out."""
    return [x for x in (x.strip() for x in str(text).split(",")) if x]


def _is_effect_file(item: str) -> bool:
    """Whether an item of ``effects`` (not an inline term) names an effect file."""
    return "~" not in item and item.lower().endswith(EFFECT_FILE_SUFFIXES)


def effect_files_named(text: str) -> tuple[Path, ...]:
    """The effect files an ``effects`` text names (the items :func:`resolve_effects` reads as
    files), for the command line's check that no output is written over an input."""
    return tuple(Path(item) for item in _effect_items(text) if _is_effect_file(item))


def resolve_effects(
    items: Sequence[str], turntable=None, extra: Sequence[Effect] = ()
) -> tuple[Effect, ...]:
    """The effects of a fit's ``effects``: each item a comma-separated list of catalogue names
    (or names of ``extra`` or of installed effects), effect files (``.yaml``/``.yml``) and inline
    terms (``SITE~SHAPE(VAR)``); duplicates refused, empty items ignored."""
    out: list[Effect] = []
    installed: tuple[Effect, ...] | None = None
    for text in items:
        for item in _effect_items(text):
            if "~" in item:
                effect = inline_effect(item, turntable)
            elif _is_effect_file(item):
                effect = read_effect_file(item, turntable)
                # the same file given as a catalogue too is the same definition
                others = [e for e in extra if getattr(e, "source", None) != effect.source]
                check_user_effect_names([effect], turntable, others=others)
            else:
                try:
                    effect = resolve_effect(item, turntable, extra)
                except InputError as exc:
                    if installed is None:  # installed plug-ins are loaded only when needed
                        installed = installed_effects()
                    found = [e for e in installed if e.name == item]
                    if not found:
                        raise InputError(
                            f"{exc.detail}; or give an effect file (.yaml) or an inline term "
                            "such as dphi_z2~h3(phi2)"
                        ) from None
                    effect = found[0]
            if any(e.name == effect.name for e in out):
                raise InputError(f"effect '{effect.name}' is listed twice in {argument('effects')}")
            out.append(effect)
    return tuple(out)


def describe_effects(effects: Sequence[Effect], turntable=None) -> list[dict]:
    """Each effect's story with its parameters (``name, unit, description``) on a data set that
    has every column it needs, and where it comes from (``catalogue`` or its file)."""
    table = measured_table(turntable)
    j = table.n_joints
    columns = {c for e in effects for c in e.required_columns}
    extra = {c: np.zeros(1) for c in columns
             if c != "time_s" and not re.match(r"^(dir|phi)\d+$", c)}  # fmt: skip
    variables = PositionVariables(np.zeros((1, j)), np.zeros(1), (np.ones(1),) * j, extra)
    out = []
    for effect in effects:
        entry = effect.describe()
        entry["source"] = getattr(effect, "source", "") or "catalogue"
        entry["parameters"] = [
            {"name": p.name, "unit": p.unit, "description": p.description}
            for p in checked_parameters(effect, variables, "one position")
        ]
        out.append(entry)
    return out
