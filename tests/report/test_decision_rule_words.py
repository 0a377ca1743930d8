"""The decision rule is stated once, in the same words, from the engine's constant: the
``diagnose --help`` text, the printed diagnosis, the JSON and the HTML page (issue 30)."""

import html
import re

import pytest

from turntable_pin.cli import build_parser
from turntable_pin.core.resources import examples_dir
from turntable_pin.measurement.data import read_measurements
from turntable_pin.measurement.diagnosis import diagnose_measurements
from turntable_pin.report.diagnosis_text import decision_rule_words, diagnosis_lines
from turntable_pin.report.html_report import diagnosis_html
from turntable_pin.stats.model_selection import acceptance_threshold
from turntable_pin.stats.structure_search import BIC_THRESHOLD

RULE = f"an effect is accepted when delta_bic <= {BIC_THRESHOLD:g} - 2 ln K (K testable candidates)"
OTHER_WORDINGS = ("BIC by 6", "delta <= -6", "accepts:", "-6 - 2 ln K for K")


@pytest.fixture(scope="module")
def diagnosis():
    data = read_measurements(examples_dir() / "measurements_example.csv")
    return diagnose_measurements(data)


def _one_line(text: str) -> str:
    return " ".join(text.split())


def test_the_rule_is_written_from_the_threshold_constant():
    assert decision_rule_words() == RULE
    assert acceptance_threshold(1) == BIC_THRESHOLD


def test_diagnose_help_states_the_rule():
    help_text = _one_line(build_parser("diagnose")._subparsers._group_actions[0]
                          .choices["diagnose"].format_help())  # fmt: skip
    assert RULE in help_text
    assert not any(w in help_text for w in OTHER_WORDINGS)


def test_text_json_and_html_state_the_same_rule_with_the_rounds_threshold(diagnosis):
    d = diagnosis.to_dict()
    threshold = d["decision_rule"]["threshold"]
    assert d["decision_rule"]["accept_effect"] in RULE
    here = f"{RULE}, here {threshold:.1f}"
    text = "\n".join(diagnosis_lines(d))
    assert here in text
    page = html.unescape(re.sub(r"<[^>]+>", " ", diagnosis_html(diagnosis, title="t")))
    assert here in _one_line(page)
    for output in (text, page):
        assert not any(w in output for w in OTHER_WORDINGS)
