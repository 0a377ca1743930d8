"""Effect files stay small to read (issue 27, "Runaway memory and time"): nested aliases are
refused before the file is walked, the terms are read in time linear in their number, and an
effect file holds at most MAX_EFFECT_TERMS terms."""

import time

import pytest

from runaway import time_limit
from turntable_pin.core.exceptions import InputError
from turntable_pin.measurement import user_effects
from turntable_pin.measurement.user_effects import read_effect_file


def effect_file(folder, terms: list[str], name: str = "many.yaml"):
    path = folder / name
    path.write_text("name: many\nterms:\n" + "".join(f"  - {t}\n" for t in terms))
    return path


def test_nested_aliases_in_an_effect_file_are_refused_before_it_is_walked(tmp_path):
    # Before, the line numbers of the keys were gathered by walking every alias: 5.7 GB in 45 s.
    lines = ["name: laughs", 'title: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 8) + "]" for k in range(1, 9)]
    lines.append("terms: *a8")
    path = tmp_path / "laughs.yaml"
    path.write_text("\n".join(lines) + "\n")
    start = time.perf_counter()
    with time_limit(20), pytest.raises(InputError) as caught:
        read_effect_file(path)
    assert "more than 1,000,000 values once its aliases (*name) are expanded" in str(caught.value)
    assert str(caught.value).startswith(f"{path}, line ")
    assert time.perf_counter() - start < 5


def test_an_effect_file_of_more_terms_than_the_limit_is_refused_naming_the_line(tmp_path):
    terms = [f"{{site: dpsi, harmonics: 1, of: phi1, prefix: t{i}_}}" for i in range(100)]
    assert len(read_effect_file(effect_file(tmp_path, terms)).terms) == 100
    path = effect_file(tmp_path, [*terms, "{site: dpsi, harmonics: 1, of: phi1, prefix: u_}"])
    with pytest.raises(InputError) as caught:
        read_effect_file(path)
    assert str(caught.value) == (
        f"{path}, line 2: terms: 101 terms; an effect file holds at most 100 (one physical "
        "effect; write several files for several effects)"
    )
    assert user_effects.MAX_EFFECT_TERMS == 100


@pytest.mark.slow
def test_the_terms_are_read_in_time_linear_in_their_number(tmp_path, monkeypatch):
    # 1,000 terms of 200 parameters each: the check that no parameter is defined twice compared
    # every name with every other (4e10 comparisons); now it is one pass.
    monkeypatch.setattr(user_effects, "MAX_EFFECT_TERMS", 1000, raising=False)
    terms = [f"{{site: dpsi, harmonics: 1..100, of: phi1, prefix: t{i}_}}" for i in range(1000)]
    path = effect_file(tmp_path, terms)
    with time_limit(30):
        effect = read_effect_file(path)
    assert len(effect.terms) == 1000
    repeated = effect_file(tmp_path, [*terms[:999], terms[0]], "repeated.yaml")
    with time_limit(30), pytest.raises(InputError, match=r"parameter\(s\) t0_c1, t0_c10, "):
        read_effect_file(repeated)


def test_a_polynomial_degree_is_checked_before_its_powers_are_listed(tmp_path):
    # polynomial: 10**12 built the tuple of its 10**12 powers before the degree was checked
    path = effect_file(tmp_path, ["{site: dpsi, polynomial: 1000000000000, of: temperature_c}"])
    with time_limit(20), pytest.raises(InputError, match="polynomial degree 1000000000000: "):
        read_effect_file(path)


def test_errors_still_name_the_line_of_the_key(tmp_path):
    path = effect_file(tmp_path, ["{site: dpsi, harmonics: 1, of: phi1}", "{site: nowhere}"])
    with pytest.raises(InputError, match=r"many.yaml, line 4: terms\[2\]: a term needs 'site'"):
        read_effect_file(path)
