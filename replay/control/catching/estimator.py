"""Ball velocity/acceleration and time-to-contact from stereo positions (not in the paper).

Eq. 17 needs r_o' and r_o'' and the hand must start closing before the ball arrives; the paper
says neither how it got the derivatives nor when the hand closed. Ours: a least-squares fit of a
ballistic arc with *known* gravity, r(t) = r0 + v (t - t_last) + g (t - t_last)^2 / 2, over the
measurements of the last ``window`` seconds (per axis two unknowns, r0 and v). The time to reach
the catch surface |r - O| = R_c (where q4 = q_alpha, i.e. contact) is the first future root of the
quartic |d + v s + g s^2 / 2|^2 = R_c^2. This is the default (``estimator: ballistic``);
:class:`LastFrameEstimator` (``estimator: last``) is the prediction-free alternative.
"""

from __future__ import annotations

import math
from collections import deque

import numpy as np


class BallisticEstimator:
    """The fit is solved from running sums (the 2 x 2 normal equations per axis) kept as
    measurements enter and leave the window: with time measured from a reference t_ref the
    model r = a + b (t - t_ref) + g (t - t_ref)^2 / 2 spans the same arcs as the one about
    t_last, so the least-squares solution is the same; t_ref is moved (the sums rebuilt) once
    per window so that the sums stay well conditioned."""

    def __init__(self, gravity=(0.0, 0.0, -9.81), window: float = 0.1, max_samples: int = 400):
        self.g = np.asarray(gravity, float)
        self._g = tuple(self.g.tolist())
        self.window = float(window)
        self.buf: deque[tuple[float, tuple[float, float, float]]] = deque(maxlen=max_samples)
        self._fit = None
        self._rebuild(None)

    def reset(self) -> None:
        self.buf.clear()
        self._fit = None
        self._rebuild(None)

    @property
    def n(self) -> int:
        return len(self.buf)

    @property
    def last(self):
        return self.buf[-1] if self.buf else None

    # ---- running sums: n, sum tau, sum tau^2, sum y, sum tau y (y = r - g tau^2 / 2, per axis)
    def _rebuild(self, t_ref) -> None:
        self._t_ref = t_ref
        self._S = [0.0, 0.0, 0.0]
        self._Sy = [0.0, 0.0, 0.0]
        self._Sty = [0.0, 0.0, 0.0]
        for t, r in self.buf:
            self._account(t, r, 1.0)

    def _account(self, t: float, r, sign: float) -> None:
        tau = t - self._t_ref
        S, Sy, Sty = self._S, self._Sy, self._Sty
        g0, g1, g2 = self._g
        st = sign * tau
        S[0] += sign
        S[1] += st
        S[2] += st * tau
        h = 0.5 * tau * tau
        y0, y1, y2 = r[0] - g0 * h, r[1] - g1 * h, r[2] - g2 * h
        Sy[0] += sign * y0
        Sy[1] += sign * y1
        Sy[2] += sign * y2
        Sty[0] += st * y0
        Sty[1] += st * y1
        Sty[2] += st * y2

    def add(self, t: float, r) -> None:
        r = (float(r[0]), float(r[1]), float(r[2]))
        buf = self.buf
        if buf and t <= buf[-1][0]:
            return  # out of order or repeated frame
        t = float(t)
        if self._t_ref is None:
            self._t_ref = t
        if len(buf) == buf.maxlen:  # the deque drops its oldest: so do the sums
            self._account(*buf[0], -1.0)
        buf.append((t, r))
        # _account(t, r, 1.0) written out (sign 1: the same values)
        tau = t - self._t_ref
        S, Sy, Sty = self._S, self._Sy, self._Sty
        g0, g1, g2 = self._g
        S[0] += 1.0
        S[1] += tau
        S[2] += tau * tau
        h = 0.5 * tau * tau
        y0, y1, y2 = r[0] - g0 * h, r[1] - g1 * h, r[2] - g2 * h
        Sy[0] += y0
        Sy[1] += y1
        Sy[2] += y2
        Sty[0] += tau * y0
        Sty[1] += tau * y1
        Sty[2] += tau * y2
        limit = self.window + 1e-12
        while t - buf[0][0] > limit:  # (never the newest)
            # _account(*buf.popleft(), -1.0) written out (x + (-y) is x - y: the same values)
            t_old, (x0, x1, x2) = buf.popleft()
            tau = t_old - self._t_ref
            S[0] -= 1.0
            S[1] -= tau
            S[2] -= tau * tau
            h = 0.5 * tau * tau
            y0, y1, y2 = x0 - g0 * h, x1 - g1 * h, x2 - g2 * h
            Sy[0] -= y0
            Sy[1] -= y1
            Sy[2] -= y2
            Sty[0] -= tau * y0
            Sty[1] -= tau * y1
            Sty[2] -= tau * y2
        if buf[0][0] - self._t_ref > self.window:  # re-centre: sums of the window only
            self._rebuild(buf[0][0])
        self._fit = None

    def fit(self):
        """(t_last, r0, v) at the last measurement time; v is None with a single measurement."""
        f = self.fit_f()
        if f is None:
            return None
        return f[0], np.array(f[1]), None if f[2] is None else np.array(f[2])

    def fit_f(self):
        """:meth:`fit` with r0 and v as 3-tuples of floats (the per-step path)."""
        if self._fit is None:
            if not self.buf:
                return None
            t_last, r_last = self.buf[-1]
            if len(self.buf) == 1:
                self._fit = (t_last, r_last, None)
            else:  # per axis k: b = (n Sty - s1 Sy) / det, a = (Sy - b s1) / n, at t_last
                s1, s2 = self._S[1], self._S[2]
                n = float(len(self.buf))  # exact, not a running sum
                det = n * s2 - s1 * s1
                tl = t_last - self._t_ref
                g0, g1, g2 = self._g
                Sy0, Sy1, Sy2 = self._Sy
                St0, St1, St2 = self._Sty
                b0 = (n * St0 - s1 * Sy0) / det
                b1 = (n * St1 - s1 * Sy1) / det
                b2 = (n * St2 - s1 * Sy2) / det
                a0, a1, a2 = (Sy0 - b0 * s1) / n, (Sy1 - b1 * s1) / n, (Sy2 - b2 * s1) / n
                r0 = (
                    a0 + b0 * tl + 0.5 * g0 * tl * tl,
                    a1 + b1 * tl + 0.5 * g1 * tl * tl,
                    a2 + b2 * tl + 0.5 * g2 * tl * tl,
                )
                self._fit = (t_last, r0, (b0 + g0 * tl, b1 + g1 * tl, b2 + g2 * tl))
        return self._fit

    def state(self, t: float, *, from_fit: bool = False):
        """(r, v, a) at time t: the last measurement (or the fit) carried forward ballistically.

        With one measurement the velocity is unknown and taken as zero.
        """
        st = self.state_f(t, from_fit=from_fit)
        if st is None:
            return None
        return np.array(st[0]), np.array(st[1]), self.g.copy()

    def state_f(self, t: float, *, from_fit: bool = False):
        """:meth:`state` as 3-tuples of floats: per component the operations NumPy did on the
        3-vectors (base + v dt + (0.5 g) dt dt), so the same values."""
        f = self.fit_f()
        if f is None:
            return None
        t_last, r0, v = f
        if v is None:
            v = (0.0, 0.0, 0.0)
        dt = t - t_last
        b = r0 if from_fit else self.buf[-1][1]
        g0, g1, g2 = self._g
        return (
            (
                b[0] + v[0] * dt + 0.5 * g0 * dt * dt,
                b[1] + v[1] * dt + 0.5 * g1 * dt * dt,
                b[2] + v[2] * dt + 0.5 * g2 * dt * dt,
            ),
            (v[0] + g0 * dt, v[1] + g1 * dt, v[2] + g2 * dt),
            self._g,
        )

    def time_to_radius(self, t: float, origin, radius: float):
        """Absolute time at which the arc first reaches |r - origin| = radius (None if never),
        in Python floats: the quartic's first root by Newton's method where it provably finds
        it, else by the eigenvalues of its companion matrix."""
        st = self.state_f(t, from_fit=True)
        if st is None or self.n < 2:
            return None
        (rx, ry, rz), (vx, vy, vz), (gx, gy, gz) = st
        dx, dy, dz = rx - float(origin[0]), ry - float(origin[1]), rz - float(origin[2])
        dd = dx * dx + dy * dy + dz * dz
        if dd <= radius * radius:
            return t
        coeffs = [
            0.25 * (gx * gx + gy * gy + gz * gz),
            vx * gx + vy * gy + vz * gz,
            (vx * vx + vy * vy + vz * vz) + (dx * gx + dy * gy + dz * gz),
            2.0 * (dx * vx + dy * vy + dz * vz),
            dd - radius * radius,
        ]
        s = _first_root_newton(coeffs)
        if s is not None:
            return t + s
        roots = _roots(coeffs)
        real = roots[np.abs(roots.imag) < 1e-9].real
        real = real[real >= 0.0]
        return t + float(real.min()) if real.size else None


def _first_root_newton(c):
    """The smallest root s >= 0 of the quartic c[0] s^4 + ... + c[4] (c[4] > 0: outside the
    sphere) when Newton's method from s = 0 provably finds it, else None (then the caller takes
    the companion matrix's eigenvalues). Proof: where h'' > 0 on [0, s*] and h'(0) < 0, Newton's
    iterates from 0 rise monotonically to the first root. A ball flying at the arm makes h
    convex (h'' = 2 |v + g s|^2 + 2 (d + v s + g s^2 / 2) . g, the first term dominating)."""
    c4, c3, c2, c1, c0 = c
    s = 0.0
    for _ in range(60):
        f = (((c4 * s + c3) * s + c2) * s + c1) * s + c0
        fp = ((4.0 * c4 * s + 3.0 * c3) * s + 2.0 * c2) * s + c1
        if not fp < 0.0:
            return None
        step = f / fp
        s -= step
        if abs(step) <= 1e-15 * max(s, 1e-3):
            break
    else:
        return None
    if not s >= 0.0:
        return None
    # h'' = 12 c4 s^2 + 6 c3 s + 2 c2 must stay positive on [0, s]: check its minimum there
    cand = [0.0, s]
    if c4 > 0.0 and 0.0 < -c3 / (4.0 * c4) < s:
        cand.append(-c3 / (4.0 * c4))
    if min((12.0 * c4 * x + 6.0 * c3) * x + 2.0 * c2 for x in cand) <= 0.0:
        return None
    return s


def _roots(coeffs) -> np.ndarray:
    """np.roots of a polynomial (highest power first): the eigenvalues of the same companion
    matrix, built directly when neither end coefficient is zero (np.roots strips those)."""
    if coeffs[0] == 0.0 or coeffs[-1] == 0.0:
        return np.roots(coeffs)
    n = len(coeffs) - 1
    A = np.eye(n, k=-1)
    A[0, :] = [-c / coeffs[0] for c in coeffs[1:]]
    return np.linalg.eigvals(A)


class LastFrameEstimator:
    """The prediction-free estimate (``estimator: last``; issue #38): no model of the flight.

    Eq. 7 takes r_o as the newest stereo position, as measured (no latency extrapolation); eq. 23
    takes r_o' as the backward difference of the two newest frames (no fit, no gravity); eq. 16's
    r_o'' is 0 (a second difference of frames ~1 mm apart in error is +-10^3 m/s^2 at 1 kHz). The
    hand still needs a time to contact to close in time: the first-order one (Lee's tau), the gap
    to the catch surface over the closing speed, |d + v s| = R_c, with no gravity either.
    """

    ZERO = (0.0, 0.0, 0.0)

    def __init__(self) -> None:
        self.buf: deque[tuple[float, tuple[float, float, float]]] = deque(maxlen=2)

    def reset(self) -> None:
        self.buf.clear()

    @property
    def n(self) -> int:
        return len(self.buf)

    def add(self, t: float, r) -> None:
        if self.buf and t <= self.buf[-1][0]:
            return  # out of order or repeated frame
        self.buf.append((float(t), (float(r[0]), float(r[1]), float(r[2]))))

    def state_f(self, t: float, *, from_fit: bool = False):
        """(r, v, a) as 3-tuples, whatever ``t``: the newest frame, the two newest frames'
        difference quotient (zero with one frame) and zero acceleration."""
        if not self.buf:
            return None
        t1, r1 = self.buf[-1]
        if len(self.buf) == 1:
            return r1, self.ZERO, self.ZERO
        t0, r0 = self.buf[0]
        h = t1 - t0
        return r1, ((r1[0] - r0[0]) / h, (r1[1] - r0[1]) / h, (r1[2] - r0[2]) / h), self.ZERO

    def state(self, t: float, *, from_fit: bool = False):
        st = self.state_f(t)
        return None if st is None else tuple(np.array(x) for x in st)

    def time_to_radius(self, t: float, origin, radius: float):
        """Absolute time at which |d + v s| = radius first (d = r - origin; None if never): the
        smaller root s >= 0 of |v|^2 s^2 + 2 d.v s + |d|^2 - radius^2."""
        st = self.state_f(t)
        if st is None or self.n < 2:
            return None
        r, v, _ = st
        d = [r[i] - float(origin[i]) for i in range(3)]
        c = sum(x * x for x in d) - radius * radius
        if c <= 0.0:
            return t
        a = sum(x * x for x in v)
        b = sum(x * y for x, y in zip(d, v))
        disc = b * b - a * c
        if a == 0.0 or b >= 0.0 or disc < 0.0:
            return None  # not closing in, or passing the sphere by
        return t + (-b - math.sqrt(disc)) / a
