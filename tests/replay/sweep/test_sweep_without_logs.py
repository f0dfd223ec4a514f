"""``replay sweep --no-logs`` without a metrics function writes no log at all (issue #41: a sweep
pays only for what it keeps), and its rows are the ones a sweep keeping full logs makes: the
outcome, its metrics, the events and where the run stopped, for each paper and for a run that
ends on a non-finite value."""

from __future__ import annotations

import pytest

from conftest import ROOT
from replay.runner import Runner
from replay.scenario import load_scenario
from replay.sweep.spec import from_options
from replay.sweep.variants import expand
from replay.sweep.worker import run_variant

SAME_WHATEVER_RAN = ("wall_time", "cpu_time", "log")  # (the rest must be equal)


def _rows(scenario, sets, tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)  # (run_variant changes the cwd: restored after the test)
    spec = from_options(["seed=3"], [], None)
    (v,) = expand(scenario, spec, 0, sets=sets, version="test")
    assert not v.error, v.error
    rows = []
    for log in (str(tmp_path / "kept.mcap"), ""):
        task = {"key": v.key, "index": 0, "resolved": v.resolved, "file_dirs": v.file_dirs}
        task |= {"error": "", "log": log, "cwd": str(ROOT), "metrics": ""}
        rows.append(run_variant(task))
    return rows


@pytest.mark.parametrize(
    "scenario,sets",
    [
        ("stick_3step", ["timing.duration=1.0"]),
        ("catch_optimised", ["timing.duration=0.4"]),
        ("grasp_hexahedron", ["timing.duration=0.3"]),
        ("catch_optimised_mujoco", ["timing.duration=0.35"]),
    ],
)
def test_a_variant_without_a_log_has_the_row_of_one_with_a_full_log(
    scenario, sets, tmp_path, monkeypatch
):
    kept, unwritten = _rows(ROOT / "scenarios" / f"{scenario}.yaml", sets, tmp_path, monkeypatch)
    assert kept["log"] and not unwritten["log"]
    strip = lambda row: {k: v for k, v in row.items() if k not in SAME_WHATEVER_RAN}  # noqa: E731
    assert strip(unwritten) == strip(kept)
    assert any(k.startswith("m.") for k in kept) and any(k.startswith("e.") for k in kept)


def test_a_non_finite_value_ends_an_unwritten_run_as_it_ends_a_logged_one(toy_yaml, tmp_path):
    sc = load_scenario(toy_yaml, sets=["plant.params.blow_up_at=0.2"])
    logged = Runner(sc).run(tmp_path / "nan.mcap")
    unwritten = Runner(load_scenario(toy_yaml, sets=["plant.params.blow_up_at=0.2"])).run(None)
    assert unwritten.stopped_by == logged.stopped_by == "error"
    assert unwritten.outcome == logged.outcome and "non-finite" in unwritten.outcome["reason"]
    assert unwritten.steps == logged.steps  # (its count leaves out the Foxglove topics)
    assert not list(tmp_path.glob("*.part"))
