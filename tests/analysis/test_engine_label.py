"""A run that states a default is the shipped run: ``--set plant.params.engine.type=pybullet``
(the arm rig's own engine, which the shipped catch_optimised leaves empty) or an engine setting
at its default gets no label, so the claims count it as the paper's run; a changed engine or
engine setting is still a labelled variant, and each run still joins its engine's column."""

from __future__ import annotations

from pathlib import Path

import pytest

from analysis import runs
from analysis.engines import evaluate_runs, split_logs
from replay import registry
from replay.log import LogReader

from cli_checks import invoke

ENGINE = "plant.params.engine"


def run(out: Path, *sets: str) -> LogReader:
    args: list[object] = ["run", "catch_optimised", "-q", "-o", out]
    for s in sets:
        args += ["--set", s]
    r = invoke(*args)
    assert r.exit_code == 0, r.output
    return LogReader(out)


@pytest.fixture(scope="module")
def logs(tmp_path_factory) -> dict[str, LogReader]:
    d = tmp_path_factory.mktemp("engine_label")
    return {
        "shipped": run(d / "shipped.mcap"),
        "pybullet": run(d / "pybullet.mcap", f"{ENGINE}.type=pybullet"),
        "defaults": run(
            d / "defaults.mcap",
            f"{ENGINE}.type=pybullet",
            f"{ENGINE}.solver_iterations=50",
            f"{ENGINE}.object_restitution=0.6",
        ),
        "iterations": run(
            d / "iterations.mcap", f"{ENGINE}.type=pybullet", f"{ENGINE}.solver_iterations=20"
        ),
        "mujoco": run(d / "mujoco.mcap", f"{ENGINE}.type=mujoco"),
    }


def test_the_default_engine_stated_is_no_variant(logs):
    stated = logs["pybullet"].scenario_config()["plant"]["params"]["engine"]
    shipped = runs._shipped("catch_optimised")
    assert stated["type"] == "pybullet"  # stated in the log, where the shipped one names none:
    assert shipped is not None and not any(k.startswith(f"{ENGINE}.") for k in shipped)
    for which in ("shipped", "pybullet", "defaults"):
        run = runs.describe(logs[which])
        assert (run.label, run.experiment) == ("", "catch_optimised"), which


def test_the_default_engine_stated_gives_the_shipped_runs_claims(logs):
    evaluate = registry.load("claims", "namiki2003")
    rows = {}
    for which in ("shipped", "pybullet"):
        assert runs.variants_as_shipped({"catch_optimised": logs[which]}) == {}
        got, _ = evaluate_runs(evaluate, {"catch_optimised": logs[which]})
        rows[which] = {r.quantity: (r.kind, r.status) for r in got}
    assert any(kind == "measured" for kind, _ in rows["shipped"].values())  # counted rows
    assert rows["pybullet"] == rows["shipped"]


def test_an_engine_setting_changed_is_still_a_variant(logs):
    """Named by the setting (it was "engine pybullet", which the claims took for the same
    experiment in another engine and counted as the paper's run)."""
    assert runs.describe(logs["iterations"]).label == "solver iterations 20"
    one = {"catch_optimised": logs["iterations"]}
    assert runs.variants_as_shipped(one) == {"catch_optimised": "solver iterations 20"}
    assert list(split_logs(one)) == ["PyBullet"]
    evaluate = registry.load("claims", "namiki2003")
    shipped, _ = evaluate_runs(evaluate, {"catch_optimised": logs["shipped"]})
    variant = {r.quantity: r for r in evaluate_runs(evaluate, one)[0]}
    read = [
        r.quantity
        for r in shipped
        if r.kind == "measured" and any(m.startswith("catch_optimised:") for m in r.measures)
    ]
    assert read and all(variant[q].kind == "other regime" for q in read)
    assert all("solver iterations 20" in variant[q].note for q in read)


def test_each_run_joins_its_engines_column(logs):
    assert runs.describe(logs["mujoco"]).label == "engine mujoco"
    keys = runs.keyed([logs["pybullet"], logs["mujoco"]])
    assert list(keys) == ["catch_optimised", "catch_optimised (engine mujoco)"]
    split = split_logs(keys)
    assert list(split) == ["PyBullet", "MuJoCo"]
    assert split["PyBullet"] == {"catch_optimised": logs["pybullet"]}
    assert split["MuJoCo"] == {"catch_optimised": logs["mujoco"]}


def test_an_old_log_of_the_shipped_scenario_is_no_variant(tmp_path):
    """A log made before the engine field (plant ``bullet_arm``, PyBullet's settings flat at
    their defaults) reads as the engine named (``current_config``), yet is the shipped run."""
    import yaml

    from plants.bullet_arm.settings import PybulletSettings
    from replay.log import LogWriter
    from replay.messages import TOPIC_SCENARIO, ScenarioInfo
    from replay.scenario import load_scenario
    from replay.scenario.loader import to_plain

    data = to_plain(load_scenario("catch_optimised"))
    data["plant"]["type"] = "bullet_arm"
    flat = {k: v for k, v in to_plain(PybulletSettings()).items() if k != "type"}
    data["plant"]["params"].update(flat)
    with LogWriter(tmp_path / "old.mcap") as w:
        text = yaml.safe_dump(data, sort_keys=False)
        w.write(TOPIC_SCENARIO, ScenarioInfo(0.0, "catch_optimised", "namiki2003", text, 0, ""), 0)
    old = LogReader(tmp_path / "old.mcap")
    assert runs.current_config(old)["plant"]["params"]["engine"]["type"] == "pybullet"
    assert runs.describe(old).label == ""
