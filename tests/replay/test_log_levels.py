"""What a run's log holds is a choice (issue #41): ``log.level`` full (the default: the log
contract, the goldens' resolved scenario unchanged), decimated (state and images at stated
rates) or outcome (the scenario and the events); a lower level leaves messages out, never
changes the run."""

from __future__ import annotations

import math

import pytest
import yaml
from click.testing import CliRunner

from conftest import ROOT
from replay.cli import main
from replay.log import LogReader
from replay.runner import Runner
from replay.scenario import load_scenario, resolved_yaml

CATCH = ROOT / "scenarios" / "catch_optimised.yaml"
SHORT = ["timing.duration=0.3"]
IMAGES = "/camera/stereo/cam0"  # (a Foxglove image topic of the catch's stereo camera)
STATE = "/arm/joint_state"  # (a plant state topic)
MEASURED = "/arm/encoders"  # (a sensor's measurement topic)


def _run(tmp_path, level_sets: list[str], name: str):
    sc = load_scenario(CATCH, sets=SHORT + level_sets)
    result = Runner(sc).run(tmp_path / f"{name}.mcap")
    return result, LogReader(result.path)


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    return _run(tmp_path_factory.mktemp("full"), [], "full")


def test_the_default_level_leaves_the_resolved_scenario_as_it_was():
    data = yaml.safe_load(resolved_yaml(load_scenario(CATCH)))
    assert "log" not in data  # (so every golden's /scenario is unchanged)
    said = yaml.safe_load(resolved_yaml(load_scenario(CATCH, sets=["log.level=decimated"])))
    assert said["log"] == {"level": "decimated", "state_rate": 100.0, "image_rate": 10.0}


def test_decimated_keeps_state_and_images_at_their_rates(full, tmp_path):
    full_result, full_log = full
    sets = ["log.level=decimated", "log.state_rate=50", "log.image_rate=20"]
    result, log = _run(tmp_path, sets, "decimated")
    counts, full_counts = log.topic_counts(), full_log.topic_counts()
    t = result.t_end
    assert counts[STATE] == pytest.approx(t * 50 + 1, abs=2)  # (and the final state)
    assert counts[IMAGES] == pytest.approx(t * 20, abs=2)
    assert full_counts[IMAGES] > 3 * counts[IMAGES] and full_counts[STATE] > 3 * counts[STATE]
    assert counts[MEASURED] == full_counts[MEASURED]  # (the rest in full)
    assert result.outcome == full_result.outcome and log.events() == full_log.events()
    full_states = {s["t"]: s for s in full_log.series(STATE)}
    assert all(full_states[s["t"]] == s for s in log.series(STATE))  # left out, never changed


def test_outcome_keeps_the_scenario_and_the_events(full, tmp_path):
    full_result, full_log = full
    result, log = _run(tmp_path, ["log.level=outcome"], "outcome")
    assert set(log.topic_counts()) == {"/scenario", "/events"}
    assert result.outcome == full_result.outcome and log.events() == full_log.events()
    assert log.outcome()["data"] == full_log.outcome()["data"]
    assert log.metadata()["provenance"] == full_log.metadata()["provenance"]
    assert log.size < full_log.size / 20


def test_a_non_finite_value_not_logged_still_ends_the_run(toy_yaml, tmp_path):
    def run(sets):
        sc = load_scenario(toy_yaml, sets=["plant.params.blow_up_at=0.2", *sets])
        return Runner(sc).run(tmp_path / f"{len(sets)}.mcap")

    full, outcome = run([]), run(["log.level=outcome"])
    assert outcome.stopped_by == full.stopped_by == "error"
    assert outcome.outcome == full.outcome and math.isclose(outcome.t_end, full.t_end)


def test_the_command_line_sets_the_level(toy_yaml, tmp_path):
    out = tmp_path / "toy.mcap"
    r = CliRunner().invoke(
        main, ["run", str(toy_yaml), "-o", str(out), "-q", "--log-level", "outcome"]
    )
    assert r.exit_code == 0, r.output
    assert set(LogReader(out).topic_counts()) == {"/scenario", "/events"}


@pytest.mark.parametrize(
    "args,words",
    [
        (["--set", "log.level=some"], "log.level: expected one of full, decimated, outcome"),
        (["--set", "log.state_rate=0"], "log.state_rate: expected a number > 0"),
        (["--set", "log.rate=3"], "unknown field 'rate'"),
        (["--log-level", "all"], "'all' is not one of"),
    ],
)
def test_a_bad_level_is_one_line(toy_yaml, tmp_path, args, words):
    r = CliRunner().invoke(main, ["run", str(toy_yaml), "-o", str(tmp_path / "x.mcap"), *args])
    assert r.exit_code == 2 and words in r.output
    assert len([line for line in r.output.splitlines() if line.startswith("error")]) <= 1
    assert "Traceback" not in r.output and not (tmp_path / "x.mcap").exists()


def test_a_sweep_logs_at_its_level(toy_yaml, tmp_path):
    out = tmp_path / "sweep"
    args = ["sweep", str(toy_yaml), "--grid", "seed=1,2", "-o", str(out), "--workers", "1"]
    r = CliRunner().invoke(main, [*args, "--log-level", "outcome", "-q"])
    assert r.exit_code == 0, r.output
    logs = sorted((out / "logs").glob("*.mcap"))
    assert len(logs) == 2
    assert all(set(LogReader(p).topic_counts()) == {"/scenario", "/events"} for p in logs)
