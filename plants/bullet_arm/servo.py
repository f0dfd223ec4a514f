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

import math

import numpy as np
import pybullet as p


class VelocityServos:
    """A bank of PI velocity servos on joints ``joints`` of body ``body``. The state is kept
    per joint in plain floats (7 joints: lists beat arrays); the attributes ``command``,
    ``integral``, ``torque``, ``saturated`` give it as arrays."""

    def __init__(self, inertia, torque_limits, bandwidth: float, dt: float) -> None:
        self.limits = np.asarray(torque_limits, float).reshape(-1)
        self.K = np.asarray(inertia, float).reshape(-1) * float(bandwidth)
        if self.limits.shape != self.K.shape:
            raise ValueError("one torque limit and one inertia per servo joint")
        self.wi = float(bandwidth) / 4.0
        self.dt = dt
        n = len(self.K)
        self._lim, self._K = self.limits.tolist(), self.K.tolist()
        self.command_l = [0.0] * n
        self.integral_l = [0.0] * n
        self.torque_l = [0.0] * n
        self.saturated_l = [False] * n

    command = property(lambda self: np.array(self.command_l))
    integral = property(lambda self: np.array(self.integral_l))
    torque = property(lambda self: np.array(self.torque_l))
    saturated = property(lambda self: np.array(self.saturated_l, dtype=bool))

    def preload(self, torque) -> None:
        """Start with the integral that gives ``torque`` at zero velocity error (a servo that was
        holding its joint before the run began)."""
        tau = np.clip(np.asarray(torque, float), -self.limits, self.limits)
        self.integral_l = (tau / (self.K * self.wi)).tolist()
        self.torque_l = tau.tolist()

    def set_command(self, qd) -> None:
        v = np.asarray(qd, float).reshape(-1)
        if v.shape != (len(self._K),):
            raise ValueError(f"velocity command needs {len(self.K)} values, got {v.shape[0]}")
        self.command_l = [x if math.isfinite(x) else 0.0 for x in v.tolist()]  # non-finite: stop

    def torques(self, qd: list) -> list:
        """The motors' torques for joint velocities ``qd`` (before a physics step), per joint in
        floats: the same operations as the vector form (e = w_d - w; integral + e dt; K (e + w_i
        integral); clipped; the integral held at the limit)."""
        dt, wi = self.dt, self.wi
        integral, torque, sat = self.integral_l[:], [0.0] * len(qd), [False] * len(qd)
        for i, (c, w, K, lim) in enumerate(zip(self.command_l, qd, self._K, self._lim)):
            e = c - w
            acc = integral[i] + e * dt
            raw = K * (e + wi * acc)
            if abs(raw) > lim:
                sat[i] = True  # anti-windup: the integral stays
            else:
                integral[i] = acc
            torque[i] = min(max(raw, -lim), lim)
        self.integral_l, self.torque_l, self.saturated_l = integral, torque, sat
        return torque


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
