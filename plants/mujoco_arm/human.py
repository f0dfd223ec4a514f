"""The grasping rig's human hand in MuJoCo: the engine-free path and spring-damper coupling
(``plants.arm_rig.human_path.HumanPath``, the PyBullet rig's) applied to the object's free body
through ``xfrc_applied`` (a world-frame force at the body's centre of mass and a world torque:
PyBullet's ``applyExternalForce`` at the base's position with ``WORLD_FRAME``).
"""

from __future__ import annotations

import mujoco
import numpy as np

from plants.arm_rig.human_path import HumanPath


def object_pose_velocity(data: mujoco.MjData, qpos: int, dof: int, body: int) -> tuple:
    """(pos, orn [x, y, z, w], v, w) of a free body in world coordinates, as PyBullet's
    getBasePositionAndOrientation / getBaseVelocity give them (qvel's angular part is in the
    body frame: turned to world with xmat)."""
    q = data.qpos
    pos = [float(q[qpos]), float(q[qpos + 1]), float(q[qpos + 2])]
    orn = [float(q[qpos + 4]), float(q[qpos + 5]), float(q[qpos + 6]), float(q[qpos + 3])]
    v = [float(x) for x in data.qvel[dof : dof + 3]]
    R = np.asarray(data.xmat[body]).reshape(3, 3)
    w = (R @ np.asarray(data.qvel[dof + 3 : dof + 6])).tolist()
    return pos, orn, v, w


def drive_human(human: HumanPath, data: mujoco.MjData, t: float, qpos: int, dof: int, body: int):
    """The coupling's wrench at ``t`` from the object's state now, set for the next step."""
    human.drive(t, *object_pose_velocity(data, qpos, dof, body))
    data.xfrc_applied[body, :3] = human.force_l
    data.xfrc_applied[body, 3:] = human.torque_l
