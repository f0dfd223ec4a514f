"""``replay evaluate``: a policy beside the paper's method on the same inputs of a named set,
rates with Wilson intervals; bad policies and unknown sets are one-line errors."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main  # noqa: E402
from replay.api import run  # noqa: E402
from replay.evaluate import (  # noqa: E402
    InputSetError,
    PolicyError,
    Tally,
    evaluate,
    input_set,
    load_policy,
)
from replay.golden import compare_logs  # noqa: E402
from replay.log import LogReader  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
EXACT = {"abs": 0, "rel": 0}
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
    assert "input set held-out, episodes 0..1: 2 distinct physical inputs" in r.stdout
    rows = ROW.findall(r.stdout)
    assert [row[0] for row in rows] == ["my_policy:catch", "paper (the paper's method)"]
    for name, wins, n, rate, lo, hi in rows:
        assert int(n) == 2
        assert float(rate) == pytest.approx(100 * int(wins) / 2, abs=0.05)
        assert float(lo) <= float(rate) <= float(hi)
    # the paper's method catches held-out throws 0 and 1 (data/ablations/engine_rates.csv)
    assert rows[1][1] == "2"


def test_the_episodes_and_their_logs_follow_the_set(tmp_path):
    seen = []
    tallies = evaluate(
        "paper",
        "stick",
        input_set("held-out", "stick", 2, first=3),
        sets=["timing.duration=0.05"],  # (after the set's 3.0 s: it wins)
        logs=tmp_path,
        progress=lambda name, ep, outcome: seen.append((name, ep.number, ep.seed)),
    )
    assert seen == [("paper", 3, 3), ("paper", 4, 4)] and len(tallies) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["paper-3.mcap", "paper-4.mcap"]
    for k in (3, 4):
        yaml = LogReader(tmp_path / f"paper-{k}.mcap").scenario()["yaml"]
        assert "random: true" in yaml and "duration: 0.05" in yaml, yaml


def test_the_paper_through_evaluate_equals_replay_run_on_held_out_throws(tmp_path):
    """The paper's method on 3 held-out catch episodes: the outcome and the log of
    ``replay run --seed S --set ...`` with that episode's overrides (zero tolerance)."""
    episodes = input_set("held-out", "catch", 3)
    outcomes = {}
    evaluate(
        "paper",
        "catch",
        episodes,
        logs=tmp_path,
        progress=lambda name, ep, outcome: outcomes.setdefault(ep.number, outcome),
    )
    for ep in episodes:
        r = run("catch_optimised", seed=ep.seed, set=list(ep.set), log=tmp_path / "run.mcap")
        assert outcomes[ep.number] == r.outcome, ep.input
        assert compare_logs(r.path, tmp_path / f"paper-{ep.number}.mcap", {}, EXACT) == []
    assert len({o["first_contact_time"] for o in outcomes.values()}) == 3  # three throws


def test_an_unknown_input_set_is_a_one_line_error_listing_the_known_ones():
    with pytest.raises(InputSetError, match=r"unknown input set 'nope' \(known: .*held-out"):
        input_set("nope", "catch", 1)
    r = CliRunner().invoke(main, ["evaluate", "paper", "--task", "catch", "--set-of", "nope"])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert r.output.strip().splitlines() == ["error: unknown input set 'nope' (known: held-out)"]


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


@pytest.mark.parametrize(
    "made, message",
    [
        (lambda task, n: [{"seed": -1, "set": []}] * n, "episode 0 is not"),
        (lambda task, n: [{"seed": 1, "set": "x=1"}] * n, "episode 0 is not"),
        (lambda task, n: [{"seed": 1}] * (n - 1), "gave fewer than 2 episodes"),
        (lambda task, n: 1 / 0, "division by zero"),
    ],
)
def test_a_bad_input_set_plugin_is_a_one_line_error(monkeypatch, made, message):
    from replay import registry

    monkeypatch.setitem(registry._registered["input_sets"], "bad", made)
    with pytest.raises(InputSetError, match=message):
        input_set("bad", "catch", 2)
