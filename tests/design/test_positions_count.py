"""How many positions a design chooses is checked before any work (issue 27, "Runaway memory
and time"): at most the candidates of its space, each chosen once; the library names its
argument (``n_positions``), the command line ``-n``. Before, ``design --calibrate -n 2**63-1``
ran for ten minutes (factorising N for its reference grid) and ``-n 1e9`` took 25 s to be
refused."""

import pytest

from runaway import time_limit
from turntable_pin.core.exceptions import InputError
from turntable_pin.design.calibrate import design_calibration
from turntable_pin.design.identify import design_identify
from turntable_pin.design.separate import design_separate
from turntable_pin.design.space import design_space
from turntable_pin.measurement.catalogue import resolve_effect


@pytest.fixture(scope="module")
def space():
    return design_space(candidates=100, seed=1)  # 100 drawn + the 144 of the 30-degree grid


@pytest.mark.parametrize("n", [245, 10**9, 2**63 - 1])
def test_calibrate_refuses_more_positions_than_candidates_at_once(space, n):
    assert space.candidates_deg.shape[0] == 244
    with time_limit(10), pytest.raises(InputError) as caught:
        design_calibration(space, n)
    assert str(caught.value) == (
        f"n_positions is {n:,}, more than the 244 candidate positions a design chooses among "
        "(each once); ask for fewer, or give more candidates"
    )


@pytest.mark.parametrize("design", ["identify", "separate"])
def test_identify_and_separate_refuse_before_the_rows_are_built(space, design, monkeypatch):
    import turntable_pin.design.identify as identify

    def never(*args, **kwargs):
        raise AssertionError("the design's rows were built")

    monkeypatch.setattr(identify, "design_rows", never)  # both designs build their rows there
    if design == "identify":
        run = lambda n: design_identify(space, n)  # noqa: E731
    else:
        pair = [resolve_effect(n, None) for n in ("backlash", "inner_encoder_harmonics")]
        pair_space = design_space(effects=pair, candidates=100, seed=1)
        run = lambda n: design_separate(pair_space, n)  # noqa: E731
    with pytest.raises(InputError, match=r"^n_positions is 1,000,000,000, more than the 244 "):
        run(10**9)
    with pytest.raises(InputError, match=r"^n_positions must be at least 1, got 0"):
        run(0)


def test_the_check_names_the_argument_it_is_given():
    from turntable_pin.core.sizes import check_positions_count

    assert check_positions_count(5, 5) == 5
    with pytest.raises(InputError, match=r"^-n is 6, more than the 5 candidate positions .* give "
                                         r"more --candidates$"):  # fmt: skip
        check_positions_count(6, 5, "-n", "more --candidates")
    with pytest.raises(InputError, match=r"^n must be a whole number of positions, got 2\.5"):
        check_positions_count(2.5, 5, "n")
    with pytest.raises(InputError, match="got True"):
        check_positions_count(True, 5)
