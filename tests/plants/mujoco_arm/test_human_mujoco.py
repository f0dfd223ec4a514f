"""The grasping rig's human hand (plants.arm_rig.human_path, engine-free) in both engines: a
free 100 g box held only by the spring-damper to its seeded path (seeds no scenario uses) follows
the path, in position and roll, the same way in MuJoCo (xfrc_applied) and PyBullet
(applyExternalForce), with the force within its limit."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest
from plants.bullet_arm.engine import pybullet as p

from plants.bullet_arm.human_hand import HumanHand
from plants.arm_rig.human_path import HumanPath
from plants.mujoco_arm.human import drive_human, object_pose_velocity
from replay.spatial import matrix_to_quaternion, rpy_to_matrix

DT = 1e-3
SIZE = (0.05, 0.10, 0.05)  # m: grasp_hexahedron's box
MASS, G = 0.10, 9.81
ORIGIN = (0.75, 0.0, 0.55)
N, U, V = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)  # the x = 0.75 m plane's axes
# turned about z and y at start: its body axes are not the plane's, so MuJoCo's body-frame
# angular velocity must be turned to world for the coupling's damping (object_pose_velocity)
RPY0 = (0.0, 0.3, 0.4)
Q0 = [float(x) for x in matrix_to_quaternion(rpy_to_matrix(RPY0))]  # [x, y, z, w]


def coupling(seed: int, speed: float) -> dict:
    return dict(
        origin=ORIGIN, rpy0=RPY0, u=U, v=V, n=N, speed=speed, roll_rate=0.2,
        f_min=0.1, f_max=1.0, components=6, max_force=30.0, start=0.0, mass=MASS, gravity=G,
        stiffness=500.0, damping=10.0, rot_stiffness=0.5, rot_damping=0.01, max_torque=1.0,
    )  # fmt: skip


def box_inertia() -> list[float]:
    x, y, z = SIZE
    return [MASS * (y * y + z * z) / 12, MASS * (x * x + z * z) / 12, MASS * (x * x + y * y) / 12]


def run_mujoco(seed: int, speed: float, steps: int) -> tuple[list, HumanPath]:
    spec = mujoco.MjSpec()
    spec.option.timestep = DT
    spec.option.gravity = [0.0, 0.0, -G]
    body = spec.worldbody.add_body(
        name="object", pos=list(ORIGIN), quat=[Q0[3], Q0[0], Q0[1], Q0[2]]
    )
    body.add_freejoint()
    body.add_geom(type=mujoco.mjtGeom.mjGEOM_BOX, size=[s / 2 for s in SIZE], mass=MASS, contype=0)
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    b = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, "object")
    human = HumanPath(np.random.default_rng(seed), **coupling(seed, speed))
    out = []
    for k in range(steps):
        drive_human(human, d, k * DT, 0, 0, b)
        mujoco.mj_step(m, d)
        out.append(object_pose_velocity(d, 0, 0, b))
    return out, human


def run_bullet(seed: int, speed: float, steps: int) -> list:
    bc = p.connect(p.DIRECT)
    try:
        p.setGravity(0, 0, -G, physicsClientId=bc)
        p.setTimeStep(DT, physicsClientId=bc)
        shape = p.createCollisionShape(
            p.GEOM_BOX, halfExtents=[s / 2 for s in SIZE], physicsClientId=bc
        )
        obj = p.createMultiBody(
            MASS,
            shape,
            basePosition=ORIGIN,
            baseOrientation=Q0,
            physicsClientId=bc,
        )
        p.changeDynamics(obj, -1, linearDamping=0.0, angularDamping=0.0, physicsClientId=bc)

        class Client:  # the bc argument HumanHand calls (its plant's BulletClient)
            def applyExternalForce(self, *a):
                p.applyExternalForce(*a, physicsClientId=bc)

            def applyExternalTorque(self, *a):
                p.applyExternalTorque(*a, physicsClientId=bc)

        human = HumanHand(Client(), obj, np.random.default_rng(seed), **coupling(seed, speed))
        out = []
        for k in range(steps):
            pos, orn = p.getBasePositionAndOrientation(obj, physicsClientId=bc)
            v, w = p.getBaseVelocity(obj, physicsClientId=bc)
            human.drive(k * DT, pos, orn, v, w)
            p.stepSimulation(physicsClientId=bc)
            pos, orn = p.getBasePositionAndOrientation(obj, physicsClientId=bc)
            out.append((list(pos), list(orn)))
        return out
    finally:
        p.disconnect(physicsClientId=bc)


def roll_about_n(orn) -> float:
    """The box's rotation about the plane normal (x) since start: R R0^T's angle about x."""
    R = np.asarray(p.getMatrixFromQuaternion(orn)).reshape(3, 3) @ rpy_to_matrix(RPY0).T
    return math.atan2(R[2, 1], R[1, 1])


@pytest.mark.parametrize("seed,speed", [(11, 0.05), (23, 0.15), (37, 0.3)])
def test_free_box_follows_the_human_path_in_both_engines(seed, speed):
    steps = 1500
    mj, human = run_mujoco(seed, speed, steps)
    pb = run_bullet(seed, speed, steps)
    worst_path, worst_roll, worst_engines, worst_turn = 0.0, 0.0, 0.0, 0.0
    for k in range(200, steps):  # after the first 0.2 s (the spring's transient)
        t = (k + 1) * DT
        du, dv, dr = human.offset(t)
        target = np.asarray(ORIGIN) + du * np.asarray(U) + dv * np.asarray(V)
        pos, orn = np.asarray(mj[k][0]), mj[k][1]
        worst_path = max(worst_path, float(np.linalg.norm(pos - target)))
        worst_roll = max(worst_roll, abs(roll_about_n(orn) - dr))
        worst_engines = max(worst_engines, float(np.linalg.norm(pos - np.asarray(pb[k][0]))))
        worst_turn = max(worst_turn, abs(roll_about_n(orn) - roll_about_n(pb[k][1])))
    # the spring-damper (500 N/m, 10 N s/m on 100 g, its weight carried) tracks within 0.4 mm
    # at 0.3 m/s, the roll spring within 0.3 mrad: bounds of 2 mm and 5 mrad
    assert worst_path < 2e-3, worst_path
    assert worst_roll < 5e-3, worst_roll
    # no contact: both engines integrate the same free body under the same wrench (they agree
    # to ~1e-18 m here); a wrong frame or quaternion order in either is off by far more
    assert worst_engines < 1e-6, worst_engines
    assert worst_turn < 1e-6, worst_turn
    assert math.hypot(*human.force_l) <= 30.0 + 1e-9
