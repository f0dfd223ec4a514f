"""The active-vision head's dynamics: two DC-servo axes (pan, tilt) taking velocity commands.

Each axis is a rigid inertia ``J`` (the camera platform, balanced: no gravity torque) driven by a
DC servo whose velocity loop gives ``tau = K (w_d - w)`` with ``K = J * bandwidth``, clipped to
the motor's torque limit. Integrated per physics step: implicitly while the torque is within the
limit (exact first-order response, stable for any bandwidth), explicitly at the limit. The joint
angle limits are hard stops. Simulator-free (the head is not a PyBullet body: it carries nothing
and nothing touches it); kinematics in ``replay.robot.head``.
"""

from __future__ import annotations

import numpy as np

from replay.robot.head import HeadSpec


class HeadServo:
    def __init__(self, head: HeadSpec, bandwidth: float, dt: float, q0) -> None:
        self.J = np.asarray(head.inertia, float)
        self.tau_max = np.asarray(head.torque_limit, float)
        self.lower, self.upper = np.asarray(head.lower, float), np.asarray(head.upper, float)
        self.K = self.J * bandwidth
        self.dt = dt
        self.q = np.asarray(q0, float).copy()
        self.qd = np.zeros(2)
        self.command = np.zeros(2)
        self.torque = np.zeros(2)

    def set_command(self, w) -> None:
        w = np.asarray(w, float).reshape(-1)
        if w.shape != (2,):
            raise ValueError(f"head command needs 2 values (pan, tilt), got {w.shape[0]}")
        self.command = np.where(np.isfinite(w), w, 0.0)

    def step(self) -> None:
        dt, J, K = self.dt, self.J, self.K
        qd_new = (J * self.qd + dt * K * self.command) / (J + dt * K)  # implicit velocity loop
        tau = K * (self.command - qd_new)
        over = np.abs(tau) > self.tau_max
        if over.any():
            tau = np.clip(K * (self.command - self.qd), -self.tau_max, self.tau_max)
            qd_new = np.where(over, self.qd + dt * tau / J, qd_new)
        self.torque = tau
        q = self.q + dt * qd_new
        stop = (q < self.lower) | (q > self.upper)
        self.q = np.clip(q, self.lower, self.upper)
        self.qd = np.where(stop, 0.0, qd_new)
