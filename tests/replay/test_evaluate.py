"""``replay evaluate``: a policy beside the paper's method on the same seeds, rates with Wilson
intervals; bad policies are one-line errors."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

pytest.importorskip("gymnasium")

from replay.cli import main  # noqa: E402
from replay.evaluate import PolicyError, Tally, evaluate, load_policy  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
ROW = re.compile(r"^(\S.*?)\s+(\d+)/(\d+)\s+([\d.]+) %\s+\[\s*([\d.]+),\s*([\d.]+)\] %$", re.M)


def _cli(*args, cwd: Path):
    return subprocess.run(
        [sys.executable, "-m", "replay.cli", *args],
        capture_output=True,
        text=True,
        cwd=cwd,
        timeout=600,
    )


def test_evaluate_prints_both_rates_with_intervals():
    r = _cli("evaluate", "my_policy:catch", "--task", "catch", "--n", "2", cwd=EXAMPLES)
    assert r.returncode == 0, r.stderr
    rows = ROW.findall(r.stdout)
    assert [row[0] for row in rows] == ["my_policy:catch", "paper (the paper's method)"]
    for name, wins, n, rate, lo, hi in rows:
        assert int(n) == 2
        assert float(rate) == pytest.approx(100 * int(wins) / 2, abs=0.05)
        assert float(lo) <= float(rate) <= float(hi)
    assert rows[1][1] == "2"  # the paper's method catches the nominal throw at seeds 0 and 1


def test_the_paper_and_the_policy_see_the_same_seeds(tmp_path):
    seen = []
    tallies = evaluate(
        "paper",
        "stick",
        [3, 4],
        sets=["timing.duration=0.05"],
        logs=tmp_path,
        progress=lambda name, seed, outcome: seen.append((name, seed)),
    )
    assert seen == [("paper", 3), ("paper", 4)] and len(tallies) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper-3.mcap", "paper-4.mcap"]


def test_wilson_interval_of_a_tally():
    lo, hi = Tally("x", wins=5, n=10).interval()
    assert lo == pytest.approx(0.2366, abs=1e-3) and hi == pytest.approx(0.7634, abs=1e-3)


@pytest.mark.parametrize(
    "name, message",
    [
        ("no_such_module_xyz:policy", "no module 'no_such_module_xyz'"),
        ("os:no_such_thing", "has no 'no_such_thing'"),
        ("not a path", "bad policy"),
        ("os:sep", "is not callable"),
    ],
)
def test_bad_policies_are_one_line_errors(name, message):
    with pytest.raises(PolicyError, match=message):
        load_policy(name)
    r = CliRunner().invoke(main, ["evaluate", name, "--task", "stick", "--n", "1"])
    assert r.exit_code == 2 and message in r.output and "Traceback" not in r.output


def test_an_action_of_the_wrong_size_is_a_one_line_error(tmp_path):
    (tmp_path / "short_policy.py").write_text(
        "import numpy as np\ndef policy(env):\n    return lambda obs, info: np.zeros(2)\n"
    )
    r = _cli("evaluate", "short_policy:policy", "--task", "stick", "--n", "1", cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "an action has 6 values, got 2" in r.stderr


def test_example_05_runs():
    r = subprocess.run(
        [sys.executable, str(EXAMPLES / "05_evaluate_a_policy.py"), "1"],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, r.stderr
    assert re.search(r"^my_policy:catch: [01]/1 caught, Wilson 95 % \[", r.stdout, re.M)
    assert "paper (the paper's method): 1/1 caught" in r.stdout


def test_the_command_line_does_not_import_gymnasium():
    code = "import sys, replay.cli; print('gymnasium' in sys.modules)"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.stdout.strip() == "False"
