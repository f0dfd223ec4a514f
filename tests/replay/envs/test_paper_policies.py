"""The papers' methods as policies (replay/envs/policies.py): run through the environment on
several seeds, the same outcome and the same log as ``replay run`` (zero tolerance)."""

from __future__ import annotations

import pytest

import gymnasium  # noqa: E402

import replay.envs  # noqa: E402 - registers the environments
from replay.envs.policies import PaperPolicy  # noqa: E402
from replay.golden import compare_logs  # noqa: E402
from replay.runner import Runner  # noqa: E402
from replay.scenario import load_scenario  # noqa: E402

EXACT = {"abs": 0, "rel": 0}
# s: timing.duration of the runs here (catch: past the catch at ~0.28 s and its 0.1 s hold)
SHORT = {"stick": 0.5, "catch": 0.4, "grasp": 0.15}


@pytest.mark.parametrize("task", sorted(replay.envs.TASKS))
@pytest.mark.parametrize("seed", [1, 7])
def test_paper_policy_through_the_env_equals_replay_run(task, seed, tmp_path):
    env_id, name = replay.envs.TASKS[task]
    duration = SHORT[task]
    env = gymnasium.make(env_id, set={"timing.duration": duration}, log=tmp_path / "env.mcap")
    policy = PaperPolicy(env)
    obs, info = env.reset(seed=seed, options=policy.reset_options)
    steps = 0
    while True:
        obs, reward, terminated, truncated, info = env.step(policy(obs, info))
        steps += 1
        if terminated or truncated:
            break
    run = Runner(load_scenario(name, [f"timing.duration={duration}"], seed)).run(
        tmp_path / "run.mcap"
    )
    assert info["outcome"] == run.outcome
    assert reward == (1.0 if run.outcome["success"] else 0.0)
    assert terminated == (run.stopped_by != "duration")
    assert steps * env.unwrapped.dt == pytest.approx(run.t_end, abs=1e-9)
    assert compare_logs(run.path, info["result"].path, {}, EXACT) == []
