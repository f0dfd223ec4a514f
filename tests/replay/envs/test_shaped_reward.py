"""The optional shaped reward (replay/envs/rewards.py): each step minus the task's hand-object
distance (from the observation's own ground truth) times the step, on top of the sparse one;
the verdict and the log are those of the episode without it."""

from __future__ import annotations

import math

import numpy as np
import pytest


from replay.envs.env import ScenarioEnv  # noqa: E402
from replay.envs.policies import PaperPolicy  # noqa: E402
from replay.golden import compare_logs  # noqa: E402

EXACT = {"abs": 0, "rel": 0}
SHORT = {"catch_optimised": 0.35, "stick_3step": 0.5, "grasp_hexahedron": 0.05}


def _gap(task: str, obs: dict) -> float:
    """The distance the reward should hold, from the truth vectors (t first, then fields)."""
    if task == "stick_3step":
        x, y = obs["truth//stick/state"][1:3]
        ax, ay, bx, by = obs["truth//fingers/state"][1:5]
        return math.hypot(x - (ax + bx) / 2, y - (ay + by) / 2)
    return float(
        np.linalg.norm(obs["truth//object/state"][1:4] - obs["truth//effector/motion"][1:4])
    )


def _episode(env, seed: int):
    policy = PaperPolicy(env)
    obs, info = env.reset(seed=seed, options=policy.reset_options)
    rewards, gaps = [], []
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs, info))
        rewards.append(reward)
        gaps.append(_gap(env.scenario_name, obs) if env.truth else 0.0)
        if terminated or truncated:
            return rewards, gaps, info


@pytest.mark.parametrize("task", sorted(SHORT))
def test_shaped_reward_is_minus_the_gap_and_leaves_the_verdict(task, tmp_path):
    sets = {"timing.duration": SHORT[task]}
    plain = ScenarioEnv(task, set=sets, log=tmp_path / "plain.mcap")
    shaped = ScenarioEnv(task, set=sets, truth=True, shaped=True, log=tmp_path / "shaped.mcap")
    r0, _, info0 = _episode(plain, 2)
    r1, gaps, info1 = _episode(shaped, 2)
    assert info1["outcome"] == info0["outcome"]
    assert compare_logs(info0["result"].path, info1["result"].path, {}, EXACT) == []
    sparse = np.asarray(r0)
    assert set(sparse[:-1]) == {0.0}
    dense = np.asarray(r1) - sparse
    assert dense == pytest.approx(-shaped.dt * np.asarray(gaps), rel=1e-12, abs=1e-15)
    assert (dense < 0).all() and np.ptp(gaps) > 1e-4  # m: the gap changes as it runs
