"""The papers' tasks as Gymnasium environments (replay/envs): check_env, the spaces, and the
paper's method run as a policy through the environment against ``replay run``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import gymnasium  # noqa: E402
from gymnasium.utils.env_checker import check_env  # noqa: E402

import replay.envs  # noqa: E402 - registers the environments
from replay.envs.env import ScenarioEnv  # noqa: E402
from replay.runner import Runner  # noqa: E402
from replay.scenario import load_scenario  # noqa: E402


@pytest.mark.parametrize("task", sorted(replay.envs.TASKS))
def test_check_env_passes(task):
    env_id, _ = replay.envs.TASKS[task]
    env = gymnasium.make(env_id, set={"timing.duration": 0.02})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (its advice on normalised Box bounds)
        check_env(env.unwrapped)
    env.close()


def test_generic_id_takes_any_scenario():
    env = gymnasium.make(replay.envs.GENERIC, scenario="stick_2step", set={"timing.duration": 0.02})
    assert env.unwrapped.scenario_name == "stick_2step"
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs)


def test_spaces_are_the_measurements_and_the_plants_limits():
    env = ScenarioEnv("catch_optimised", set={"timing.duration": 0.02})
    spec_runner = Runner(load_scenario("catch_optimised"))
    spec = spec_runner.plant.spec()
    spec_runner.plant.close()
    # actions: torque of the 4 arm joints within +-their limits, then the 3 hand joints' range
    assert np.array_equal(env.action_space.high[:4], spec.torque_limits)
    assert np.array_equal(env.action_space.low[4:], spec.hand.lower)
    # observations: the two sensors the controller reads, time first in each
    assert set(env.observation_space) == {"time", "/arm/encoders", "/vision/object"}
    assert env.observation_space["/vision/object"].shape == (4,)  # t, x, y, z
    obs, info = env.reset(seed=0)
    assert obs["/vision/object"][0] == -1.0  # nothing delivered at t = 0: the ball not yet seen
    assert obs["/arm/encoders"][0] == 0.0  # encoders: no latency
    assert "truth//object/state" not in obs


def test_latency_is_kept():
    """The stick camera (300 fps, one frame of latency) reaches the observation 1/300 s late,
    at the 1 kHz controller's next step (within 1 ms more)."""
    env = ScenarioEnv("stick_3step", set={"timing.duration": 0.05})
    obs, info = env.reset(seed=0)
    hold = env.layout.action_of(None, None)  # all NaN: keep the hand where it is
    seen = []
    while True:
        obs, reward, term, trunc, info = env.step(hold)
        if term or trunc:
            break
        if info["measurements"]:
            seen.append((info["t"], obs["/vision/stick"][0]))
    assert seen, "the camera delivered nothing"
    for t, captured in seen:
        assert 1 / 300 - 1e-9 <= t - captured < 1 / 300 + 1e-3


def test_truth_only_on_request():
    env = ScenarioEnv("stick_3step", set={"timing.duration": 0.02}, truth=True)
    obs, _ = env.reset(seed=0)
    assert obs["truth//stick/state"][2] == pytest.approx(0.461)  # t, x, y: the scenario's y


def test_a_policy_outside_changes_the_run():
    """The action reaches the plant: zero torque lets the catching arm fall (no catch)."""
    env = ScenarioEnv("catch_optimised", set={"timing.duration": 0.4})
    env.reset(seed=1)
    zero = np.zeros(env.action_space.shape)
    while True:
        _, reward, terminated, truncated, info = env.step(zero)
        if terminated or truncated:
            break
    assert info["outcome"]["success"] is False
    assert reward == 0.0


def test_an_episode_left_unfinished_keeps_its_log_as_interrupted(tmp_path):
    env = ScenarioEnv("stick_3step", set={"timing.duration": 0.05}, log=tmp_path / "ep{seed}.mcap")
    env.reset(seed=1)
    env.step(env.layout.action_of(None))
    env.reset(seed=2)  # episode 1 abandoned
    while not any(env.step(env.layout.action_of(None))[2:4]):
        pass
    env.close()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ep1.interrupted.mcap", "ep2.mcap"]


def test_async_vector_env_over_processes():
    """Gymnasium's async vector env runs the environment in worker processes: two seeds at
    once, each ending at the duration with its own verdict."""
    envs = gymnasium.make_vec(
        "paper_replay/StickCapture-v0",
        num_envs=2,
        vectorization_mode="async",
        set={"timing.duration": 0.02},
    )
    try:
        obs, _ = envs.reset(seed=[1, 2])
        assert obs["/vision/stick"].shape == (2, 4)
        hold = np.stack([envs.single_action_space.low] * 2)
        for _ in range(20):  # 0.02 s of 1 ms steps
            obs, reward, terminated, truncated, info = envs.step(hold)
        assert truncated.all() and not terminated.any()
        assert info["_outcome"].all() and (info["outcome"]["success"] == (reward == 1.0)).all()
    finally:
        envs.close()
