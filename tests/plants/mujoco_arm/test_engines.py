"""Claims per engine (analysis/engines.py): the catch rows of the PyBullet and the MuJoCo runs of
the same scenarios side by side, each decided by the paper's own rows on each engine's truth."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis.claims import Claim
from analysis.engines import closing_note, engine_rows, join, rate_row, split_logs

ROOT = Path(__file__).resolve().parents[3]
NAMES = ("catch_optimised", "catch_initial")


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    from replay.log import LogReader
    from replay.runner import Runner
    from replay.scenario import load_scenario

    out = tmp_path_factory.mktemp("engines")
    res = {}
    for name in NAMES + tuple(n + "_mujoco" for n in NAMES):
        path = out / f"{name}.mcap"
        Runner(load_scenario(ROOT / "scenarios" / f"{name}.yaml")).run(path)
        res[name] = LogReader(str(path))
    return res


def test_every_catch_row_shows_both_engines(logs):
    from analysis.catching.claims import evaluate

    groups = split_logs(logs)
    assert list(groups) == ["PyBullet", "MuJoCo"]
    pb, mj = groups["PyBullet"], groups["MuJoCo"]
    assert set(pb) == set(mj) == set(NAMES)
    rows = engine_rows(evaluate, logs)
    assert {r.quantity for r in rows} == {r.quantity for r in evaluate(pb)}
    for r in rows:
        assert r.measured.startswith("PyBullet: ") and " ‖ MuJoCo: " in r.measured, r.quantity
        if r.status != "not run":  # (a row neither engine's logs decide says "not run" in both)
            assert "not run" not in r.measured, r.quantity
    # the optimised catch is the paper's throws' row, the unoptimised one a note of its own
    caught = {r.quantity: r for r in rows if "caught" in r.quantity or "throws, 8" in r.quantity}
    assert set(caught) == {"catch over the stated throws, 8 ~ 10 m/s", "catch_initial: ball caught"}
    for r in caught.values():  # the plants' own verdict, the same in each engine
        assert "engines part" not in r.note, r
    assert caught["catch over the stated throws, 8 ~ 10 m/s"].status == "reproduced"
    note = closing_note(rows)
    assert "catch over the stated throws, 8 ~ 10 m/s" in note.splitlines()[0]


def test_rows_that_part_say_so():
    a = [Claim("q", "1", "1.0", "reproduced", "n"), Claim("only", "x", "y", "note")]
    b = [Claim("q", "1", "2.0", "differs", "n")]
    rows = join({"PyBullet": a, "MuJoCo": b})
    assert rows[0].status == "differs" and rows[0].note.startswith(
        "engines part: PyBullet reproduced, MuJoCo differs"
    )
    assert rows[0].measured == "PyBullet: 1.0 ‖ MuJoCo: 2.0"
    assert rows[1].measured.endswith("MuJoCo: not run")
    assert rows[1].status == "note"  # run in one engine only: that engine's verdict stands
    assert "q (PyBullet reproduced, MuJoCo differs)" in closing_note(rows)


def test_a_row_an_engine_did_not_run_is_not_compared():
    # MuJoCo's logs lack the row's runs (its evaluate says "not run", with why): no engine
    # comparison, so the closing note does not say it holds in both
    a = [Claim("q", "1", "caught", "reproduced", "")]
    b = [Claim("q", "1", "(no catch_optimised log)", "not run", "")]
    rows = join({"PyBullet": a, "MuJoCo": b})
    assert rows[0].measured == "PyBullet: caught ‖ MuJoCo: not run (no catch_optimised log)"
    assert rows[0].status == "reproduced"  # the engine that ran decides the row
    note = closing_note(rows).splitlines()
    assert note[0] == "Hold in both engines (0): none."
    assert note[-1] == "Run in one engine only, not compared: 1 rows."


def test_any_number_of_engines_join_and_the_note_says_all():
    a = [Claim("q", "1", "1.0", "reproduced", ""), Claim("r", "1", "1", "reproduced", "")]
    b = [Claim("q", "1", "2.0", "reproduced", ""), Claim("r", "1", "1", "reproduced", "")]
    c = [Claim("q", "1", "3.0", "differs", ""), Claim("r", "1", "1", "reproduced", "")]
    rows = join({"PyBullet": a, "MuJoCo": b, "Drake": c})
    assert rows[0].measured == "PyBullet: 1.0 ‖ MuJoCo: 2.0 ‖ Drake: 3.0"
    assert rows[0].status == "differs"
    assert rows[0].note == "engines part: PyBullet reproduced, MuJoCo reproduced, Drake differs"
    assert rows[1].status == "reproduced"
    note = closing_note(rows).splitlines()
    assert note[0] == "Hold in all 3 engines (1): r."
    assert note[1].startswith("Hold in some engines only (1): q (PyBullet reproduced")


def test_the_engine_is_the_resolved_scenarios():
    """A log's engine: plant.params.engine.type, else its plant type (logs before the field);
    a twin named with ``_<engine>`` joins its reference run's name."""

    class Log:
        def __init__(self, scenario: dict) -> None:
            self._scenario = scenario

        def scenario(self) -> dict:
            return {"name": self._scenario["name"]}

        def scenario_config(self) -> dict:
            return self._scenario

    arm = {"type": "arm_rig", "params": {}}
    logs = {
        "catch_optimised": Log({"name": "catch_optimised", "plant": arm}),
        "catch_optimised_mujoco": Log(
            {"name": "catch_optimised_mujoco", "plant": {"type": "mujoco_arm", "params": {}}}
        ),
        "catch_initial_drake": Log(
            {
                "name": "catch_initial_drake",
                "plant": {"type": "arm_rig", "params": {"engine": {"type": "drake"}}},
            }
        ),
        "catch_optimised_newton": Log(
            {
                "name": "catch_optimised_newton",
                "plant": {"type": "arm_rig", "params": {"engine": {"type": "newton"}}},
            }
        ),
        "catch_initial_mujoco": Log(
            {
                "name": "catch_initial_mujoco",
                "plant": {"type": "arm_rig", "params": {"engine": {"type": "mujoco"}}},
            }
        ),
    }
    groups = split_logs(logs)
    assert {e: sorted(g) for e, g in groups.items()} == {
        "PyBullet": ["catch_optimised"],
        "MuJoCo": ["catch_initial", "catch_optimised"],
        "Drake": ["catch_initial"],
        "newton": ["catch_optimised"],  # an engine LABELS does not list: its name
    }


def test_rate_row():
    ok, bad = {"success": True, "reason": "caught"}, {"success": False, "reason": "x"}
    r = rate_row("rate", "≥ 90 %", {"PyBullet": [ok] * 10, "MuJoCo": [ok] * 9 + [bad]})
    assert r.status == "reproduced" and "MuJoCo: 9/10 = 90 % [60–98 %]" in r.measured
    assert r.measured.startswith("PyBullet: 10/10 = 100 % [72–100 %] ‖ ")
    assert r.note == "MuJoCo failures: 1× x"
    r = rate_row("rate", "≥ 90 %", {"PyBullet": [ok] * 10, "MuJoCo": [ok] * 8 + [bad] * 2})
    assert r.status == "differs" and "MuJoCo failures: 2× x" in r.note
    # the engines part, but 10/10 and 8/10 are within each other's sampling error
    assert r.note.startswith("engines part: PyBullet reproduced, MuJoCo differs (their intervals")
    r = rate_row("rate", "≥ 90 %", {"PyBullet": [ok] * 40, "MuJoCo": [ok] * 20 + [bad] * 20})
    assert r.note.startswith("engines part: PyBullet reproduced, MuJoCo differs; ")
    r = rate_row("rate", "≥ 90 %", {"PyBullet": [bad] * 3, "MuJoCo": []})
    assert r.status == "differs" and r.measured.endswith("MuJoCo: not run")
