"""The diagnosis in words: the one-line verdict, and a partial explanation named as such."""

import dataclasses

import numpy as np
import pytest

from turntable_pin import TurntableErrors
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.measurement.simulation import simulate_measurements
from turntable_pin.report.diagnosis_text import diagnosis_lines, headline, verdict_lines

TERM = {
    "term": "dtheta 3/rev in phi2",
    "description": "a 3/rev term in phi2 of dtheta itself",
    "delta_bic": -250.0,
    "amplitude": 1.9,
    "unit": "arcsec",
    "coefficients": [1.5, 1.2],
}


def _dict(*, steps=(), chi2_best=1.01, fails=False, structure=()):
    """A minimal ``Diagnosis.to_dict()``: base rms 1.9 arcsec, chi2_reduced 3.64."""
    steps = [{"added": name, "delta_bic": -1100.0, "rms_arcsec": 0.99, "chi2_reduced": chi2_best,
              "n_params": 13, "rank": 10, "p_value": 0.4} for name in steps]  # fmt: skip
    base = {"rms_arcsec": 1.9, "chi2_reduced": 3.64, "n_params": 8, "rank": 5, "p_value": 1e-100}
    best = dict(base, rms_arcsec=0.99, chi2_reduced=chi2_best) if steps else dict(base)
    story = {"title": "t", "explanation": "e", "confirm": "c"}
    return {
        "base": base,
        "best": {"effects": [s["added"] for s in steps], **best},
        "steps": steps,
        "verdict": {
            "missing_effect": steps[0]["added"] if steps else None,
            "missing_effects": [s["added"] for s in steps[:1]],
            "also_significant": [s["added"] for s in steps[1:]],
            "unexplained": bool(fails or structure),
            "fails_fit_test": fails,
            "remaining_structure": list(structure),
            "separations": {},
            "indistinguishable_from_base": [],
            **({"effect_story": story} if steps else {}),
        },
    }


def _first_text_line(d):
    """The first line of the text report of ``d`` (completed with the header's keys)."""
    d = dict(d, n_positions=144, n_observations=432, sigma_source="column", sigma_arcsec=1.0,
             candidates=[], warnings=[])  # fmt: skip
    return diagnosis_lines(d)[0]


def test_headline_names_the_missing_effect_with_the_fall():
    line = headline(_dict(steps=["inner_encoder_harmonics"]))
    assert line == ("Missing effect: inner_encoder_harmonics -- rms 1.90 -> 0.990 arcsec, "
                    "chi2_reduced 3.64 -> 1.01")  # fmt: skip


def test_an_effect_that_leaves_the_fit_failing_is_a_partial_explanation():
    d = _dict(steps=["gravity_sag"], chi2_best=2.7, fails=True)
    line = headline(d)
    assert line.startswith("Partial explanation: gravity_sag")
    assert "3.64 -> 2.70" in line and "fails the chi2 test" in line
    assert "Missing effect" not in line
    words = verdict_lines(d)
    assert any(w.startswith("partial explanation: gravity_sag") for w in words)
    assert not any(w.startswith("missing effect:") for w in words)
    assert _first_text_line(d) == line


def test_an_effect_with_structure_left_is_a_partial_explanation():
    line = headline(_dict(steps=["gravity_sag"], structure=[TERM, TERM]))
    assert line.startswith("Partial explanation: gravity_sag")
    assert line.endswith("structure remains: dtheta 3/rev in phi2 (1.9 arcsec) and 1 more")


def test_headline_without_an_effect():
    assert headline(_dict(structure=[TERM])) == (
        "Unexplained structure: dtheta 3/rev in phi2 (1.9 arcsec) (no catalogued effect) -- "
        "rms 1.90 arcsec, chi2_reduced 3.64"
    )
    assert headline(_dict(fails=True)).startswith("Unexplained misfit:")
    clean = _dict()
    clean["base"]["chi2_reduced"] = 1.02
    fits = "The base model fits to the noise -- rms 1.90 arcsec, chi2_reduced 1.02"
    assert headline(clean) == fits


@pytest.mark.slow
def test_a_real_partial_explanation_is_announced_as_such():
    # gravity sag plus a stated sigma 0.6 of the true noise: the sag is found, chi2_reduced stays
    # near 1 / 0.6^2 = 2.8, so the best model fails the fit test
    sim = simulate_measurements(
        TurntableErrors.from_arcsec(deps_y=4), {"gravity_sag": {"k": 4.0}}, seed=7
    )
    data = dataclasses.replace(sim.data, sigma_rad=np.asarray(sim.data.sigma_rad) * 0.6)
    d = diagnose_measurements(data).to_dict()
    assert d["verdict"]["missing_effect"] == "gravity_sag" and d["verdict"]["fails_fit_test"]
    assert d["best"]["chi2_reduced"] == pytest.approx(2.8, abs=0.5)
    line = headline(d)
    assert line.startswith("Partial explanation: gravity_sag") and "still unexplained" in line
    assert diagnosis_lines(d)[0] == line


def test_a_separation_prints_the_design_command_that_settles_it():
    d = _dict(steps=["gravity_sag"])
    verdict = d["verdict"]
    verdict["alternatives"] = ["outer_encoder_harmonics"]
    verdict["separations"] = {"outer_encoder_harmonics": "no set of positions separates them"}
    plain = verdict_lines(d)
    command = "turntable-pin design --separate gravity_sag,outer_encoder_harmonics --from d.csv"
    verdict["separation_commands"] = {"outer_encoder_harmonics": command}
    lines = verdict_lines(d)
    at = lines.index("  alternative outer_encoder_harmonics: no set of positions separates them")
    assert lines[at + 1] == f"    to settle it, design the next positions: {command}"
    assert lines[: at + 1] + lines[at + 2 :] == plain  # nothing else changes


def test_a_set_taken_instead_says_what_later_steps_made_of_it():
    """The GEM run's case: a set taken at step 2 whose member the final model does not need, and
    the many-parameter effect added after all; the line says so rather than 'the set is named'."""
    d = _dict(steps=("TF", "DAF", "gravity_sag"))
    d["verdict"]["simpler_sets"] = [
        {"step": 2, "effect": "gravity_sag", "added_rank": 4, "delta_bic": -155.6,
         "simpler_set": ["DAF", "FO"], "set_added_rank": 2, "set_delta_bic": -316.5,
         "set_named": True},
    ]  # fmt: skip
    named = [*d["verdict"]["missing_effects"], *d["verdict"]["also_significant"]]
    assert {"TF", "DAF", "gravity_sag"} <= set(named) and "FO" not in named
    assert (
        "parsimony at step 2: the simpler set DAF + FO (2 parameters, delta_bic -316.5) has a "
        "lower BIC than gravity_sag (4 parameters, delta_bic -155.6), so the set is taken instead; "
        "afterwards FO left out at the end (not needed by the final model); gravity_sag still "
        "added at a later step"
    ) in verdict_lines(d)


def test_the_simpler_set_compared_and_the_implausible_effects_are_said():
    """Issue 29: each many-parameter effect compared with a set of simpler ones (named or not),
    and each significant effect left out for an implausible amplitude, with the belief."""
    d = _dict(steps=("table:deps_y", "instrument_heading"))
    d["verdict"]["simpler_sets"] = [
        {"step": 1, "effect": "table:inner_wobble_harmonics", "added_rank": 8,
         "delta_bic": -2443.8, "simpler_set": ["table:deps_y", "instrument_heading"],
         "set_added_rank": 2, "set_delta_bic": -2468.5, "set_named": True},
        {"step": 2, "effect": "bias_drift", "added_rank": 2, "delta_bic": -30.0,
         "simpler_set": ["table:dalpha_x2", "table:dalpha_y2"], "set_added_rank": 2,
         "set_delta_bic": -12.0, "set_named": False},
    ]  # fmt: skip
    d["verdict"]["implausible"] = [
        {"effect": "table:outer_wobble_harmonics", "delta_bic": -90.1,
         "belief": "a bearing of outer_axis whose axis wobbles by 14.1 arcmin as it turns (where "
                   "a turntable reaches about 5 arcmin)"},
    ]  # fmt: skip
    lines = verdict_lines(d)
    assert (
        "parsimony at step 1: the simpler set table:deps_y + instrument_heading (2 parameters, "
        "delta_bic -2468.5) has a lower BIC than table:inner_wobble_harmonics (8 parameters, "
        "delta_bic -2443.8), so the set is taken instead"
    ) in lines
    assert (
        "parsimony at step 2: bias_drift (2 parameters, delta_bic -30.0) is kept; the best "
        "simpler set, table:dalpha_x2 + table:dalpha_y2 (2 parameters, delta_bic -12.0), does "
        "not fit as well"
    ) in lines
    assert (
        "not named: table:outer_wobble_harmonics (delta_bic -90.1, significant alone) is "
        "implausible: to accept it one would have to believe in a bearing of outer_axis whose "
        "axis wobbles by 14.1 arcmin as it turns (where a turntable reaches about 5 arcmin)"
    ) in lines
