"""The grasping arm's velocity servos (issue #20): every joint, stepped on the rig with the
others commanded still, reaches its command with the scenario's stated bandwidth (+-20 %) and
leaves the others (nearly) where they were: the loops are inertia-decoupled."""

from __future__ import annotations


import numpy as np
import pytest

from replay.robot.arm_types import ServoCommand
from grasp_rig import rig, rise_bandwidth

STEP = 0.05  # rad/s: small enough that no joint reaches its torque limit (a linear step)


def _step_response(plant, j: int, steps: int = 100) -> np.ndarray:
    zero = [0.0] * 7
    for _ in range(50):  # settle the preloaded integrals
        plant.apply(ServoCommand(arm=zero))
        plant.step()
    w0 = np.array(plant.arm_state()[1])
    cmd = np.zeros(7)
    cmd[j] = STEP
    out = []
    for _ in range(steps):
        plant.apply(ServoCommand(arm=cmd))
        plant.step()
        assert not any(plant.arm_servos.saturated_l)
        out.append(np.array(plant.arm_state()[1]) - w0)
    return np.array(out)


@pytest.mark.parametrize("joint", range(7))
def test_each_arm_joint_has_the_stated_bandwidth(joint):
    plant = rig()
    try:
        bw = plant.params.arm_servo_bandwidth
        w = _step_response(plant, joint)
        got = rise_bandwidth(w[:, joint], STEP, plant.dt)
        print(
            f"J{joint + 1}: {got:.0f} rad/s (stated {bw:.0f}), peak {w[:, joint].max() / STEP:.3f}"
        )
        assert got == pytest.approx(bw, rel=0.2)
        assert w[-10:, joint] == pytest.approx(STEP, rel=0.02)  # settled on the command
        others = np.delete(w, joint, axis=1)
        assert np.abs(others).max() < 0.1 * STEP  # decoupled
    finally:
        plant.close()


def test_rise_bandwidth_of_a_sampled_first_order_step():
    dt, bw = 1e-3, 200.0
    t = np.arange(1, 40) * dt
    assert rise_bandwidth(1.0 - np.exp(-bw * t), 1.0, dt) == pytest.approx(bw, rel=0.02)
