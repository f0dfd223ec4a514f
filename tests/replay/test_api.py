"""The Python API (replay.api): runs from a name, a file or a mapping, their data as arrays equal
to what their logs hold, no file left behind without ``log=``, one kind of error for a bad
scenario; and the loader's shipped names and ``extends`` in a text."""

from __future__ import annotations

import re
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import yaml

import replay
from replay.log import LogError, LogReader
from replay.resources import scenario_dir
from replay.scenario import ScenarioError, load_scenario, scenario_from_text

ROOT = Path(__file__).resolve().parents[2]
SHORT = ["timing.duration=0.35"]  # s: past the first collision (0.31 s), ~0.1 s to run


def _same_tables(a: replay.Run, b: replay.Run, topics=None) -> None:
    for topic in topics or ["/stick/state", "/fingers/state", "/hand/state", "/events"]:
        ta, tb = a.table(topic), b.table(topic)
        assert list(ta) == list(tb), topic
        for k in ta:
            assert ta[k].dtype == tb[k].dtype and ta[k].shape == tb[k].shape, (topic, k)
            if ta[k].dtype == object:
                assert list(ta[k]) == list(tb[k]), (topic, k)
            else:
                assert np.array_equal(ta[k], tb[k], equal_nan=ta[k].dtype.kind == "f"), (topic, k)


def test_a_kept_run_gives_exactly_what_its_log_holds(tmp_path):
    path = tmp_path / "stick.mcap"
    run = replay.run("stick_3step", set=SHORT, log=path)
    assert run.path == path and path.is_file()
    log = LogReader(path)
    assert run.topics == log.topic_counts()
    assert run.events == log.events() and run.outcome == log.outcome()["data"]
    assert run.scenario == yaml.safe_load(log.scenario()["yaml"])
    assert run.scenario["timing"]["duration"] == 0.35
    for topic in ("/stick/state", "/fingers/state", "/hand/state", "/vision/stick"):
        stored = list(log.messages(topic))
        table = run.table(topic)
        assert list(table) == list(stored[0].data)  # every field, t first, in the log's order
        for field, column in table.items():
            values = [m.data[field] for m in stored]
            assert column.dtype.kind in "fi" and len(column) == len(stored)
            assert np.array_equal(column, np.array(values, dtype=column.dtype)), field
            assert column.tolist() == values  # the same numbers, not close ones
    tips = run.table("/fingers/state")["tips"]
    assert tips.shape == (run.topics["/fingers/state"], 2, 2)
    # the outcome is the verdict `replay info` shows
    info = subprocess.run(
        [sys.executable, "-m", "replay.cli", "info", str(path)], capture_output=True, text=True
    )
    verdict = "success" if run.outcome["success"] else "FAILED"
    assert f"outcome: {verdict}: {run.outcome['reason']}" in info.stdout, info.stderr


def test_what_a_caller_changes_in_events_or_outcome_is_not_seen_later():
    run = replay.run("stick_3step", set=SHORT)
    reason, first = run.outcome["reason"], run.events[0]["kind"]
    run.outcome["reason"] = "changed"  # (a notebook annotating its results)
    run.events[0]["kind"] = "changed"
    assert run.outcome["reason"] == reason and run.events[0]["kind"] == first
    assert run.table("/events")["kind"][0] == first


def test_a_run_in_memory_writes_no_file_and_equals_its_logged_twin(tmp_path, monkeypatch):
    cwd, tmp = tmp_path / "cwd", tmp_path / "tmp"
    cwd.mkdir()
    tmp.mkdir()
    monkeypatch.chdir(cwd)
    monkeypatch.setattr(tempfile, "tempdir", str(tmp))
    run = replay.run("stick_3step", set=SHORT)
    assert run.path is None
    assert list(cwd.iterdir()) == [] and list(tmp.iterdir()) == []  # nothing left behind
    kept = replay.run("stick_3step", set=SHORT, log=tmp_path / "kept.mcap")
    _same_tables(run, kept)
    assert run.events == kept.events and run.outcome == kept.outcome
    assert run.scenario == kept.scenario and run.topics == kept.topics
    assert run.table("/events")["kind"].tolist()[-1] == "outcome"
    with pytest.raises(KeyError, match="not JSON"):  # Foxglove's protobuf topic: no table
        run.table("/tf")


def test_a_name_a_file_and_a_mapping_run_the_same_scenario(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    by_name = replay.run("stick_3step", set=SHORT)
    by_path = replay.run(scenario_dir() / "stick_3step.yaml", set=SHORT)
    by_extends = replay.run({"extends": "stick_3step"}, set=SHORT)
    whole = yaml.safe_load((scenario_dir() / "stick_3step.yaml").read_text())
    by_mapping = replay.run(whole, set=SHORT)
    for other in (by_path, by_extends, by_mapping):
        _same_tables(by_name, other)
        assert other.scenario == by_name.scenario
    # a mapping's relative extends resolves against the cwd (a user's own file)
    (tmp_path / "mine.yaml").write_text("extends: stick_3step\nname: mine\n")
    mine = replay.run({"extends": "mine.yaml", "timing": {"duration": 0.35}})
    assert mine.scenario["name"] == "mine"
    _same_tables(by_name, mine)


def test_a_mapping_runs_a_controller_from_a_file_in_the_cwd(tmp_path, monkeypatch):
    (tmp_path / "keeper_api.py").write_text((ROOT / "examples" / "my_controller.py").read_text())
    monkeypatch.chdir(tmp_path)
    controller = {"type": "keeper_api:GoalKeeper", "rate": 1000}
    run = replay.run(
        {"extends": "catch_optimised", "controller": controller}, set=["timing.duration=0.2"]
    )
    assert run.scenario["controller"]["type"] == "keeper_api:GoalKeeper"
    assert run.outcome is not None and "/effector/state" not in run.topics
    assert not [p for p in tmp_path.rglob("*") if ".mcap" in p.name]  # no log left


def test_set_as_a_list_or_a_mapping_overrides_alike():
    as_list = replay.run("stick_3step", set=[*SHORT, "plant.params.stick.friction=1.0", "seed=3"])
    as_dict = replay.run(
        "stick_3step",
        set={"timing.duration": 0.35, "plant.params.stick.friction": np.float64(1.0)},
        seed=np.int64(3),
    )
    assert as_list.scenario == as_dict.scenario
    assert as_dict.scenario["plant"]["params"]["stick"]["friction"] == 1.0
    assert as_dict.scenario["seed"] == 3
    _same_tables(as_list, as_dict)


def test_the_loader_takes_shipped_names_and_extends_in_a_text(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # an empty folder
    assert load_scenario("stick_3step").name == "stick_3step"
    assert load_scenario("stick_3step.yaml").name == "stick_3step"
    sc = scenario_from_text("extends: stick_3step\n")
    assert sc.name == "stick_3step" and sc.plant.params.stick.friction == 0.3
    assert sc.inputs == ((scenario_dir() / "stick_3step.yaml").resolve(),)
    # a relative name resolves against base_dir (else the cwd); the text's fields win
    base = tmp_path / "base"
    base.mkdir()
    (base / "slow.yaml").write_text("extends: stick_3step\ntiming: {duration: 0.5}\n")
    sc = scenario_from_text("extends: slow.yaml\nname: slower\n", base_dir=base)
    assert (sc.name, sc.timing.duration) == ("slower", 0.5)
    with pytest.raises(ScenarioError, match="no such scenario file 'slow.yaml'"):
        scenario_from_text("extends: slow.yaml\n")
    # reading a log's text (known-only) reads no other file: its extends is ignored
    (tmp_path / "other.yaml").write_text("extends: stick_3step\nname: other\n")
    text = (scenario_dir() / "stick_3step.yaml").read_text() + "extends: other.yaml\n"
    assert (tmp_path / "other.yaml").resolve() in scenario_from_text(text).inputs
    assert scenario_from_text(text, plugins="known-only").inputs == ()
    # a file parameter resolves from the file that set it (the catch's alpha_file)
    sc = scenario_from_text("extends: catch_optimised\n")
    assert Path(sc.controller.params.scenario_dir) == scenario_dir().resolve()


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: replay.run("no_such_scenario"), r"^no_such_scenario: no such scenario file"),
        (lambda: replay.run("stick_3step", set=["timing.bogus=1"]), r"timing\.bogus: unknown"),
        (lambda: replay.run("stick_3step", set={"timing.duration": "x"}), r"timing\.duration"),
        (lambda: replay.run({"extends": "stick_3step", "bogus": 1}), r"^<mapping>: bogus: unk"),
        (lambda: replay.run({"extends": "nope"}), r"^<mapping>: extends: no such scen"),
        (lambda: replay.run({"extends": "stick_3step", "seed": object()}), r"^<mapping>: seed"),
        (lambda: replay.run("stick_3step", seed=-1), r"seed from 0"),
        (lambda: replay.run("stick_3step", set={"seed=1": 2}), r"^set: expected a key path"),
    ],
)
def test_a_bad_scenario_is_one_scenario_error(call, match, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError, match=match) as info:
        call()
    assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_other_misuse_says_what_was_expected(tmp_path):
    with pytest.raises(TypeError, match="a shipped scenario's name, a file or a mapping"):
        replay.run(3)  # type: ignore[arg-type]
    with pytest.raises(LogError, match="no such log file"):
        replay.open_log(tmp_path / "none.mcap")
    with pytest.raises(LogError, match="not a file"):  # (there, but a folder or a device)
        replay.open_log(tmp_path)
    run = replay.open_log(ROOT / "data" / "golden" / "stick_3step.mcap")
    with pytest.raises(KeyError, match="no topic '/nope' in this run") as info:
        run.table("/nope")
    assert "/stick/state" in str(info.value)


def test_a_table_flattens_fills_and_types_its_columns(tmp_path):
    run = replay.open_log(ROOT / "data" / "golden" / "stick_3step.mcap")
    assert run.path == ROOT / "data" / "golden" / "stick_3step.mcap"
    ev = run.table("/events")
    n = len(run.events)
    assert all(len(c) == n for c in ev.values())
    assert ev["kind"].dtype == object and ev["kind"].tolist() == [e["kind"] for e in run.events]
    collisions = ev["kind"] == "collision"
    # nested data flattened with dots; a number a row lacks is NaN, anything else None
    idx = [e["data"].get("index", np.nan) for e in run.events]
    assert np.array_equal(ev["data.index"], np.array(idx, float), equal_nan=True)
    assert np.isnan(ev["data.index"][~collisions & (ev["kind"] == "outcome")]).all()
    assert "data.planned.r_x" in ev
    assert ev["data.reason"][ev["kind"] == "collision"].tolist() == [None] * collisions.sum()
    assert ev["t"].tolist() == [e["t"] for e in run.events]
    assert run.outcome == run.events[-1]["data"] == LogReader(run.path).outcome()["data"]


def test_df_columns_are_the_table_keys(tmp_path):
    run = replay.run("stick_3step", set=SHORT)
    for topic in ("/fingers/state", "/events"):
        table, df = run.table(topic), run.df(topic)
        assert list(df.columns) == list(table) and len(df) == len(table["t"])
    df = run.df("/fingers/state")
    assert np.array_equal(np.stack(df["tips"].to_list()), run.table("/fingers/state")["tips"])
    assert df["t"].to_numpy().tolist() == run.table("/fingers/state")["t"].tolist()


def test_df_without_pandas_names_the_extra(monkeypatch):
    run = replay.open_log(ROOT / "data" / "golden" / "stick_3step.mcap")
    monkeypatch.setitem(sys.modules, "pandas", None)  # (import pandas raises ImportError)
    with pytest.raises(ImportError, match=re.escape("pip install 'paper-replay[frames]'")):
        run.df("/stick/state")


def test_import_replay_stays_light():
    code = "import sys, replay; print(sorted(m for m in ('numpy', 'yaml', 'replay.api') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "[]", out.stderr
    code = "import replay; print(replay.run.__module__, replay.Run.__name__, replay.ScenarioError)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.startswith("replay.api Run <class 'replay.scenario.yamlio.ScenarioError'>")


def test_the_python_api_example_runs(tmp_path):
    r = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "04_python_api.py"), str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert "mu = 0.3: not captured" in r.stdout and "mu = 1.0: not captured" in r.stdout
    assert "largest spin difference: 0.00e+00 rad/s" in r.stdout  # friction independence
    assert "collision at 0.310 s" in r.stdout
    assert "same omega as the run in memory: True" in r.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["stick_3step.mcap"]


def test_the_readme_example_runs(tmp_path, monkeypatch):
    text = (ROOT / "README.md").read_text()
    section = text.split("## Python API", 1)[1].split("\n## ", 1)[0]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    replay.run("stick_3step", set=SHORT, log="out/logs/stick_3step.mcap")
    scope: dict = {}
    exec(compile(code, "README.md", "exec"), scope)
    assert scope["st"]["omega"].ndim == 1 and scope["tips"].ndim == 3
    assert list(scope["df"].columns)[:2] == ["t", "kind"]
