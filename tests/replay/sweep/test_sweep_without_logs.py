"""``replay sweep --no-logs`` writes no log at all (issue #41: a sweep pays only for what it
keeps), and its rows are the ones a sweep keeping full logs makes: the outcome, its metrics, the
events and where the run stopped, for each paper and for a run that ends on a non-finite value;
with a ``metrics:`` function, its columns too, read from the run's messages kept in memory."""

from __future__ import annotations

import math

import pytest

from conftest import ROOT
from replay.runner import Runner
from replay.scenario import load_scenario
from replay.sweep.spec import from_options
from replay.sweep.variants import expand
from replay.sweep.worker import run_variant

SAME_WHATEVER_RAN = ("wall_time", "cpu_time", "log")  # (the rest must be equal)


def _rows(scenario, sets, tmp_path, monkeypatch, metrics=""):
    monkeypatch.chdir(ROOT)  # (run_variant changes the cwd: restored after the test)
    spec = from_options(["seed=3"], [], None)
    (v,) = expand(scenario, spec, 0, sets=sets, version="test")
    assert not v.error, v.error
    rows = []
    for log in (str(tmp_path / "kept.mcap"), ""):
        task = {"key": v.key, "index": 0, "resolved": v.resolved, "file_dirs": v.file_dirs}
        task |= {"error": "", "log": log, "cwd": str(ROOT), "metrics": metrics}
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


def every_topic(log) -> dict:
    """A metrics function that reads everything a metrics function may: each JSON topic's
    message count and the sum of its numbers, the events, the outcome, the stored scenario."""
    out: dict = {}
    for topic, n in sorted(log.topic_counts().items()):
        series = log.series(topic)
        if series:  # (the Foxglove topics are not JSON: a log's only, never read as series)
            out[f"{topic}.n"] = n
            out[f"{topic}.sum"] = _numbers(series)
    out["events"] = [e["kind"] for e in log.events()]
    out["outcome"] = log.outcome()
    out["scenario"] = log.scenario()["name"]
    out["plant"] = log.scenario_config()["plant"]["type"]
    out["messages"] = sum(1 for _ in log.messages(["/events", "/scenario"]))
    return out


def _numbers(value) -> float:
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return 0.0
    if isinstance(value, (int, float)):
        return float(value) if math.isfinite(value) else 0.0
    items = value.values() if isinstance(value, dict) else value
    return math.fsum(_numbers(v) for v in items)


def _same(a: dict, b: dict) -> None:
    strip = lambda row: {k: v for k, v in row.items() if k not in SAME_WHATEVER_RAN}  # noqa: E731
    a, b = strip(a), strip(b)
    assert a.keys() == b.keys()
    for k, v in a.items():
        if isinstance(v, float):
            assert b[k] == pytest.approx(v, rel=1e-12, abs=1e-12), k
        else:
            assert b[k] == v, k


@pytest.mark.parametrize(
    "scenario,sets,metrics",
    [
        ("stick_3step", ["timing.duration=1.0"], "analysis.stick.ablations:run_metrics"),
        ("stick_3step", ["timing.duration=1.0"], "analysis.stick.ablations:first_collision"),
        ("catch_optimised", ["timing.duration=0.5"], "analysis.catching.ablations:catch_metrics"),
        (
            "catch_optimised",  # (as sweeps/catch_optimisation.yaml's cells: torque limits)
            ["timing.duration=0.45", "plant.params.torque_limits=[60, 60, 45, 30]"],
            "analysis.catching.ablation_opt:effort_metrics",
        ),
        ("grasp_hexahedron", ["timing.duration=0.3"], f"{__name__}:every_topic"),
        ("catch_optimised_mujoco", ["timing.duration=0.45"], f"{__name__}:every_topic"),
        ("catch_optimised", ["timing.duration=0.5"], f"{__name__}:every_topic"),
    ],
)
def test_metrics_without_a_log_equal_those_of_a_full_log(
    scenario, sets, metrics, tmp_path, monkeypatch
):
    kept, memory = _rows(
        ROOT / "scenarios" / f"{scenario}.yaml", sets, tmp_path, monkeypatch, metrics
    )
    assert kept["log"] and not memory["log"]
    assert not list(tmp_path.iterdir()) or [p.name for p in tmp_path.iterdir()] == ["kept.mcap"]
    extra = [k for k in kept if k.startswith("x.")]
    assert len(extra) >= 2, kept  # (the metrics ran and gave columns)
    assert not str(kept["reason"]).startswith("error"), kept["reason"]
    _same(kept, memory)


def test_a_memory_run_writes_no_file(tmp_path, monkeypatch):
    """The run behind a metrics row without a log: no file anywhere under the cwd or TMPDIR."""
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", None)
    sc = load_scenario(ROOT / "scenarios" / "stick_3step.yaml", sets=["timing.duration=0.3"])
    runner = Runner(sc)
    result = runner.run(None, keep=True)
    reader = runner.log.reader()
    assert reader.outcome()["data"] == result.outcome
    assert reader.topic_counts()["/events"] == len(reader.events())
    assert not list(tmp_path.iterdir())
