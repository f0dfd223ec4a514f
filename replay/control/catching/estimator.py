"""Ball velocity/acceleration and time-to-contact from stereo positions (not in the paper).

Eq. 17 needs r_o' and r_o'' and the hand must start closing before the ball arrives; the paper
says neither how it got the derivatives nor when the hand closed. Ours: a least-squares fit of a
ballistic arc with *known* gravity, r(t) = r0 + v (t - t_last) + g (t - t_last)^2 / 2, over the
measurements of the last ``window`` seconds (per axis two unknowns, r0 and v). The time to reach
the catch surface |r - O| = R_c (where q4 = q_alpha, i.e. contact) is the first future root of the
quartic |d + v s + g s^2 / 2|^2 = R_c^2.
"""

from __future__ import annotations

from collections import deque

import numpy as np


class BallisticEstimator:
    def __init__(self, gravity=(0.0, 0.0, -9.81), window: float = 0.1, max_samples: int = 400):
        self.g = np.asarray(gravity, float)
        self.window = float(window)
        self.buf: deque = deque(maxlen=max_samples)
        self._fit = None

    def reset(self) -> None:
        self.buf.clear()
        self._fit = None

    @property
    def n(self) -> int:
        return len(self.buf)

    @property
    def last(self):
        return self.buf[-1] if self.buf else None

    def add(self, t: float, r) -> None:
        r = np.asarray(r, float)
        if self.buf and t <= self.buf[-1][0]:
            return  # out of order or repeated frame
        self.buf.append((float(t), r))
        while self.buf and self.buf[-1][0] - self.buf[0][0] > self.window + 1e-12:
            self.buf.popleft()
        self._fit = None

    def fit(self):
        """(t_last, r0, v) at the last measurement time; v is None with a single measurement."""
        if not self.buf:
            return None
        if self._fit is None:
            t_last, r_last = self.buf[-1]
            if len(self.buf) == 1:
                self._fit = (t_last, r_last, None)
            else:
                s = np.array([b[0] for b in self.buf]) - t_last
                Y = np.array([b[1] for b in self.buf]) - 0.5 * np.outer(s * s, self.g)
                A = np.column_stack([np.ones_like(s), s])
                sol, *_ = np.linalg.lstsq(A, Y, rcond=None)
                self._fit = (t_last, sol[0], sol[1])
        return self._fit

    def state(self, t: float, *, from_fit: bool = False):
        """(r, v, a) at time t: the last measurement (or the fit) carried forward ballistically.

        With one measurement the velocity is unknown and taken as zero.
        """
        f = self.fit()
        if f is None:
            return None
        t_last, r0, v = f
        r_meas = self.buf[-1][1]
        v = np.zeros(3) if v is None else v
        dt = t - t_last
        base = r0 if from_fit else r_meas
        return base + v * dt + 0.5 * self.g * dt * dt, v + self.g * dt, self.g.copy()

    def time_to_radius(self, t: float, origin, radius: float):
        """Absolute time at which the arc first reaches |r - origin| = radius (None if never)."""
        st = self.state(t, from_fit=True)
        if st is None or self.n < 2:
            return None
        r, v, g = st
        d = r - np.asarray(origin, float)
        if d @ d <= radius * radius:
            return t
        coeffs = [0.25 * (g @ g), v @ g, v @ v + d @ g, 2.0 * (d @ v), d @ d - radius * radius]
        roots = np.roots(coeffs)
        real = roots[np.abs(roots.imag) < 1e-9].real
        real = real[real >= 0.0]
        return t + float(real.min()) if real.size else None
