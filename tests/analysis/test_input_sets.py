"""The held-out input sets of ``replay evaluate`` (analysis/input_sets.py): every episode a
different physical input, read from the run's own ground truth at t = 0, not from the set."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from analysis.input_sets import held_out
from replay import registry
from replay.api import run
from replay.log import LogReader

TRUTH_AT_START = {"catch": ("/object/state", "velocity"), "stick": ("/stick/state", None)}


def _first_truth(task: str, scenario: str, episode: dict, tmp_path) -> np.ndarray:
    topic, field = TRUTH_AT_START[task]
    sets = [*episode["set"], "timing.duration=0.002"]
    r = run(scenario, seed=episode["seed"], set=sets, log=tmp_path / "probe.mcap")
    first = LogReader(r.path).series(topic)[0]
    assert first["t"] == pytest.approx(0.0, abs=1e-9)
    values = first[field] if field else [first[k] for k in ("x", "y", "theta", "vx", "vy", "omega")]
    return np.asarray(values, float)


@pytest.mark.parametrize("task, scenario", [("catch", "catch_optimised"), ("stick", "stick_3step")])
def test_held_out_episodes_start_pairwise_different(task, scenario, tmp_path):
    episodes = held_out(task, 5)
    starts = [_first_truth(task, scenario, ep, tmp_path) for ep in episodes]
    for (i, a), (j, b) in itertools.combinations(enumerate(starts), 2):
        assert np.linalg.norm(a - b) > 0.01, (task, i, j, a, b)  # m/s (stick: mixed units)
    assert len({ep["input"] for ep in episodes}) == 5


def test_catch_held_out_throws_are_none_of_the_tuning_throws(tmp_path):
    from analysis.catching.throws import tuning_throws

    tuning = np.array([t["velocity"] for t in tuning_throws()])
    for ep in held_out("catch", 5):
        v = _first_truth("catch", "catch_optimised", ep, tmp_path)
        assert 8.0 <= np.linalg.norm(v) <= 10.5  # m/s at release (8-10 at first sight)
        assert np.min(np.linalg.norm(tuning - v, axis=1)) > 0.01


def test_grasp_held_out_paths_are_distinct_and_bounded():
    episodes = held_out("grasp", 23)
    pairs = {(ep["seed"], ep["set"][0]) for ep in episodes}
    assert len(pairs) == 23 and all(ep["seed"] != 0 for ep in episodes)  # the scenario's: 0
    with pytest.raises(ValueError, match="grasp has 23 human paths, asked for 24"):
        held_out("grasp", 24)


def test_the_set_is_installed_as_an_entry_point():
    assert registry.load("input_sets", "held-out") is held_out
