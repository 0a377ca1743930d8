"""Nothing runaway, second sweep (issue 27, "Runaway memory and time"), at the command line: every
input file is checked before it is read, a YAML document of nested aliases is refused before it is
walked, a calibration run's random positions and a design's -n are checked before any work; each
in one line, exit status 2.

One test runs the commands in child processes under a 1.5 GB address-space limit: where they
allocated first (and were killed at 24 GB, or read /dev/zero until the memory ran out), they now
refuse cleanly."""

import os
import resource
import subprocess
import sys
import time

import pytest

from conftest import EXAMPLES_DIR, cli, cli_env, refused
from runaway import time_limit

RUN = EXAMPLES_DIR / "runs" / "run_clean.csv"
DATA = EXAMPLES_DIR / "measurements_example.csv"


def laughs(folder, levels: int = 9, name: str = "laughs.yaml"):
    """An effect file whose ``terms`` expand to 10**levels values through nested aliases (a few
    hundred bytes; it passes the safe loader)."""
    lines = ["name: laughs", 'a0: &a0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", '
             '"lol", "lol"]']  # fmt: skip
    lines += [f"a{k}: &a{k} [" + ", ".join([f"*a{k - 1}"] * 10) + "]" for k in range(1, levels)]
    lines.append(f"terms: *a{levels - 1}")
    path = folder / name
    path.write_text("\n".join(lines) + "\n")
    return path


# (command line, {zero} standing for a link to /dev/zero with the suffix the option wants)
DEVICE_READERS = [
    ["import-tpoint", "{zero}.dat", "-o", "{out}.csv"],
    ["report", "{zero}.csv", "-o", "{out}.html"],
    ["calibrate", "{zero}.csv"],
    ["rate-error", "--gyrowheel", "{zero}.yaml"],
    ["fit", "{zero}.csv"],
    ["diagnose", "{zero}.csv"],
    ["diagnose", DATA.as_posix(), "--catalogue", "{zero}.yaml"],
    ["effects", "--catalogue", "{zero}.yaml"],
    ["simulate", "--errors", "{zero}.yaml", "-o", "{out}.csv"],
    ["simulate", "--positions", "{zero}.csv", "-o", "{out}.csv"],
    ["simulate", "--urdf", "{zero}.urdf", "-o", "{out}.csv"],
    ["design", "--from", "{zero}.csv"],
    ["allocate", "--lower-bounds", "{zero}.yaml"],
    ["fit", DATA.as_posix(), "--effects", "{zero}.yaml"],
]


@pytest.mark.parametrize("argv", DEVICE_READERS, ids=lambda a: " ".join(a[:2]))
def test_every_reader_refuses_a_device_before_reading_it(tmp_path, argv):
    zero = tmp_path / "zero"
    args = []
    for a in argv:
        if a.startswith("{zero}"):
            link = tmp_path / ("zero" + a[len("{zero}") :])
            link.symlink_to("/dev/zero")
            a = str(link)
        args.append(a.replace("{out}", str(tmp_path / "out")))
    with time_limit(20):  # it read /dev/zero until the memory ran out
        proc = cli(*args)
    line = refused(proc, "cannot read the file: it is a character device", str(zero))
    assert "(give a regular file)" in line
    assert not any(p.name.startswith("out") for p in tmp_path.iterdir())


@pytest.mark.parametrize(
    "argv",
    [
        ["diagnose", DATA.as_posix(), "--catalogue", "{laughs}"],
        ["simulate", "--catalogue", "{laughs}", "-o", "{out}"],
        ["fit", DATA.as_posix(), "--effects", "{laughs}"],
        ["effects", "--catalogue", "{laughs}"],
    ],
    ids=lambda a: a[0],
)
def test_a_billion_laughs_effect_file_is_refused_at_once(tmp_path, argv):
    # Before: 5.7 GB after 45 s, growing.
    path = laughs(tmp_path)
    out = tmp_path / "out.csv"
    args = [str(path) if a == "{laughs}" else str(out) if a == "{out}" else a for a in argv]
    with time_limit(20):
        proc = cli(*args)
    refused(proc, str(path), "more than 1,000,000 values once its aliases")
    assert not out.exists()


@pytest.mark.parametrize(
    "argv, shown",
    [
        (["design", "--calibrate", "-n", "9223372036854775807"], "9,223,372,036,854,775,807"),
        (["design", "--calibrate", "-n", "1000000000"], "1,000,000,000"),
        (["design", "-n", "1000000000"], "1,000,000,000"),
        (["design", "--separate", "backlash,inner_encoder_harmonics", "-n", "20000"], "20,000"),
        (
            [
                "design",
                "--separate",
                "table:dalpha_x2,g_squared_terms",
                "--run",
                RUN.as_posix(),
                "-n",
                "1000000",
            ],
            "1,000,000",
        ),  # fmt: skip
    ],
    ids=["calibrate-max", "calibrate-1e9", "identify", "separate", "separate-run"],
)
def test_design_checks_n_against_the_candidates_before_any_work(argv, shown):
    # Before: --calibrate -n 2**63-1 ran for 10 minutes, -n 1e9 took 25 s to be refused, and
    # --separate --run -n 1000000 returned all 10,144 candidates after 90 s.
    with time_limit(20):
        proc = cli(*argv)
    line = refused(proc)
    assert line.endswith(
        f"error: -n is {shown}, more than the 10,144 candidate positions a design chooses among "
        "(each once); ask for fewer, or give more --candidates"
    )


def test_simulate_run_checks_its_random_positions_before_drawing_them(tmp_path):
    out = tmp_path / "run.csv"
    with time_limit(20):  # it allocated 16 GB of angles first
        proc = cli("simulate", "--run", "--random-positions", "1000000000", "-o", str(out))
    line = refused(proc)
    assert "1,000,000,000 random positions of a calibration run would be needed" in line
    assert "at most 200,000 are accepted" in line and not out.exists()


def test_a_huge_input_file_is_refused_with_its_size(tmp_path):
    tpoint = tmp_path / "run.dat"
    with tpoint.open("wb") as handle:  # sparse: 200 MB said, 3 million lines' worth
        handle.truncate(200_000_000)
    with time_limit(20):
        proc = cli("import-tpoint", str(tpoint), "-o", str(tmp_path / "out.csv"))
    line = refused(proc)
    assert line.endswith(
        "the file is 200 MB (200,000,000 bytes); a TPOINT file is read up to 16 MB"
    )


def _address_space_limit():
    limit = 1_500_000_000
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
def test_under_a_memory_limit_the_runaways_are_clean_refusals(tmp_path):
    """In a child process limited to 1.5 GB of address space, each command refuses in one line
    (exit 2). Before, the first allocated 16 GB of angles (a MemoryError traceback here, a kill by
    the kernel without the limit) and the others read /dev/zero or walked 10**9 aliases until the
    memory ran out."""
    zero = tmp_path / "zero.csv"
    zero.symlink_to("/dev/zero")
    commands = [
        ["simulate", "--run", "--random-positions", "1000000000", "-o", str(tmp_path / "r.csv")],
        ["import-tpoint", "/dev/zero", "-o", str(tmp_path / "t.csv")],
        ["report", str(zero), "-o", str(tmp_path / "report.html")],
        ["effects", "--catalogue", str(laughs(tmp_path))],
        ["design", "--calibrate", "-n", "9223372036854775807"],
    ]
    for argv in commands:
        start = time.perf_counter()
        proc = subprocess.run(
            [sys.executable, "-m", "turntable_pin", *argv], capture_output=True, text=True,
            env=cli_env(), preexec_fn=_address_space_limit, timeout=120,
        )  # fmt: skip
        assert proc.returncode == 2, (argv, proc.returncode, proc.stderr[-2000:])
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "error:" in lines[0], (argv, proc.stderr[-2000:])
        assert "MemoryError" not in proc.stderr and "Traceback" not in proc.stderr
        assert time.perf_counter() - start < 60, argv
    assert sorted(os.listdir(tmp_path)) == ["laughs.yaml", "zero.csv"]
