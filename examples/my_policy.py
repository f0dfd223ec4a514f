"""Simple non-paper policies for the papers' tasks, to set against the papers' methods:

    cd examples && replay evaluate my_policy:catch --task catch --n 10
    python examples/05_evaluate_a_policy.py

Each is a factory ``policy(env) -> act(observation, info) -> action`` (docs/envs.md); it knows
what a controller knows: the observation and the plant's nominal ``plant_spec``.
"""

from __future__ import annotations

import numpy as np


def catch(env):
    """Hold the arm at its start with a joint PD loop and close the hand when the stereo
    cameras see the ball within 0.2 m of the hand's x (no prediction, no planned motion)."""
    spec = env.unwrapped.plant_spec
    q0 = np.asarray(spec.initial_q, float)
    kp, kd = 400.0, 20.0  # N m/rad, N m s/rad (chosen, not tuned)
    hand_x = 0.72  # m: where the arm's hand is at the start, along the throw (catch_optimised)

    def act(obs, info):
        enc = obs["/arm/encoders"]
        n = q0.size
        q, qd = enc[1 : 1 + n], enc[1 + n : 1 + 2 * n]
        torque = kp * (q0 - q) - kd * qd
        ball = obs["/vision/object"]  # t, x, y, z; t = -1 before the ball is seen
        near = ball[0] >= 0 and ball[1] < hand_x + 0.2
        hand = spec.hand.closed_posture if near else spec.hand.open_posture
        return np.concatenate([torque, hand])

    return act


def stick(env):
    """Keep the hand's base under the stick as the camera last saw it, fingers at home."""
    hand = env.unwrapped.plant_spec.hand
    (x_lo, x_hi), _ = hand.base_limits
    joints = np.asarray(hand.start_joints, float).reshape(-1)

    def act(obs, info):
        seen = obs["/vision/stick"]  # t, x, y, theta
        x = float(np.clip(seen[1], x_lo, x_hi)) if seen[0] >= 0 else hand.start_base[0]
        return np.concatenate([[x, hand.start_base[1]], joints])

    return act


def grasp(env):
    """Stand still: every servo at zero velocity (the floor any grasping method must beat)."""
    still = np.zeros(env.action_space.shape)

    def act(obs, info):
        return still

    return act
