"""A sweep's variants are counted and bounded (``sweep_variants``) before any is made, made one
at a time, and bad ``--random`` bounds are one ``error:`` line."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from replay.sweep.spec import SweepSpecError, from_options

RUNNER = """
import atexit, resource, sys
import replay.cli, numpy
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
grown = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base
atexit.register(lambda: sys.stderr.write(f"\\nRSS_GROWTH_KB {grown()}\\n"))
sys.argv = ["replay", *sys.argv[1:]]
from replay.entry import main
main()
"""


def _sweep(*args, env=None, timeout=60):
    p = subprocess.run(
        [sys.executable, "-c", RUNNER, "sweep", "stick_3step", *args],
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
        timeout=timeout,
    )
    lines = p.stderr.splitlines()
    growth = [int(x.split()[1]) for x in lines if x.startswith("RSS_GROWTH_KB")]
    p.stderr = "\n".join(x for x in lines if x and not x.startswith("RSS_GROWTH_KB"))
    return p, growth[0] if growth else -1


def _one_error_line(p, *words):
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr
    errors = [x for x in p.stderr.splitlines() if x.startswith("error:")]
    assert len(errors) == 1 and p.stdout == "", p.stderr
    for w in words:
        assert w in errors[0], errors[0]


@pytest.mark.parametrize(
    "args, count",
    [
        (["--random", "plant.params.stick.friction=0:1", "--n", "100000000"], "100,000,000"),
        (["--random", "plant.params.stick.friction=0:1", "--n", str(10**30)], "variants"),
        (
            ["--grid", "plant.params.stick.friction=" + ",".join(f"0.{i:03d}" for i in range(1000))]
            + [
                "--grid",
                "plant.params.stick.restitution=" + ",".join(f"0.{i:03d}" for i in range(1000)),
            ],
            "1,000,000",
        ),
    ],
)
def test_too_many_variants_is_one_line_at_once(tmp_path, args, count):
    t0 = time.perf_counter()
    p, growth = _sweep(*args, "-o", str(tmp_path / "out"))
    assert time.perf_counter() - t0 < 30
    _one_error_line(p, count, "100,000", "REPLAY_LIMIT_SWEEP_VARIANTS")
    assert 0 <= growth < 40_000  # KB
    assert not (tmp_path / "out").exists()


def test_the_count_comes_first_and_the_limit_can_be_raised(tmp_path):
    p, _ = _sweep(
        "--grid",
        "plant.params.stick.friction=0.2,0.3,0.4",
        "--set",
        "timing.duration=0.05",
        "-o",
        str(tmp_path / "out"),
        env={"REPLAY_LIMIT_SWEEP_VARIANTS": "2"},
    )
    _one_error_line(p, "this sweep is 3 variants", "over the limit of 2")
    p, _ = _sweep(
        "--grid",
        "plant.params.stick.friction=0.2,0.3,0.4",
        "--set",
        "timing.duration=0.05",
        "--workers",
        "1",
        "-o",
        str(tmp_path / "out"),
        env={"REPLAY_LIMIT_SWEEP_VARIANTS": "3"},
    )
    assert p.returncode == 0, p.stderr
    assert p.stderr.splitlines()[0] == "note: sweep: 3 variants to plan"
    assert p.stdout.startswith("sweep: 3 variants: 3 ran")


@pytest.mark.parametrize(
    "bounds, words",
    [
        ("seed=0:9223372036854775807", None),  # (drawn, each a whole number within int64)
        ("plant.params.stick.friction=0:18446744073709551616", "out of range"),
        ("plant.params.stick.friction=-9223372036854775809:0", "out of range"),
        ("plant.params.stick.friction=0:" + "9" * 5000, "5000 characters"),
        ("plant.params.stick.friction=0:.inf", "finite"),
        ("plant.params.stick.friction=.nan:1", "finite"),
        ("plant.params.stick.friction=1:0", "lo < hi"),
        ("plant.params.stick.friction=0.5:0.5", "lo < hi"),
        ("plant.params.stick.friction=-1.0e+308:1.0e+308", "too wide"),
        ("plant.params.stick.friction=0:1e999", "number"),
        ("plant.params.stick.friction=0:[1]", "number"),
    ],
)
def test_bad_random_bounds_are_one_line(bounds, words):
    if words is None:
        spec = from_options([], [bounds], 3)
        points = spec.points(0)
        assert len(points) == 3
        assert all(isinstance(p["seed"], int) and 0 <= p["seed"] < 2**63 for p in points)
        return
    with pytest.raises(SweepSpecError) as exc:
        from_options([], [bounds], 2)
    assert words in str(exc.value) and "\n" not in str(exc.value)
    assert len(str(exc.value)) < 300


def test_the_reproducers_of_the_issue_on_the_command_line(tmp_path):
    p, _ = _sweep(
        "--random", "plant.params.stick.friction=0:18446744073709551616", "--n", "2", "-q"
    )
    _one_error_line(p, "out of range")
    p, _ = _sweep(
        "--random",
        "seed=0:9223372036854775806",
        "--n",
        "2",
        "--set",
        "timing.duration=0.05",
        "--workers",
        "1",
        "-q",
        "-o",
        str(tmp_path / "out"),
    )
    assert p.returncode == 0, p.stderr
    assert p.stdout.startswith("sweep: 2 variants: 2 ran") and "Traceback" not in p.stderr


def test_points_are_made_lazily_and_counted_before():
    spec = from_options(["x=1,2,3"], ["z=0:1"], 4)
    assert spec.count == 12
    it = spec.iter_points(0)
    first = next(it)
    assert set(first) == {"x", "z"}
    assert [first, *it] == spec.points(0)  # the same draws for every grid point, in order
    big = from_options([], ["z=0:1"], 100_000)
    assert big.count == 100_000
    with pytest.raises(SweepSpecError, match="REPLAY_LIMIT_SWEEP_VARIANTS"):
        from_options([], ["z=0:1"], 100_001)


def test_a_sweep_file_is_bounded_too(tmp_path):
    from replay.sweep.spec import load_sweep_file

    base = "scenario: s.yaml\nplot: m:f\nrandom: {a: [0, 1]}\n"
    for n, words in [
        ("1000000", "REPLAY_LIMIT_SWEEP_VARIANTS"),
        ("abc", "n: expected"),
        ("0", "n: expected"),
    ]:
        f = tmp_path / "sw.yaml"
        f.write_text(base + f"n: {n}\n")
        with pytest.raises(SweepSpecError, match=words):
            load_sweep_file(f)
