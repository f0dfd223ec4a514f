"""The hand's velocity servos (its DC servos) on PyBullet joints: PyBullet's velocity motors."""

from __future__ import annotations

import math

import numpy as np

from plants.bullet_arm.engine import pybullet as p


class VelocityMotors:
    """Stiff geared velocity servos: PyBullet's velocity motor (solved implicitly with the
    contacts) drives each joint at its commanded rate with at most its torque limit. A finger's
    geared DC motor reflects an inertia far above the light finger link's, so a velocity loop
    on the link's own inertia would let the fingers flop under the arm's accelerations; the
    implicit motor is that stiff drive. The torque it gave (``appliedJointMotorTorque``) is what
    the joint's strain gauge reads."""

    def __init__(self, bc, body: int, joints, torque_limits) -> None:
        self.bc, self.body, self.joints = bc, body, list(joints)
        self.limits = np.asarray(torque_limits, float).reshape(-1)
        self._forces = [float(x) for x in self.limits]
        self.command = [0.0] * len(self.joints)
        self.torque = [0.0] * len(self.joints)  # N m per joint, floats

    def set_command(self, qd) -> None:
        v = np.asarray(qd, float).reshape(-1)
        if v.shape != (len(self.joints),):
            raise ValueError(f"velocity command needs {len(self.joints)} values, got {v.shape[0]}")
        self.command = [x if math.isfinite(x) else 0.0 for x in v.tolist()]

    def actuate(self) -> None:
        self.bc.setJointMotorControlArray(
            self.body,
            self.joints,
            p.VELOCITY_CONTROL,
            targetVelocities=self.command,
            forces=self._forces,
        )

    def read(self, torques) -> None:
        """The motors' torques of this step (the joint states' appliedJointMotorTorque)."""
        self.torque = list(torques)
