"""The grasping rig as the plant tests build it (shared by the plant, vision and loop tests)."""

from __future__ import annotations

import math

import numpy as np

from plants.arm_rig.grasp_rig import GraspRig
from plants.arm_rig.params import GraspParams
from replay.robot.arm_types import ServoCommand

DT = 1e-3
Q0 = [0.0, 0.533482, 0.0, 2.134676, 0.0, -1.0973, 0.0]  # scenarios/grasp_hexahedron.yaml


def rig(**kw) -> GraspRig:
    base = dict(
        arm="wam7",
        hand="grasp4",
        object="box",
        object_size=[0.05, 0.10, 0.05],
        object_mass=0.1,
        object_position=[0.75, 0.0, 0.55],
        initial_q=Q0,
        head_position=[0.0, 0.15, 0.70],
        human_speed=0.0,
        human_roll_rate=0.0,
        velocity_limits=[3.0] * 7,
    )
    base.update(kw)
    return GraspRig(GraspParams(**base), dt=DT, rng=np.random.default_rng(0))


def nudged_truth(plant, steps: int = 5) -> dict:
    """The rig's truth topics after ``steps`` steps of a small command to arm, hand and head."""
    cmd = ServoCommand(arm=[0.01] * 7, hand=[0.1] * 14, head=[0.1, 0.0])
    for _ in range(steps):
        plant.apply(cmd)
        plant.step()
    return plant.truth(steps * DT)


def rise_bandwidth(w: np.ndarray, target: float, dt: float) -> float:
    """1 / t63 (rad/s): the time to 63 % of the step, interpolated between samples (sample k
    at (k + 1) dt, the response starting from 0 at t = 0)."""
    level = (1.0 - math.exp(-1.0)) * target
    prev_t, prev_w = 0.0, 0.0
    for k, x in enumerate(w):
        t = (k + 1) * dt
        if x >= level:
            return 1.0 / (prev_t + (level - prev_w) / (x - prev_w) * (t - prev_t))
        prev_t, prev_w = t, x
    return 0.0
