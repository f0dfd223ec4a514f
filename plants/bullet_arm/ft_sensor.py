"""The wrist's 6-axis force/torque sensor: PyBullet's joint force/torque sensor on the fixed
flange-palm joint (``palm_joint``, kept as a joint: the URDF is loaded without merging fixed
links).

``getJointState(...)[2]`` gives ``(Fx, Fy, Fz, Mx, My, Mz)`` in the joint frame (= the palm
frame = the tool frame). Measured (tests/plants/bullet_arm/test_grasp_plant.py, the hand hanging from the flange,
a known static load): it is the wrench the **parent (arm) exerts on the child (hand)**, the
moment taken about the **child link's centre of mass** (the palm's inertial origin), not about
the joint. Converted here to what a wrist sensor reports: the force and torque the hand side
exerts on the flange, moment about the joint origin,

    F = -F_pb,    M = -(M_pb + r_c x F_pb)      (r_c: the palm's centre of mass, palm frame),

so a hand of mass m hanging still reads F = m g (along gravity, in the palm frame) and
M = r x m g (r: the whole hand's centre of mass).
"""

from __future__ import annotations

import numpy as np


class WristFT:
    def __init__(self, bc, body: int, joint: int, palm_com) -> None:
        self.bc, self.body, self.joint = bc, body, joint
        self.r_c = np.asarray(palm_com, float)
        bc.enableJointForceTorqueSensor(body, joint, True)

        self._rc = self.r_c.tolist()

    def convert(self, raw) -> list[float]:
        """PyBullet's joint reaction (F, M) -> the hand's load on the flange about the joint:
        [Fx, Fy, Fz, Mx, My, Mz] in floats (cross3's products and sums, per component)."""
        fx, fy, fz, mx, my, mz = raw
        ax, ay, az = self._rc
        return [
            -fx,
            -fy,
            -fz,
            -(mx + (ay * fz - az * fy)),
            -(my + (az * fx - ax * fz)),
            -(mz + (ax * fy - ay * fx)),
        ]
