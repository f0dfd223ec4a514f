"""The grasping arm's velocity servos (plants/arm_rig/servo.py ``VelocityServos``: engine-free
maths, inertia-decoupled by the arm's mass matrix) on the MuJoCo arm with the 14-joint hand: the
PyBullet rig's step test (tests/plants/bullet_arm/test_grasp_servos.py) passes in MuJoCo too:
every joint reaches its command with the stated bandwidth (+-20 %), settles on it and leaves the
others (nearly) still."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest
from grasp_rig import DT, Q0, rise_bandwidth

from plants.arm_rig.servo import VelocityServos
from plants.mujoco_arm import Params
from plants.mujoco_arm.plant import MujocoArmPlant
from replay.robot.arm_types import ArmCommand

STEP = 0.05  # rad/s, as the PyBullet test: no joint reaches its torque limit
BANDWIDTH = 500.0  # rad/s: scenarios/grasp_hexahedron.yaml's arm_servo_bandwidth


def arm_mass_matrix(plant: MujocoArmPlant) -> np.ndarray:
    """The arm joints' block of MuJoCo's joint-space mass matrix now (hand joints held by their
    servos, as the PyBullet rig's)."""
    M = np.zeros((plant.engine.mj.nv, plant.engine.mj.nv))
    mujoco.mj_fullM(plant.engine.mj, plant.engine.md, M)  # MuJoCo 4: (model, data, out)
    dofs = plant.engine.world.arm_dof
    return M[np.ix_(dofs, dofs)]


def step_response(j: int, steps: int = 100) -> np.ndarray:
    plant = MujocoArmPlant(
        Params(
            arm="wam7", hand="grasp4", object="none", initial_q=Q0,
            torque_limit_set="public_urdf", velocity_limits=[3.0] * 7,
        ),
        dt=DT, rng=np.random.default_rng(0),
    )  # fmt: skip
    servos = VelocityServos(plant.torque_limits, BANDWIDTH, DT)
    # held still before t = 0: the integrals carry the static (gravity) torques
    servos.preload(
        plant.engine.md.qfrc_bias[list(plant.engine.world.arm_dof)].tolist(), arm_mass_matrix(plant)
    )

    def run(cmd) -> None:
        servos.set_command(cmd)
        tau = servos.torques(plant.arm_state()[1].tolist(), arm_mass_matrix(plant))
        plant.apply(ArmCommand(torque=tau))
        plant.step()

    zero = [0.0] * 7
    for _ in range(50):
        run(zero)
    w0 = plant.arm_state()[1]
    cmd = [0.0] * 7
    cmd[j] = STEP
    out = []
    for _ in range(steps):
        run(cmd)
        assert not any(servos.saturated_l)
        out.append(plant.arm_state()[1] - w0)
    return np.array(out)


@pytest.mark.parametrize("joint", range(7))
def test_each_arm_joint_has_the_stated_bandwidth_in_mujoco(joint):
    w = step_response(joint)
    got = rise_bandwidth(w[:, joint], STEP, DT)
    print(f"J{joint + 1}: {got:.0f} rad/s (stated {BANDWIDTH:.0f})")
    assert got == pytest.approx(BANDWIDTH, rel=0.2)
    assert w[-10:, joint] == pytest.approx(STEP, rel=0.02)
    others = np.delete(w, joint, axis=1)
    assert np.abs(others).max() < 0.1 * STEP
