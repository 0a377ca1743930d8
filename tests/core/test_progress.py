import io

from turntable_pin.core.progress import Progress


def test_non_tty_prints_every_ten_percent():
    stream = io.StringIO()
    with Progress(100, "monte carlo", stream=stream) as bar:
        for _ in range(100):
            bar.update(1)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 11 and lines[-1].startswith("monte carlo: 100% (100/100")


def test_disabled_is_silent():
    stream = io.StringIO()
    with Progress(10, "x", enabled=False, stream=stream) as bar:
        bar.update(10)
    assert stream.getvalue() == "" and bar.done == 10


def test_a_delay_keeps_short_work_silent_and_long_work_reported(monkeypatch):
    import turntable_pin.core.progress as progress

    now = [0.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: now[0])
    quiet, loud = io.StringIO(), io.StringIO()
    with Progress(4, "short", stream=quiet, delay_s=1.0) as bar:
        bar.update(4)  # done at once
    assert quiet.getvalue() == ""
    with Progress(4, "long", stream=loud, delay_s=1.0) as bar:
        bar.update(1)  # before the delay: silent
        now[0] = 2.0
        bar.update(1)
        bar.update(2)
    assert loud.getvalue().splitlines() == ["long:  50% (2/4, 2.0 s)", "long: 100% (4/4, 2.0 s)"]
