"""Velocity-command servos (the arm's AC servos, the hand's DC servos) on PyBullet joints.

A servo amplifier takes a joint velocity command and closes its own velocity loop, whose torque
the motor limits. Modelled per joint as a PI velocity loop run at the physics rate,

    e = w_d - w,   tau = clip(K (e + w_i * integral(e)), -tau_max, tau_max),

with ``K = I_j * bandwidth`` (``I_j``: the joint's effective inertia with the other joints free,
``1 / (M^-1)_jj`` at the initial posture, divided by the coupling of all joints' loops, see the
plant: each amplifier tuned to its axis), ``w_i = bandwidth / 4`` (the integral removes
the droop under gravity and under a steady load) and the integral held while the torque is at its
limit (anti-windup). The torque is applied as a joint torque (``TORQUE_CONTROL``), so the arm's
dynamics, gravity and contacts act on it and a saturated joint lags its command. With
``bandwidth * dt <= 1`` the explicit loop is stable (the inertia-scaled gain makes it so for every
joint). The torque given is what a strain gauge on the drive reads.
"""

from __future__ import annotations

import numpy as np
import pybullet as p


class VelocityServos:
    """A bank of PI velocity servos on joints ``joints`` of body ``body``."""

    def __init__(self, inertia, torque_limits, bandwidth: float, dt: float) -> None:
        self.limits = np.asarray(torque_limits, float).reshape(-1)
        self.K = np.asarray(inertia, float).reshape(-1) * float(bandwidth)
        if self.limits.shape != self.K.shape:
            raise ValueError("one torque limit and one inertia per servo joint")
        self.wi = float(bandwidth) / 4.0
        self.dt = dt
        self.command = np.zeros(len(self.K))
        self.integral = np.zeros(len(self.K))
        self.torque = np.zeros(len(self.K))
        self.saturated = np.zeros(len(self.K), dtype=bool)

    def preload(self, torque) -> None:
        """Start with the integral that gives ``torque`` at zero velocity error (a servo that was
        holding its joint before the run began)."""
        tau = np.clip(np.asarray(torque, float), -self.limits, self.limits)
        self.integral = tau / (self.K * self.wi)
        self.torque = tau

    def set_command(self, qd) -> None:
        v = np.asarray(qd, float).reshape(-1)
        if v.shape != self.command.shape:
            raise ValueError(f"velocity command needs {len(self.K)} values, got {v.shape[0]}")
        self.command = np.where(np.isfinite(v), v, 0.0)  # a non-finite command: stop

    def torques(self, qd: np.ndarray) -> np.ndarray:
        """The motors' torques for joint velocities ``qd`` (before a physics step)."""
        e = self.command - qd
        integral = self.integral + e * self.dt
        raw = self.K * (e + self.wi * integral)
        lim = self.limits
        sat = np.abs(raw) > lim
        self.integral = np.where(sat, self.integral, integral)  # anti-windup
        self.torque = np.clip(raw, -lim, lim)
        self.saturated = sat
        return self.torque


def apply_torques(bc, body: int, joints: list, torques: np.ndarray) -> None:
    bc.setJointMotorControlArray(body, joints, p.TORQUE_CONTROL, forces=torques.tolist())


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
        self.command = np.zeros(len(self.joints))
        self.torque = np.zeros(len(self.joints))

    def set_command(self, qd) -> None:
        v = np.asarray(qd, float).reshape(-1)
        if v.shape != self.command.shape:
            raise ValueError(f"velocity command needs {len(self.joints)} values, got {v.shape[0]}")
        self.command = np.where(np.isfinite(v), v, 0.0)

    def actuate(self) -> None:
        self.bc.setJointMotorControlArray(
            self.body,
            self.joints,
            p.VELOCITY_CONTROL,
            targetVelocities=self.command.tolist(),
            forces=self._forces,
        )

    def read(self, states) -> None:
        """The motors' torques from this step's joint states (index 3)."""
        self.torque = np.array([s[3] for s in states])
