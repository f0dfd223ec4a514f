"""A time-parameterised joint trajectory: per joint the quintic from (q0, qd0, qdd0) at t0 to
(q1, 0, 0) at t1 (minimum-jerk boundary conditions; a textbook choice, not from the papers)."""

from __future__ import annotations

import numpy as np


class Quintic:
    def __init__(self, t0: float, t1: float, q0, qd0, qdd0, q1) -> None:
        self.t0, self.t1 = float(t0), float(t1)
        T = self.t1 - self.t0
        if T <= 0.0:
            raise ValueError("a trajectory needs t1 > t0")
        q0, qd0, qdd0, q1 = (np.asarray(x, float) for x in (q0, qd0, qdd0, q1))
        self.goal = q1
        # q(s) = sum c_k s^k, s in [0, T]; c0..c2 from the start, c3..c5 from the end (rest)
        h = q1 - q0 - qd0 * T - 0.5 * qdd0 * T * T
        hd = -qd0 - qdd0 * T
        hdd = -qdd0
        M = np.array(
            [[T**3, T**4, T**5], [3 * T**2, 4 * T**3, 5 * T**4], [6 * T, 12 * T**2, 20 * T**3]]
        )
        c345 = np.linalg.solve(M, np.vstack([h, hd, hdd]))
        self.c = np.vstack([q0, qd0, 0.5 * qdd0, c345])  # (6, n)

    def __call__(self, t: float):
        """(q, qd, qdd) at t; before t0 the start, after t1 at rest at the goal."""
        if t >= self.t1:
            return self.goal.copy(), np.zeros_like(self.goal), np.zeros_like(self.goal)
        s = max(0.0, t - self.t0)
        k = np.arange(6)
        pw = s**k
        q = pw @ self.c
        qd = (k[1:] * s ** (k[1:] - 1)) @ self.c[1:]
        qdd = (k[2:] * (k[2:] - 1) * s ** (k[2:] - 2)) @ self.c[2:]
        return q, qd, qdd

    def peak_speed(self, n: int = 50) -> np.ndarray:
        ts = np.linspace(self.t0, self.t1, n)
        return np.max(np.abs([self(t)[1] for t in ts]), axis=0)
