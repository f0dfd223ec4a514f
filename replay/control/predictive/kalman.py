"""A Kalman filter on the stereo positions: state (r, v), known gravity, white-noise acceleration.

The textbook constant-acceleration-input model (not from either paper): between measurements
r' = v, v' = g + w with w white of spectral density ``accel_sigma^2`` per axis, so over dt

    x <- F x + B g,   F = [[I, dt I], [0, I]],   B g = [g dt^2 / 2, g dt],
    P <- F P F^T + Q, Q = q [[dt^3/3 I, dt^2/2 I], [dt^2/2 I, dt I]],  q = accel_sigma^2,

and a stereo position z = r + n, n ~ N(0, meas_sigma^2 I), updates it. The filter is kept at the
time of its newest measurement; :meth:`state` carries it forward ballistically.
"""

from __future__ import annotations

import numpy as np


class BallKalman:
    def __init__(
        self,
        gravity=(0.0, 0.0, -9.81),
        *,
        meas_sigma: float = 0.002,
        accel_sigma: float = 2.0,
        v_sigma0: float = 10.0,
    ) -> None:
        self.g = np.asarray(gravity, float)
        self.R = np.eye(3) * meas_sigma**2
        self.q = accel_sigma**2
        self.v_sigma0 = v_sigma0
        self.x = np.zeros(6)  # r, v (valid once n > 0)
        self.P = np.eye(6)
        self.t = 0.0
        self.n = 0

    def _predict(self, dt: float) -> None:
        if dt <= 0.0:
            return
        F = np.eye(6)
        F[:3, 3:] = np.eye(3) * dt
        self.x = F @ self.x + np.concatenate([0.5 * self.g * dt * dt, self.g * dt])
        I3 = np.eye(3)
        Q = self.q * np.block([[dt**3 / 3 * I3, dt**2 / 2 * I3], [dt**2 / 2 * I3, dt * I3]])
        self.P = F @ self.P @ F.T + Q

    def add(self, t: float, z) -> None:
        z = np.asarray(z, float)
        if self.n == 0:
            self.x = np.concatenate([z, np.zeros(3)])
            self.P = np.diag([self.R[0, 0]] * 3 + [self.v_sigma0**2] * 3)
            self.t = float(t)
            self.n = 1
            return
        if t <= self.t:
            return  # repeated or out-of-order frame
        self._predict(t - self.t)
        self.t = float(t)
        H = np.hstack([np.eye(3), np.zeros((3, 3))])
        S = H @ self.P @ H.T + self.R
        K = np.linalg.solve(S, H @ self.P).T
        self.x = self.x + K @ (z - H @ self.x)
        self.P = (np.eye(6) - K @ H) @ self.P
        self.n += 1

    def state(self, t: float):
        """(r, v) at time t, carried ballistically from the newest estimate (None before any)."""
        if self.n == 0:
            return None
        dt = t - self.t
        r, v = self.x[:3], self.x[3:]
        return r + v * dt + 0.5 * self.g * dt * dt, v + self.g * dt

    def position_sigma(self) -> float:
        return float(np.sqrt(np.trace(self.P[:3, :3]) / 3.0)) if self.n else float("inf")

    def velocity_sigma(self) -> float:
        return float(np.sqrt(np.trace(self.P[3:, 3:]) / 3.0)) if self.n else float("inf")
