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
