"""The feedback-only baseline (replay/control/feedback) on throws it was not tuned to: seeded
random throws around the paper's 8-10 m/s are not caught; slow ones are (the row can fail)."""

from __future__ import annotations

import numpy as np
import pytest

from replay.resources import find_scenario
from replay.runner import Runner
from replay.scenario import load_scenario

NOMINAL = np.array([-8.87717, 0.0, -0.50082])  # catch_optimised's release velocity (m/s)


def _outcome(tmp_path, v, sets=()):
    sc = load_scenario(
        find_scenario("catch_feedback"),
        sets=[f"plant.params.object_velocity=[{v[0]:.5f}, {v[1]:.5f}, {v[2]:.5f}]", *sets],
    )
    return Runner(sc).run(tmp_path / "fb.mcap").outcome


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_feedback_alone_does_not_catch_a_fast_throw(tmp_path, seed):
    rng = np.random.default_rng(seed)
    speed = rng.uniform(8.0, 10.0)
    d = NOMINAL / np.linalg.norm(NOMINAL)
    d = d + rng.normal(0.0, 0.005, 3) * np.array([1.0, 0.0, 1.0])  # ±0.3° in the throw plane
    out = _outcome(tmp_path, speed * d / np.linalg.norm(d))
    assert not out["success"], out


@pytest.mark.parametrize("seed", [1, 2])
def test_feedback_alone_catches_a_slow_ball(tmp_path, seed):
    """A ball at 2.4-3.0 m/s along the same line (no gravity, so it stays on it) is caught."""
    speed = np.random.default_rng(seed).uniform(2.4, 3.0)
    v = speed * NOMINAL / np.linalg.norm(NOMINAL)
    out = _outcome(tmp_path, v, ["plant.params.object_gravity=false", "timing.duration=2.0"])
    assert out["success"], out
