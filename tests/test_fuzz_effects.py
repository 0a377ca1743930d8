"""Property-based fuzzing of the effects a user brings: Python effect modules (orientation effects,
``Effect``; calibration-run effects, ``RunEffect``) and YAML effect files, each with random breaks
of its contract.

A module gets one to three breaks: weights or columns of the wrong shape, NaN or inf (at the
probe, or only on the data), values of the wrong type, methods that raise or call ``sys.exit``,
no parameter, an unknown or an unweighed one, a bad scale, a bad site or side, a name taken by the
catalogue or by a second class, a failing import or constructor. An effect file gets one
structural break: a missing or unknown key, a value of the wrong type, a bad site, variable, order
or degree, a parameter defined twice, a catalogue name, a key given twice, no mapping at all.

Whatever the break, every command that takes the effect (``fit``, ``diagnose``, ``effects``,
``simulate``; ``calibrate --diagnose``, ``calibrate --effects``, ``design --separate --run``)
ends with exit status 2 and one line on stderr naming the file; never a traceback, never a
warning, nothing written (``fuzzing.run_and_check``).
"""

from __future__ import annotations

import shutil
import string
import tempfile
from pathlib import Path

import pytest
import yaml
from hypothesis import given
from hypothesis import strategies as st

from conftest import EXAMPLES_DIR, cli
from fuzzing import example_folder, fuzz, run_and_check, scratch_folder

pytestmark = pytest.mark.slow

RUN = EXAMPLES_DIR / "runs" / "run_clean.csv"
DATA_POSITIONS = 32
"""Positions of the measurement file the orientation commands read (the probe has 7)."""


@pytest.fixture(scope="module")
def scratch():
    """A folder for the examples: each example gets (and removes) a subfolder of it."""
    yield from scratch_folder()


def _small_measurements() -> str:
    """A small simulated measurement file (32 positions)."""
    folder = Path(tempfile.mkdtemp())
    try:
        path = folder / "base.csv"
        proc = cli(
            "simulate",
            "--error",
            "dphi_y1=3",
            "--phi1-step-deg",
            "90",
            "--phi2-step-deg",
            "45",
            "--seed",
            "5",
            "-o",
            str(path),
        )
        assert proc.returncode == 0, proc.stderr
        return path.read_text()
    finally:
        shutil.rmtree(folder)


MEASUREMENTS = _small_measurements()

STORY_BREAKS = [
    "title = 3",
    "explanation = None",
    'required_columns = "time_s"',
    "required_columns = (1,)",
    "name = 7",
]
"""Class attributes of a broken story (one line each)."""

# ---- pieces of a broken module ----------------------------------------------------------------
EXCEPTIONS = ["ValueError", "KeyError", "TypeError", "RuntimeError", "ZeroDivisionError"]
message_text = st.text(string.ascii_letters + string.digits + " .:'\"\n\t", max_size=12)


@st.composite
def raising(draw) -> str:
    """A statement that raises inside the user's code, or leaves by ``sys.exit``."""
    kind = draw(st.sampled_from(["raise", "raise", "exit", "index", "attribute", "divide"]))
    if kind == "raise":
        return f"raise {draw(st.sampled_from(EXCEPTIONS))}({draw(message_text)!r})"
    if kind == "exit":
        return f"import sys; sys.exit({draw(st.sampled_from(['0', '1', '3', 'None', repr('x')]))})"
    return {"index": "[][1]", "attribute": "None.weights", "divide": "1 / 0"}[kind]


def _wrong_count(draw, avoid: tuple[int, ...]) -> int:
    return draw(st.integers(0, 200).filter(lambda k: k not in avoid))


@st.composite
def bad_weight(draw) -> str:
    """An expression (of ``a``, the inner angle, and ``variables``) a weight must not be."""
    k = _wrong_count(draw, (7, DATA_POSITIONS, 144))
    return draw(
        st.sampled_from(
            [
                f"np.ones({k})",
                f"np.ones(({k}, 1))",
                "np.ones((variables.n, 2))",
                "a[:-1]",
                "np.ones(variables.n + 1)",
                "a * np.nan",
                "a * np.inf",
                "-a * np.inf",
                "np.where(a > 1, np.nan, a)",
                "np.where(a < 1, np.inf, a)",
                "float('nan')",
                "float('-inf')",
                "'text'",
                "None",
                "[1, 'x']",
                "a + 1j",
                "{'x': 1}",
                "np.array(['a'] * variables.n)",
                "object()",
                "np.full(variables.n, 1e400)",
            ]
        )
    )


@st.composite
def orientation_module(draw) -> tuple[str, bool]:
    """A module of one orientation effect with one to three breaks; and whether every break
    shows on any data (not only on the data's 32 positions)."""
    name = "lobes"
    attributes: list[str] = []
    parameters = (
        'return (ParameterSpec("c3", "arcsec", ARCSEC, "c"), '
        'ParameterSpec("s3", "arcsec", ARCSEC, "s"))'
    )
    site = '"dphi_z2", None'
    weights = {"c3": "np.cos(3 * a)", "s3": "np.sin(3 * a)"}
    terms = None
    top, init, second = "", "", False
    anywhere = True
    kinds = draw(
        st.permutations(
            [
                "weight",
                "data only",
                "unknown",
                "missing",
                "no parameters",
                "parameters",
                "duplicate",
                "scale",
                "parameters raise",
                "terms raise",
                "terms",
                "site",
                "name",
                "story",
                "second class",
                "import",
                "constructor",
            ]
        )
    )[: draw(st.integers(1, 3))]
    for kind in kinds:
        if kind == "weight":
            weights[draw(st.sampled_from(["c3", "s3"]))] = draw(bad_weight())
        elif kind == "data only":  # fine on the probe of 7 positions, broken on the data
            weights["c3"] = f"({draw(bad_weight())}) if variables.n > 10 else np.cos(3 * a)"
            anywhere = anywhere and len(kinds) > 1
        elif kind == "unknown":
            key = draw(st.sampled_from(["zz", "c", "C3", "lobes.c3", "c3 ", ""]))
            weights[key] = weights.pop(next(iter(weights)), "a") if weights else "a"
        elif kind == "missing" and weights:
            del weights[draw(st.sampled_from(sorted(weights)))]
        elif kind == "no parameters":
            parameters = "return ()"
        elif kind == "parameters":
            parameters = "return " + draw(
                st.sampled_from(
                    [
                        "None",
                        "'c3'",
                        "('c3', 's3')",
                        "[1, 2]",
                        "42",
                        "ParameterSpec('c3', 'arcsec', ARCSEC, 'c')",
                        "(ParameterSpec(3, 'arcsec', ARCSEC, 'c'),)",
                    ]
                )
            )
        elif kind == "duplicate":
            parameters = parameters.replace('"s3"', '"c3"')
        elif kind == "scale":
            scale = draw(
                st.sampled_from(
                    ["0", "-ARCSEC", "float('nan')", "float('inf')", "'1'", "None", "True"]
                )
            )
            parameters = parameters.replace('ARCSEC, "c"', f'{scale}, "c"')
        elif kind == "parameters raise":
            parameters = draw(raising())
        elif kind == "terms raise":
            terms = draw(raising())
        elif kind == "terms":
            terms = "return " + draw(
                st.sampled_from(
                    [
                        "None",
                        "'dphi_z2'",
                        "1",
                        "[None]",
                        "(('dphi_z2', None, {}),)",
                        "(ChainTerm('dphi_z2', None, [('c3', a)]),)",
                    ]
                )
            )
        elif kind == "site":
            site = draw(
                st.sampled_from(
                    [
                        '"dphi_q", None',
                        '"pre", "w"',
                        '"post", None',
                        '"measured", "x"',
                        '"dpsi", None',
                        "3, None",
                        '"deta", None',
                    ]
                )
            )
        elif kind == "name":
            name = draw(
                st.sampled_from(
                    [
                        "backlash",
                        "gravity_sag",
                        "thermal_drift",
                        "inner_encoder_harmonics",
                        "",
                        "two words",
                        "a,b",
                        "x~y",
                        "9lives",
                        "lobes\\n",
                    ]
                )
            )
        elif kind == "story":
            attributes.append(draw(st.sampled_from(STORY_BREAKS)))
        elif kind == "second class":
            second = True
        elif kind == "import":
            top = draw(raising())
        elif kind == "constructor":
            init = draw(raising())
    if terms is None:
        items = ", ".join(f"{k!r}: {v}" for k, v in weights.items())
        terms = f"return (ChainTerm({site}, {{{items}}}),)"
    body = "\n".join(f"    {line}" for line in attributes)
    init_text = f"    def __init__(self):\n        {init}\n\n" if init else ""
    cls = (
        f"class Lobes(Effect):\n    name = {name!r}\n    title = 'three lobes'\n{body}\n\n"
        f"{init_text}    def parameters(self, variables):\n        {parameters}\n\n"
        f"    def chain_terms(self, variables):\n        a = variables.angle(2)\n        {terms}\n"
    )
    text = (
        "import numpy as np\n\nfrom turntable_pin.measurement.effects.base import ARCSEC, "
        f"ChainTerm, Effect, ParameterSpec\n\n{top}\n\n{cls}"
    )
    if second:
        text += "\n\n" + cls.replace("class Lobes(", "class Lobes2(")
    return text, anywhere


ORIENTATION_COMMANDS = ["fit", "diagnose", "effects", "simulate"]


@fuzz(40)
@given(module=orientation_module(), command=st.sampled_from(ORIENTATION_COMMANDS))
def test_broken_orientation_effect_modules(scratch, module, command):
    text, anywhere = module
    folder = example_folder(scratch)
    path = folder / "lobes.py"
    path.write_text(text, encoding="utf-8")
    data = folder / "data.csv"
    data.write_text(MEASUREMENTS, encoding="utf-8")
    if command == "effects" and not anywhere:
        command = "fit"  # a break on the data only needs data
    args = {
        "fit": ["fit", str(data), "--effects-module", str(path), "--effects", "lobes"],
        "diagnose": ["diagnose", str(data), "--catalogue", str(path)],
        "effects": ["effects", "--catalogue", str(path)],
        "simulate": [
            "simulate",
            "--catalogue",
            str(path),
            "--effect",
            "lobes:c3=1",
            "--phi1-step-deg",
            "45",
            "-o",
            str(folder / "out.csv"),
        ],
    }[command]
    run_and_check(folder, args, str(path), outputs=("out.csv",), statuses=(2,))


@st.composite
def run_module(draw) -> str:
    """A module of one run effect with one to three breaks."""
    name, side = "cable_drag", "table"
    parameters = 'return (ParameterSpec("b", "deg/h", 1.0, "drag"),)'
    columns = None
    shape = "(n, 2, 1)"
    fill = "np.sin(context.run.joint_rad[:, 1])"
    top, second = "", False
    kinds = draw(
        st.permutations(
            [
                "shape",
                "values",
                "type",
                "data only",
                "no parameters",
                "parameters",
                "duplicate",
                "scale",
                "parameters raise",
                "columns raise",
                "side",
                "name",
                "second class",
                "import",
            ]
        )
    )[: draw(st.integers(1, 3))]
    for kind in kinds:
        if kind == "shape":
            k = _wrong_count(draw, (1,))
            shape = draw(
                st.sampled_from(
                    [
                        f"(n, 2, {k})",
                        "(n, 2)",
                        f"({k + 150}, 2, 1)",
                        "(n, 1, 1)",
                        "(n,)",
                        "(2, n, 1)",
                    ]
                )
            )
        elif kind == "values":
            fill = draw(
                st.sampled_from(
                    [
                        "np.nan",
                        "np.inf",
                        "-np.inf",
                        "np.where(context.run.joint_rad[:, 0] > 1, np.nan, 0)",
                        "np.log(context.run.joint_rad[:, 1] - 100)",
                    ]
                )
            )
        elif kind == "type":
            columns = "return " + draw(
                st.sampled_from(
                    [
                        "1.0",
                        "None",
                        "'columns'",
                        "[[1, 2], [3]]",
                        "np.zeros((n, 2, 1)) + 1j",
                        "{'b': 1}",
                        "np.array([['a', 'b']] * n)",
                    ]
                )
            )
        elif kind == "data only":
            broken = draw(st.sampled_from(["np.zeros((n, 2))", "np.full((n, 2, 1), np.nan)"]))
            columns = f"return np.zeros((n, 2, 1)) if n < 10 else {broken}"
        elif kind == "no parameters":
            parameters = "return ()"
        elif kind == "parameters":
            parameters = "return " + draw(
                st.sampled_from(
                    ["None", "'b'", "('b',)", "42", "ParameterSpec('b', 'deg/h', 1.0, 'd')"]
                )
            )
        elif kind == "duplicate":
            parameters = (
                'return (ParameterSpec("b", "deg/h", 1.0, "d"), ParameterSpec("b", '
                '"deg/h", 1.0, "d"))'
            )
        elif kind == "scale":
            scale = draw(st.sampled_from(["0.0", "-1.0", "float('nan')", "'1'", "None"]))
            parameters = f'return (ParameterSpec("b", "deg/h", {scale}, "drag"),)'
        elif kind == "parameters raise":
            parameters = draw(raising())
        elif kind == "columns raise":
            columns = draw(raising())
        elif kind == "side":
            side = draw(st.sampled_from(["gyro", "", "TABLE", "both"]))
        elif kind == "name":
            name = draw(
                st.sampled_from(
                    [
                        "bias_drift",
                        "instrument_tilt",
                        "backlash",
                        "dphi_y1",
                        "table:backlash",
                        "out_x~h2(phi1)",
                        "",
                        "a,b",
                    ]
                )
            )
        elif kind == "second class":
            second = True
        elif kind == "import":
            top = draw(raising())
    if columns is None:
        columns = f"out = np.zeros({shape}); out[..., 0] = {fill}; return out"
        if shape != "(n, 2, 1)":
            columns = f"return np.zeros({shape}) + 0.5"
    cls = (
        f"class CableDrag(RunEffect):\n    name = {name!r}\n    side = {side!r}\n"
        f"    title = 'cable drag'\n\n    def parameters(self, run):\n        {parameters}\n\n"
        f"    def columns(self, context):\n        n = context.run.n_positions\n        {columns}\n"
    )
    text = (
        "import numpy as np\n\nfrom turntable_pin.instrument.effects import RunEffect\n"
        f"from turntable_pin.instrument.effects.base import ParameterSpec\n\n{top}\n\n{cls}"
    )
    if second:
        text += "\n\n" + cls.replace("class CableDrag(", "class CableDrag2(")
    return text


RUN_COMMANDS = {
    "calibrate --diagnose": ["calibrate", "{run}", "--diagnose"],
    "calibrate --effects": ["calibrate", "{run}", "--effects", "cable_drag"],
    "design --separate --run": [
        "design",
        "--separate",
        "cable_drag,instrument_tilt",
        "--run",
        "{run}",
        "-n",
        "3",
        "--candidates",
        "200",
        "-o",
        "{out}",
    ],
}


@fuzz(40)
@given(text=run_module(), command=st.sampled_from(sorted(RUN_COMMANDS)))
def test_broken_run_effect_modules(scratch, text, command):
    folder = example_folder(scratch)
    path = folder / "cable.py"
    path.write_text(text, encoding="utf-8")
    run = folder / "run.csv"
    shutil.copy(RUN, run)
    args = [a.format(run=run, out=folder / "out.csv") for a in RUN_COMMANDS[command]]
    args += ["--effects-module", str(path)]
    run_and_check(folder, args, str(path), outputs=("out.csv",), statuses=(2,))


# ---- effect files -----------------------------------------------------------------------------
EFFECT_FILE_KEYS = ("format", "name", "title", "explanation", "confirm", "terms")
TERM_KEYS = ("site", "harmonics", "polynomial", "sign", "of", "prefix")
wrong_value = st.one_of(
    st.integers(-5, 5),
    st.floats(allow_nan=True),
    st.none(),
    st.booleans(),
    st.lists(st.integers(0, 3), max_size=2),
    st.dictionaries(st.text(max_size=2), st.integers(), max_size=1),
)


def _good_effect() -> dict:
    return {
        "format": 1,
        "name": "my_effect",
        "title": "a three-lobed inner encoder",
        "terms": [{"site": "dphi_z2", "harmonics": 3, "of": "phi2"}, "dpsi~h1(phi1)"],
    }


@st.composite
def broken_effect_file(draw) -> str:
    """The text of an effect file with one structural break (each one a refusal)."""
    doc = _good_effect()
    term = doc["terms"][0]
    kind = draw(
        st.sampled_from(
            [
                "drop",
                "unknown key",
                "name",
                "terms",
                "term item",
                "term keys",
                "site",
                "variable",
                "orders",
                "degree",
                "sign",
                "prefix",
                "twice",
                "format",
                "story",
                "not a mapping",
                "key twice",
            ]
        )
    )
    if kind == "drop":
        del doc[draw(st.sampled_from(["name", "terms"]))]
    elif kind == "unknown key":
        doc[draw(st.text(max_size=6).filter(lambda k: k not in EFFECT_FILE_KEYS))] = draw(
            wrong_value
        )
    elif kind == "name":
        doc["name"] = draw(
            st.one_of(
                wrong_value,
                st.sampled_from(
                    [
                        "",
                        "  ",
                        "two words",
                        "a,b",
                        "x~y",
                        "9lives",
                        "backlash",
                        "thermal_drift",
                        "gravity_sag",
                    ]
                ),
            )
        )
    elif kind == "terms":
        doc["terms"] = draw(
            st.one_of(st.sampled_from([[], "dphi_z2", {"site": "dpsi"}]), st.integers(), st.none())
        )
    elif kind == "term item":
        doc["terms"][1] = draw(
            st.one_of(
                st.integers(),
                st.none(),
                st.lists(st.integers(), max_size=2),
                st.text(string.ascii_letters + "_()", min_size=1, max_size=10),
                st.sampled_from(
                    [
                        "dpsi~h3",
                        "dphi_q~h1(phi1)",
                        "dpsi~h0(phi1)",
                        "dpsi~poly9(time_s)",
                        "dpsi~sign(time_s)",
                    ]
                ),
            )
        )
    elif kind == "term keys":
        change = draw(st.sampled_from(["no site", "no shape", "two shapes", "unknown"]))
        if change == "no site":
            del term["site"]
        elif change == "no shape":
            del term["harmonics"]
        elif change == "two shapes":
            term["polynomial"] = 1
        else:
            term[draw(st.text(max_size=5).filter(lambda k: k not in TERM_KEYS))] = 1
    elif kind == "site":
        term["site"] = draw(
            st.one_of(wrong_value, st.sampled_from(["dphi_q", "", "pre.w", "deta", "post"]))
        )
    elif kind == "variable":
        term["of"] = draw(
            st.one_of(
                wrong_value, st.sampled_from(["phi3", "temperature_c", "phi1*phi2", "", "dir1"])
            )
        )
    elif kind == "orders":
        term["harmonics"] = draw(
            st.sampled_from([0, -1, 101, 1.5, "x", [], True, [1, "a"], "3..1", "0..2", None, [0]])
        )
    elif kind == "degree":
        del term["harmonics"]
        term["polynomial"] = draw(st.sampled_from([0, 6, 1.5, "2", True, None, -1]))
        term["of"] = "time_s"
    elif kind == "sign":
        del term["harmonics"]
        term["sign"] = draw(st.sampled_from(["phi1", "time_s", 3, "dir9", ""]))
        if draw(st.booleans()):
            term["sign"], term["of"] = "dir1", "dir1"
    elif kind == "prefix":
        term["prefix"] = draw(wrong_value)
    elif kind == "twice":
        doc["terms"] = [dict(term), dict(term)]
    elif kind == "format":
        doc["format"] = draw(st.sampled_from([2, 0, "1", None, 1.5, [1]]))
    elif kind == "story":
        doc[draw(st.sampled_from(["title", "explanation", "confirm"]))] = draw(
            st.one_of(st.integers(), st.lists(st.integers(), max_size=2), st.booleans())
        )
    elif kind == "not a mapping":
        doc = draw(
            st.one_of(
                st.lists(st.integers(), max_size=3),
                st.integers(),
                st.text(string.ascii_letters, min_size=1, max_size=8),
            )
        )
    text = yaml.safe_dump(doc, sort_keys=False, allow_unicode=True)
    if kind == "key twice":
        lines = text.splitlines()
        top = [i for i, line in enumerate(lines) if line and not line.startswith((" ", "-"))]
        i = draw(st.sampled_from(top))
        lines.insert(i, lines[i])
        text = "\n".join(lines) + "\n"
    return text


@fuzz(40)
@given(text=broken_effect_file(), command=st.sampled_from(["fit", "diagnose", "effects"]))
def test_broken_effect_files(scratch, text, command):
    folder = example_folder(scratch)
    path = folder / "effect.yaml"
    path.write_text(text, encoding="utf-8")
    data = folder / "data.csv"
    data.write_text(MEASUREMENTS, encoding="utf-8")
    args = {
        "fit": ["fit", str(data), "--effects", str(path)],
        "diagnose": ["diagnose", str(data), "--catalogue", str(path)],
        "effects": ["effects", "--catalogue", str(path)],
    }[command]
    run_and_check(folder, args, str(path), statuses=(2,))
