"""The arm's velocity-command servos (its AC servos), engine-free: a plant applies their torques.

A servo amplifier takes a joint velocity command and closes its own velocity loop, whose torque
the motor limits. The arm's loops are **inertia-decoupled** (a computed-torque velocity loop:
each amplifier's gain is scaled by the arm's mass matrix at the current posture, so every joint
sees the same closed-loop bandwidth whatever the others' inertia), run at the physics rate:

    e = w_d - w,   a = k (e + w_i * integral(e)),   tau = clip(M(q) a, -tau_max, tau_max),

with ``M(q)`` the arm joints' block of the joint-space mass matrix (hand joints held by their
stiff drives), ``k = (1 - exp(-bandwidth dt)) / dt`` (the explicit 1 kHz loop's velocity error
then decays as ``exp(-bandwidth t)``: the stated bandwidth, not its forward-Euler
approximation), ``w_i = bandwidth / 10`` (the integral removes the droop under gravity and a
steady load without changing the step response much: <10 % overshoot) and each joint's integral
held while a torque is at its limit (anti-windup; past a limit the proportional torques are
scaled down together, see :meth:`VelocityServos.torques`). The torque is applied as a joint torque
(PyBullet's ``TORQUE_CONTROL``, MuJoCo's ``qfrc_applied``), so the arm's dynamics, gravity and
contacts act on it and a saturated joint lags its command. The torque given is what a strain
gauge on the drive reads.

(Issue #20: the former per-joint gains from ``1 / (M^-1)_jj`` divided by a coupling factor left
J1 at ~45 rad/s and J3 at ~33 rad/s against the stated 500; tests/plants/bullet_arm/
test_grasp_servos.py steps every joint.)
"""

from __future__ import annotations

import math

import numpy as np

INTEGRAL_RATIO = 10.0  # bandwidth / w_i


class VelocityServos:
    """A bank of inertia-decoupled PI velocity servos. The state is kept per joint in plain
    floats; the attributes ``command``, ``integral``, ``torque``, ``saturated`` give it as
    arrays."""

    def __init__(self, torque_limits, bandwidth: float, dt: float) -> None:
        self.limits = np.asarray(torque_limits, float).reshape(-1)
        self.bandwidth = float(bandwidth)
        self.k = (1.0 - math.exp(-self.bandwidth * dt)) / dt
        self.wi = self.bandwidth / INTEGRAL_RATIO
        self.dt = dt
        n = self.n = len(self.limits)
        self._lim = self.limits.tolist()
        self.command_l = [0.0] * n
        self.integral_l = [0.0] * n
        self.torque_l = [0.0] * n
        self.saturated_l = [False] * n

    command = property(lambda self: np.array(self.command_l))
    integral = property(lambda self: np.array(self.integral_l))
    torque = property(lambda self: np.array(self.torque_l))
    saturated = property(lambda self: np.array(self.saturated_l, dtype=bool))

    def preload(self, torque, M) -> None:
        """Start with the integral that gives ``torque`` at zero velocity error (a servo that was
        holding its joint before the run began); ``M`` the arm's mass matrix there."""
        tau = np.clip(np.asarray(torque, float), -self.limits, self.limits)
        self.integral_l = (np.linalg.solve(np.asarray(M, float), tau) / (self.k * self.wi)).tolist()
        self.torque_l = tau.tolist()

    def set_command(self, qd) -> None:
        v = np.asarray(qd, float).reshape(-1)
        if v.shape != (self.n,):
            raise ValueError(f"velocity command needs {self.n} values, got {v.shape[0]}")
        self.command_l = [x if math.isfinite(x) else 0.0 for x in v.tolist()]  # non-finite: stop

    def torques(self, qd, M) -> list:
        """The motors' torques for joint velocities ``qd`` and the arm's mass matrix ``M`` (n x
        n) before a physics step. Past a torque limit the proportional part ``M k e`` is scaled
        down as a whole (by the largest ``s`` in [0, 1] that keeps every joint within its
        limit), so a saturated arm still moves along its command's direction instead of the
        limited joint's coupling pushing the others astray; the integral then holds."""
        M = np.asarray(M, float)
        e = np.asarray(self.command_l) - np.asarray(qd, float)
        acc = np.asarray(self.integral_l) + e * self.dt
        tau_i = M @ (self.k * self.wi * acc)
        tau_p = M @ (self.k * e)
        lim = self.limits
        raw = tau_i + tau_p
        if np.all(np.abs(raw) <= lim):
            self.integral_l, self.torque_l = acc.tolist(), raw.tolist()
            self.saturated_l = [False] * self.n
            return self.torque_l
        with np.errstate(divide="ignore", invalid="ignore"):
            room = np.where(tau_p > 0.0, lim - tau_i, -lim - tau_i) / tau_p
        room = np.where(np.abs(tau_p) > 0.0, np.maximum(room, 0.0), np.inf)
        scale = float(min(1.0, room.min()))
        tau = np.clip(tau_i + scale * tau_p, -lim, lim)
        self.torque_l = tau.tolist()
        self.saturated_l = (np.abs(tau) >= lim * (1.0 - 1e-12)).tolist()
        return self.torque_l  # the integral stays (anti-windup)
