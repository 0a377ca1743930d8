"""The bundled example runs (``models/examples/runs``) are diagnosed right from their files alone:
the hidden effect (``models/examples/truth/runs``) named on its side, its values within their
standard errors, the outliers found by row, nothing named on the clean run; and ``calibrate
--effects`` with the named effect takes the residuals to the noise."""

from __future__ import annotations

import json

import numpy as np
import pytest

from conftest import EXAMPLES_DIR, cli
from turntable_pin.calibration.run import read_run
from turntable_pin.core.files import read_yaml
from turntable_pin.instrument.diagnosis import diagnose_run

TRUTHS = sorted((EXAMPLES_DIR / "truth" / "runs").glob("*.yaml"))
TABLE_ALIKE = {"deps_x": {"table:deps_x", "table:dalpha_x1"}}
"""Table errors that turn the payload alike at every position (only their sum is seen)."""


def _expected(truth) -> tuple[set[str], dict]:
    """The names the verdict may give and the values ``{parameter: value}`` to recover."""
    if truth["instrument_effects"]:
        ((name, values),) = truth["instrument_effects"].items()
        return {name}, {f"{name}.{k}": v for k, v in values.items()}
    if truth["table_effects"]:
        ((name, values),) = truth["table_effects"].items()
        return {f"table:{name}"}, {f"table:{name}.{k}": v for k, v in values.items()}
    if truth["table_errors"]:
        ((key, value),) = truth["table_errors"].items()
        error = key.removesuffix("_arcsec")
        return TABLE_ALIKE.get(error, {f"table:{error}"}), {}
    return set(), {}


@pytest.mark.parametrize("path", TRUTHS, ids=lambda p: p.stem)
def test_the_run_diagnosis_names_the_hidden_effect(path):
    truth = read_yaml(path)
    run = read_run(EXAMPLES_DIR / "runs" / truth["data"], np.radians(truth["latitude_deg"]))
    d = diagnose_run(run).to_dict()
    names, values = _expected(truth)
    verdict = d["verdict"]
    if not names:
        assert verdict["missing_effects"] == []
    else:
        assert verdict["missing_effects"] == [verdict["missing_effect"]]
        assert verdict["missing_effect"] in names
        side = "instrument" if truth["instrument_effects"] else "table"
        assert verdict["side"] == side
    entries = {p["name"]: p for ps in verdict["named_parameters"].values() for p in ps}
    for name, value in values.items():
        assert abs(entries[name]["value"] - value) < 4 * entries[name]["std"], name
    rows = sorted(int(run.rows[o["index"]]) for o in truth["outliers"])
    assert sorted(o["row"] for o in d["outliers"]) == rows
    assert not verdict["unexplained"]


def test_calibrate_effects_takes_the_mount_run_to_the_noise():
    data = EXAMPLES_DIR / "runs" / "run_mount.csv"
    result = cli("calibrate", str(data), "--effects", "instrument_tilt", "--json")
    assert result.returncode == 0, result.stderr
    out = json.loads(result.stdout)
    assert out["before"]["chi2_reduced"] > 5
    assert 0.7 < out["chi2_reduced"] < 1.3
    assert abs(out["params"]["instrument_tilt.mx"]["value"] - 60) < 10
