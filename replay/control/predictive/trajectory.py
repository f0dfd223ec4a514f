"""Time-parameterised joint trajectories of the predict-then-intercept baseline (textbook choices,
not from the papers).

- :class:`Quintic`: per joint the quintic from (q0, qd0, qdd0) at t0 to (q1, qd1, qdd1) at t1
  (minimum-jerk boundary conditions; rest at the end by default).
- :class:`InterceptPlan`: the three phases of an intercept with velocity matching: a quintic
  *move* to the pre-contact state (q_c - qd_c T_s, qd_c) at t_c - T_s, a *glide* at the constant
  joint velocity qd_c through the catch posture q_c at t_c (the hand moving with the ball as far
  as the plan allows), then a *brake* quintic from (q_c, qd_c) to rest over T_b. With qd_c = 0
  the glide is a hold: the arm settles at q_c T_s before the ball arrives.
"""

from __future__ import annotations

import numpy as np


class Quintic:
    def __init__(self, t0: float, t1: float, q0, qd0, qdd0, q1, qd1=None, qdd1=None) -> None:
        self.t0, self.t1 = float(t0), float(t1)
        T = self.t1 - self.t0
        if T <= 0.0:
            raise ValueError("a trajectory needs t1 > t0")
        q0, qd0, qdd0, q1 = (np.asarray(x, float) for x in (q0, qd0, qdd0, q1))
        qd1 = np.zeros_like(q1) if qd1 is None else np.asarray(qd1, float)
        qdd1 = np.zeros_like(q1) if qdd1 is None else np.asarray(qdd1, float)
        self.goal, self.goal_rate, self.goal_acc = q1, qd1, qdd1
        # q(s) = sum c_k s^k, s in [0, T]; c0..c2 from the start, c3..c5 from the end
        h = q1 - q0 - qd0 * T - 0.5 * qdd0 * T * T
        hd = qd1 - qd0 - qdd0 * T
        hdd = qdd1 - qdd0
        M = np.array(
            [[T**3, T**4, T**5], [3 * T**2, 4 * T**3, 5 * T**4], [6 * T, 12 * T**2, 20 * T**3]]
        )
        c345 = np.linalg.solve(M, np.vstack([h, hd, hdd]))
        self.c = np.vstack([q0, qd0, 0.5 * qdd0, c345])  # (6, n)

    def __call__(self, t: float):
        """(q, qd, qdd) at t; before t0 the start; after t1 the end state carried on at its
        velocity (at rest at the goal for the default qd1 = 0)."""
        if t >= self.t1:
            dt = t - self.t1
            return self.goal + self.goal_rate * dt, self.goal_rate.copy(), np.zeros_like(self.goal)
        s = max(0.0, t - self.t0)
        k = np.arange(6)
        pw = s**k
        q = pw @ self.c
        qd = (k[1:] * s ** (k[1:] - 1)) @ self.c[1:]
        qdd = (k[2:] * (k[2:] - 1) * s ** (k[2:] - 2)) @ self.c[2:]
        return q, qd, qdd

    def samples(self, n: int = 12):
        """(q, qd, qdd) at n instants evenly spread over [t0, t1]."""
        return [self(t) for t in np.linspace(self.t0, self.t1 - 1e-12, n)]


class InterceptPlan:
    """Move, glide, brake (module doc). ``t_catch`` is the planned arrival t_c of the ball."""

    def __init__(
        self, t0: float, q0, qd0, qdd0, q_c, qd_c, t_catch: float, settle: float, brake: float
    ) -> None:
        q_c, qd_c = np.asarray(q_c, float), np.asarray(qd_c, float)
        self.t_catch, self.settle, self.brake = float(t_catch), float(settle), float(brake)
        self.q_c, self.qd_c = q_c, qd_c
        self.t_glide = self.t_catch - self.settle
        self.move = Quintic(t0, self.t_glide, q0, qd0, qdd0, q_c - qd_c * self.settle, qd_c)
        # the brake stops the glide's velocity qd_c over T_b with zero acceleration at both ends:
        # the hand travels qd_c T_b / 2 further (as far as a constant deceleration would)
        self.stop = Quintic(
            self.t_catch,
            self.t_catch + self.brake,
            q_c,
            qd_c,
            np.zeros_like(q_c),
            q_c + 0.5 * qd_c * self.brake,
        )
        self.goal = q_c  # the catch posture (the plan's target)
        self.t1 = self.t_glide

    def __call__(self, t: float):
        if t < self.t_glide:
            return self.move(t)
        if t < self.t_catch:
            return (
                self.q_c + self.qd_c * (t - self.t_catch),
                self.qd_c.copy(),
                np.zeros_like(self.q_c),
            )
        return self.stop(t)

    def samples(self, n: int = 12):
        """Move samples plus the glide's two ends, for torque checks (the brake, after the
        ball is in the hand, is not: it is followed as far as the limits allow)."""
        return self.move.samples(n) + [self(self.t_glide), self(self.t_catch - 1e-9)]
