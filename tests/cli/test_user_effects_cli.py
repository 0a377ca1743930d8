"""The user's effects at the command line: fit --effects with effect files and inline terms,
--effects-module, diagnose --catalogue naming a user effect, the effect_spec round trip, bad
effect files (one line, exit 2), simulate with user effects, and the ``effects`` command."""

import json

import numpy as np
import pytest

from conftest import REPO_DIR, cli, write_file
from turntable_pin.core.csv_table import write_csv_table
from turntable_pin.measurement.data import read_measurements

EFFECT_FILE = """\
format: 1
name: inner_encoder_3rev
title: inner encoder with a three-lobed error
explanation: The inner encoder's read head sees a 3/rev error of its scale.
confirm: Compare the inner encoder with a 24-sided polygon and an autocollimator.
terms:
  - site: dphi_z2
    harmonics: 3
    of: phi2
"""

MODULE = '''\
"""A user's effects: a three-lobed inner encoder, as an Effect subclass."""
import numpy as np

from turntable_pin.measurement.effects.base import ARCSEC, ChainTerm, Effect, ParameterSpec


class ThreeLobes(Effect):
    name = "three_lobes"
    title = "three-lobed inner encoder"
    definition = "dphi_z2 += c3 cos 3 phi2 + s3 sin 3 phi2"
    explanation = "A three-lobed encoder scale."
    confirm = "Polygon and autocollimator."

    def parameters(self, variables):
        return (ParameterSpec("c3", "arcsec", ARCSEC, "cos(3 phi2)"),
                ParameterSpec("s3", "arcsec", ARCSEC, "sin(3 phi2)"))

    def chain_terms(self, variables):
        a = variables.angle(2)
        return (ChainTerm("dphi_z2", None, {"c3": np.cos(3 * a), "s3": np.sin(3 * a)}),)
'''


@pytest.fixture(scope="module")
def planted(tmp_path_factory):
    """Simulated data with a 3/rev inner encoder error (out of the catalogue), via the user's
    effect file given to simulate --catalogue."""
    folder = tmp_path_factory.mktemp("planted")
    effect = write_file(folder, EFFECT_FILE, "three.yaml")
    path = folder / "three.csv"
    proc = cli("simulate", "--catalogue", str(effect), "--effect", "inner_encoder_3rev:c3=3,s3=-2",
               "--error", "dphi_y1=4", "--seed", "7", "-o", str(path))  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return folder, path, effect


def test_diagnose_finds_the_term_and_its_effect_spec_brings_the_fit_to_the_noise(planted):
    folder, data, _ = planted
    proc = cli("diagnose", str(data), "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    assert out["verdict"]["unexplained"]
    terms = out["verdict"]["remaining_structure"]
    assert terms[0]["term"].endswith("3/rev in phi2") and terms[0]["amplitude"] > 2
    spec = terms[0]["effect_spec"]
    fit = json.loads(cli("fit", str(data), "--effects", spec, "--json").stdout)
    assert fit["before"]["chi2_reduced"] > 2.5
    assert 0.75 < fit["chi2_reduced"] < 1.25 and fit["p_value"] > 0.001
    text = cli("diagnose", str(data)).stdout
    assert f"turntable-pin fit {data} --effects '{spec}'" in text


def test_fit_with_the_effect_file_the_inline_term_or_the_module_is_one_fit(planted):
    folder, data, effect = planted
    module = write_file(folder, MODULE, "lobes.py")
    fits = [
        json.loads(cli("fit", str(data), *args, "--json").stdout)
        for args in (["--effects", str(effect)], ["--effects", "dphi_z2~h3(phi2)"],
                     ["--effects-module", str(module), "--effects", "three_lobes"])
    ]  # fmt: skip
    chi2 = [f["chi2_reduced"] for f in fits]
    assert chi2 == pytest.approx([chi2[0]] * 3, rel=1e-9)
    assert fits[0]["params"]["inner_encoder_3rev.c3"]["value"] == pytest.approx(3, abs=0.4)
    assert fits[0]["params"]["inner_encoder_3rev.c3"]["unit"] == "arcsec"
    both = json.loads(cli("fit", str(data), "--effects", "backlash", "--effects",
                          "dphi_z2~h3(phi2),thermal_drift", "--json").stdout)  # fmt: skip
    assert both["effects"] == ["backlash", "dphi_z2~h3(phi2)", "thermal_drift"]


def test_diagnose_and_report_name_the_users_effect_with_catalogue(planted, tmp_path):
    folder, data, effect = planted
    module = write_file(folder, MODULE, "lobes.py")
    for catalogue in (effect, module):
        proc = cli("diagnose", str(data), "--catalogue", str(catalogue), "--json")
        assert proc.returncode == 0, proc.stderr
        out = json.loads(proc.stdout)
        name = "inner_encoder_3rev" if catalogue == effect else "three_lobes"
        assert out["verdict"]["missing_effect"] == name
        assert not out["verdict"]["unexplained"]
        assert out["verdict"]["effect_story"]["effect"] == name
    text = cli("diagnose", str(data), "--catalogue", str(effect)).stdout
    assert "missing effect: inner_encoder_3rev (inner encoder with a three-lobed error)" in text
    report = tmp_path / "r.html"
    proc = cli("report", str(data), "--catalogue", str(effect), "-o", str(report))
    assert proc.returncode == 0, proc.stderr
    assert "inner_encoder_3rev" in report.read_text()


def test_a_term_in_an_extra_column_round_trips(planted, tmp_path):
    _, data, _ = planted
    measured = read_measurements(data)
    rng = np.random.default_rng(3)
    temperature = np.round(20 + 4 * rng.random(measured.n_positions), 2)
    columns = measured.columns()
    columns["dpsi_arcsec"] = columns["dpsi_arcsec"] + 1.5 * (temperature - 20)
    columns["temperature_c"] = temperature
    path = write_csv_table(tmp_path / "warm.csv", columns)
    out = json.loads(cli("diagnose", str(path), "--json").stdout)
    specs = [t["effect_spec"] for t in out["verdict"]["remaining_structure"]]
    assert any(s.endswith("~poly2(temperature_c)") for s in specs)
    fit = json.loads(cli("fit", str(path), "--effects", ",".join(specs), "--json").stdout)
    assert 0.75 < fit["chi2_reduced"] < 1.25
    linear = json.loads(cli("fit", str(path), "--effects", "dpsi~poly1(temperature_c)",
                            "--effects", "dphi_z2~h3(phi2)", "--json").stdout)  # fmt: skip
    p1 = linear["params"]["dpsi~poly1(temperature_c).p1"]
    assert p1["value"] == pytest.approx(1.5, abs=0.15) and p1["unit"] == "arcsec/temperature_c"


BAD_FILES = [
    ("name: x\nterms: []\n", "x.yaml", "terms: expected a list of at least one term"),
    ("name: x\nname: y\nterms: []\n", "x.yaml", "key 'name' is given twice"),
    (
        "name: x\nterms:\n  - site: dphi_q\n    harmonics: 3\n    of: phi2\n",
        "x.yaml",
        "line 3: terms[1]: unknown site 'dphi_q'",
    ),
    (
        "name: x\nterms:\n  - site: dpsi\n    harmonic: 3\n    of: phi2\n",
        "x.yaml",
        "line 4: terms[1].harmonic: unknown key",
    ),
    (
        "name: x\nterms:\n  - site: dpsi\n    harmonics: [1, two]\n    of: phi2\n",
        "x.yaml",
        "line 4: terms[1].harmonics: expected an order",
    ),
    ("name: x\nterms:\n  - site: dpsi\n    polynomial: 1\n", "x.yaml", "needs 'of'"),
    ("name: x y\nterms: [dpsi~h1(phi1)]\n", "x.yaml", "line 1: name: 'x y'"),
    ("terms: [dpsi~h1(phi1)]\n", "x.yaml", "the key 'name' is missing"),
    ("name: backlash\nterms: [dpsi~h1(phi1)]\n", "x.yaml", "already in the catalogue"),
    ("name: x\nterms: [dpsi~h1(phi1), 'dpsi~h1..2(phi1)']\n", "x.yaml", "defined twice"),
    ("name: x\nterms: [{site: dpsi, sign: dir1}]\nformat: 2\n", "x.yaml", "format 2 is not known"),
    ("import nothing_here_at_all\n", "m.py", "cannot import it: ModuleNotFoundError"),
    ("def f(:\n", "m.py", "cannot import it: SyntaxError"),
    ("X = 1\n", "m.py", "defines no effect"),
    ("name: x\n", "x.txt", "a .yaml/.yml effect file or a .py module"),
]


@pytest.mark.parametrize("text, name, message", BAD_FILES)
def test_bad_effect_files_exit_2_with_one_line(planted, tmp_path, text, name, message):
    _, data, _ = planted
    path = write_file(tmp_path, text, name)
    proc = cli("diagnose", str(data), "--catalogue", str(path))
    assert proc.returncode == 2, proc.stdout
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and str(path) in lines[0] and message in lines[0], lines
    if name.endswith(".yaml"):
        proc = cli("fit", str(data), "--effects", str(path))
        assert proc.returncode == 2 and message in proc.stderr


@pytest.mark.parametrize(
    "args, message",
    [
        (["fit", "{data}", "--effects", "dpsi~h3"], "expected SITE~hK(VAR)"),
        (["fit", "{data}", "--effects", "no_such_effect"], "unknown effect 'no_such_effect'"),
        (["fit", "{data}", "--effects", "dpsi~poly1(temperature_c)"], "temperature_c"),
        (["fit", "{data}", "--effects-module", "{folder}/none.py"], "no such Python file"),
        (
            ["simulate", "--effect", "inner_encoder_harmonics", "-o", "{folder}/o.csv"],
            "without parameters would simulate nothing",
        ),
        (
            [
                "simulate",
                "--effect",
                "inner_encoder_3rev",
                "--catalogue",
                "{effect}",
                "-o",
                "{folder}/o.csv",
            ],
            "without parameters would simulate nothing",
        ),
        (
            ["simulate", "--effect", "inner_encoder_3rev:c3=1", "-o", "{folder}/o.csv"],
            "unknown effect 'inner_encoder_3rev'",
        ),
    ],
)
def test_bad_effect_options_exit_2_with_one_line(planted, args, message):
    folder, data, effect = planted
    args = [a.format(data=data, folder=folder, effect=effect) for a in args]
    proc = cli(*args)
    assert proc.returncode == 2, proc.stdout
    assert len(proc.stderr.strip().splitlines()) == 1 and message in proc.stderr, proc.stderr
    assert not (folder / "o.csv").exists()


def test_simulate_takes_an_inline_term_too(tmp_path):
    path = tmp_path / "s.csv"
    proc = cli("simulate", "--effect", "dgamma~sign(dir1):b=4", "--seed", "2", "-o", str(path))
    assert proc.returncode == 0, proc.stderr
    assert "# hidden effects: dgamma~sign(dir1): b=4" in path.read_text()
    fit = json.loads(cli("fit", str(path), "--effects", "dgamma~sign(dir1)", "--json").stdout)
    assert fit["params"]["dgamma~sign(dir1).b"]["value"] == pytest.approx(4, abs=0.3)


def test_the_effects_command_lists_catalogue_and_user_effects(planted):
    folder, _, effect = planted
    module = write_file(folder, MODULE, "lobes.py")
    proc = cli("effects", "--catalogue", str(effect), "--catalogue", str(module), "--json")
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    names = [e["effect"] for e in out["effects"]]
    assert names[:9] == ["outer_encoder_harmonics", "inner_encoder_harmonics",
                         "outer_wobble_harmonics", "inner_wobble_harmonics", "gravity_sag",
                         "base_tilt", "thermal_drift", "backlash", "payload_mount"]  # fmt: skip
    assert names[9:] == ["inner_encoder_3rev", "three_lobes"]
    mine = out["effects"][9]
    assert mine["source"] == str(effect) and mine["title"].startswith("inner encoder with")
    assert mine["definition"] == "dphi_z2 += c3 cos(3 phi2) + s3 sin(3 phi2)"
    assert mine["parameters"][0] == {"name": "c3", "unit": "arcsec",
                                     "description": "dphi_z2: cos(3 phi2) coefficient"}  # fmt: skip
    drift = out["effects"][6]
    assert drift["required_columns"] == ["time_s"] and drift["parameters"][0]["unit"] == "arcsec/h"
    assert out["base_errors"][:2] == ["dphi_y1", "dphi_z2"]
    text = cli("effects").stdout
    assert "backlash" in text and "needs: dir1, dir2" in text
    assert cli("effects", "--catalogue", str(folder / "missing.yaml")).returncode == 2


def test_the_effects_command_on_another_table(tmp_path):
    urdf = REPO_DIR / "models" / "three_axis_imu_table.urdf"
    out = json.loads(cli("effects", "--urdf", str(urdf), "--json").stdout)
    names = [e["effect"] for e in out["effects"]]
    assert len(out["joints"]) == 3 and f"encoder_harmonics@{out['joints'][2]}" in names
    site = f"{out['joints'][2]}.position"
    assert site in out["base_errors"]
    effect = write_file(tmp_path, f"name: enc3\nterms: ['{site}~h3(phi3)']\n", "e.yaml")
    proc = cli("effects", "--urdf", str(urdf), "--catalogue", str(effect), "--json")
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["effects"][-1]["definition"].startswith(f"{site} += c3 cos")
    bad = write_file(tmp_path, "name: enc3\nterms: ['dphi_z2~h3(phi3)']\n", "bad.yaml")
    proc = cli("effects", "--urdf", str(urdf), "--catalogue", str(bad))
    assert proc.returncode == 2 and "unknown site 'dphi_z2'" in proc.stderr
