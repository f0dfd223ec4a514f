"""The active-vision head's dynamics: two DC-servo axes (pan, tilt) taking velocity commands.

Each axis is a rigid inertia ``J`` (the camera platform, balanced: no gravity torque) driven by a
DC servo whose velocity loop gives ``tau = K (w_d - w)`` with ``K = J * bandwidth``, clipped to
the motor's torque limit. Integrated per physics step: implicitly while the torque is within the
limit (exact first-order response, stable for any bandwidth), explicitly at the limit. The joint
angle limits are hard stops. Simulator-free (the head is not a PyBullet body: it carries nothing
and nothing touches it); kinematics in ``replay.robot.head``.
"""

from __future__ import annotations

import math

import numpy as np

from replay.robot.head import HeadSpec


class HeadServo:
    """The state per axis in plain floats (``q_l``, ``qd_l``, ``torque_l``, ``command_l``; two
    axes: lists beat arrays); ``q``, ``qd``, ``torque``, ``command`` give it as arrays."""

    def __init__(self, head: HeadSpec, bandwidth: float, dt: float, q0) -> None:
        self.J = np.asarray(head.inertia, float)
        self.tau_max = np.asarray(head.torque_limit, float)
        self.lower, self.upper = np.asarray(head.lower, float), np.asarray(head.upper, float)
        self.K = self.J * bandwidth
        self.dt = dt
        self._J, self._K, self._tmax = self.J.tolist(), self.K.tolist(), self.tau_max.tolist()
        self._lo, self._hi = self.lower.tolist(), self.upper.tolist()
        self.q_l = np.asarray(q0, float).reshape(-1).tolist()
        self.qd_l = [0.0, 0.0]
        self.command_l = [0.0, 0.0]
        self.torque_l = [0.0, 0.0]

    q = property(lambda self: np.array(self.q_l))
    qd = property(lambda self: np.array(self.qd_l))
    command = property(lambda self: np.array(self.command_l))
    torque = property(lambda self: np.array(self.torque_l))

    def set_command(self, w) -> None:
        w = np.asarray(w, float).reshape(-1)
        if w.shape != (2,):
            raise ValueError(f"head command needs 2 values (pan, tilt), got {w.shape[0]}")
        self.command_l = [x if math.isfinite(x) else 0.0 for x in w.tolist()]

    def step(self) -> None:
        # per axis in floats (the same operations as on the 2-vectors, without numpy's per-call
        # cost on two elements); one axis at its torque limit makes both torques explicit
        dt = self.dt
        J, K, w, qd0 = self._J, self._K, self.command_l, self.qd_l
        tmax, lo, hi = self._tmax, self._lo, self._hi
        qd = [(J[i] * qd0[i] + dt * K[i] * w[i]) / (J[i] + dt * K[i]) for i in (0, 1)]
        tau = [K[i] * (w[i] - qd[i]) for i in (0, 1)]
        over = [abs(tau[i]) > tmax[i] for i in (0, 1)]
        if over[0] or over[1]:
            tau = [min(max(K[i] * (w[i] - qd0[i]), -tmax[i]), tmax[i]) for i in (0, 1)]
            qd = [qd0[i] + dt * tau[i] / J[i] if over[i] else qd[i] for i in (0, 1)]
        q = [self.q_l[0] + dt * qd[0], self.q_l[1] + dt * qd[1]]
        stop = [q[i] < lo[i] or q[i] > hi[i] for i in (0, 1)]
        self.torque_l = tau
        self.q_l = [min(max(q[i], lo[i]), hi[i]) for i in (0, 1)]
        self.qd_l = [0.0 if stop[i] else qd[i] for i in (0, 1)]
