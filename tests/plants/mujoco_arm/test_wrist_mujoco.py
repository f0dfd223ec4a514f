"""The wrist's 6-axis F/T sensor in MuJoCo (world.wrist_wrench: MuJoCo's force and torque sensors
on the palm) reads the same static loads as the PyBullet rig's (bullet_arm/ft_sensor.py), at the
same posture: a 5 N push on the palm added (the hand hanging still: test_cross_engine.py, every
engine)."""

from __future__ import annotations

import mujoco
import numpy as np
from grasp_rig import DT, Q0, rig
from plants.bullet_arm.engine import pybullet as p

from plants.mujoco_arm import Params
from plants.mujoco_arm.plant import MujocoArmPlant
from plants.mujoco_arm.world import WRIST_SITE, wrist_wrench
from replay.robot.arm_types import ServoCommand
from replay.robot.hand import GRASP4


def bullet_still():
    """The PyBullet rig settled still (its servos holding): posture, palm rotation, reading."""
    plant = rig()
    try:
        for _ in range(300):
            plant.apply(ServoCommand(arm=[0.0] * 7, hand=[0.0] * 14, head=[0.0, 0.0]))
            plant.step()
        q, hq = plant.arm_state()[0], plant.hand_state()[0]
        orn = plant.engine.bc.getLinkState(plant.engine.robot, plant.engine.tool_link)[5]
        R = np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)
        return q, hq, R, np.array(plant.engine.wrench)
    finally:
        plant.close()


def mujoco_static(q, hq, push=None):
    """MuJoCo's reading at posture (q, hq) held still (qvel = qacc = 0: mj_inverse), with an
    optional world force on the palm's centre of mass; and the palm's rotation."""
    plant = MujocoArmPlant(
        Params(arm="wam7", hand="grasp4", object="none", initial_q=Q0), dt=DT,
        rng=np.random.default_rng(0),
    )  # fmt: skip
    m, d, W = plant.engine.mj, plant.engine.md, plant.engine.world
    d.qpos[list(W.arm_qpos)] = q
    d.qpos[list(W.hand_qpos)] = hq
    d.qvel[:] = 0.0
    d.qacc[:] = 0.0
    if push is not None:
        palm = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "palm")
        mujoco.mj_kinematics(m, d)
        d.xfrc_applied[palm, :3] = push  # at the body's centre of mass (MuJoCo's convention)
    mujoco.mj_inverse(m, d)
    R = d.site_xmat[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, WRIST_SITE)].reshape(3, 3)
    return R.copy(), np.array(wrist_wrench(W, d))


def test_wrist_reads_an_added_push_as_pybullet_does():
    """5 N along world +y on the palm's centre (0.0075 m ahead of the joint): the reading grows
    by the force and r x F; the PyBullet rig's test measures the same (within 0.05 N, 0.01 N m)."""
    q, hq, _, _ = bullet_still()
    R, base = mujoco_static(q, hq)
    F = np.array([0.0, 5.0, 0.0])
    _, pushed = mujoco_static(q, hq, push=F)
    extra = pushed - base
    np.testing.assert_allclose(R @ extra[:3], F, atol=1e-6)
    r = R @ np.array([0.0, 0.0, GRASP4.palm_size[2] / 2.0])
    np.testing.assert_allclose(R @ extra[3:], np.cross(r, F), atol=1e-6)
