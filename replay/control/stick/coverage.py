"""The stick's predicted motion and the area it sweeps, for the stick-capture planners.

Higashimori et al. 2007: between collisions the stick moves with constant velocities
(Assumption 6), those of the estimator's fit; after a planned contact it moves with the
velocities the contact solution predicts, u_i = J_i u_{i-1} (eq. 22). A point is covered by the
stick when it lies within a margin of the spec's L x W rectangle (W may be 0, the paper's
Assumption 5). The planners sample the sweep every ``SAMPLE_DT``.

NumPy: each check one vectorised pass over the samples (:func:`covered`, :func:`covered_along`:
the references). The checks the planners repeat most (:func:`first_covered`, ``ContactPlanner
.route_clear``) look at fixed points over hundreds of samples: there only the samples at which
the stick's centre (linear in time on each side of ``t_switch``) can be within the grown
rectangle's corner reach of the point are looked at (:func:`near_samples` solves for them),
one by one, skipping those the stick cannot reach the point by (:func:`covered_fixed`): the
same answers as the references (tests/replay/control/stick/test_coverage_paths.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.control.stick.estimator import StickEstimate

SAMPLE_DT = 0.001  # s, time step of the predicted-sweep checks


@dataclass(frozen=True, init=False)
class Motion:
    """Constant velocities from ``est``; from ``t_switch`` on, ``u_after`` (a planned contact)."""

    est: StickEstimate
    t_switch: float = math.inf
    u_after: tuple = (0.0, 0.0, 0.0)

    def __init__(
        self, est: StickEstimate, t_switch: float = math.inf, u_after: tuple = (0.0, 0.0, 0.0)
    ) -> None:
        # the fields straight into the instance's dict (the generated frozen __init__ costs
        # ~1 us a field on Python 3.11; tests/replay/test_scene_inits.py holds it to that one)
        d = self.__dict__
        d["est"], d["t_switch"], d["u_after"] = est, t_switch, u_after

    def poses(self, times) -> tuple[np.ndarray, np.ndarray]:
        t = np.asarray(times, dtype=float)
        e = self.est
        t1 = np.minimum(t, self.t_switch) - e.t_ref
        c = np.empty(t.shape + (2,))
        c[..., 0] = e.x + e.vx * t1
        c[..., 1] = e.y + e.vy * t1
        th = e.theta + e.omega * t1
        if math.isfinite(self.t_switch):
            t2 = np.maximum(t - self.t_switch, 0.0)
            c[..., 0] += self.u_after[0] * t2
            c[..., 1] += self.u_after[1] * t2
            th = th + self.u_after[2] * t2
        return c, th

    def poses_before_switch(self, times: np.ndarray) -> tuple[np.ndarray, ...]:
        """:meth:`poses` as (x, y, theta) arrays; where every time is before ``t_switch`` in
        fewer operations (min(t, t_switch) is t, and adding a finite u_after * 0 changes no more
        than the sign of a zero)."""
        e, u = self.est, self.u_after
        if not (len(times) and times[-1] < self.t_switch and math.isfinite(u[0] + u[1] + u[2])):
            c, th = self.poses(times)
            return c[:, 0], c[:, 1], th
        t1 = times - e.t_ref
        return e.x + e.vx * t1, e.y + e.vy * t1, e.theta + e.omega * t1

    def pose(self, t: float) -> tuple[np.ndarray, float]:
        x, y, th = self.pose_floats(t)
        return np.array([x, y]), float(th)

    def pose_floats(self, t: float) -> tuple[float, float, float]:
        """:meth:`pose` as (x, y, theta) floats."""
        e, ts = self.est, self.t_switch
        t1 = min(t, ts) - e.t_ref
        x, y, th = e.x + e.vx * t1, e.y + e.vy * t1, e.theta + e.omega * t1
        if math.isfinite(ts):
            t2 = max(t - ts, 0.0)
            u = self.u_after
            x, y, th = x + u[0] * t2, y + u[1] * t2, th + u[2] * t2
        return x, y, th


def _body(motion: Motion, times, points) -> tuple[np.ndarray, np.ndarray]:
    """Stick-frame coordinates (xb, yb), each (T, K), of fixed points (K, 2)."""
    c, th = motion.poses(times)
    cs, sn = np.cos(th), np.sin(th)
    d = np.asarray(points, dtype=float)[None, :, :] - c[:, None, :]
    return d[..., 0] * cs[:, None] + d[..., 1] * sn[:, None], -d[..., 0] * sn[:, None] + d[
        ..., 1
    ] * cs[:, None]


def covered(
    motion: Motion, times, points, half_length: float, half_width: float, grow
) -> np.ndarray:
    """(len(times), len(points)) booleans: point within ``grow`` of the stick rectangle."""
    xb, yb = _body(motion, times, np.asarray(points, dtype=float).reshape(-1, 2))
    return (np.abs(xb) <= half_length + grow) & (np.abs(yb) <= half_width + grow)


def covered_along(
    motion: Motion, times, points, half_length: float, half_width: float, grow, poses=None
) -> np.ndarray:
    """(T,) booleans: points[i] (a moving point, (T, 2)) within ``grow`` of the stick at
    times[i]; ``grow`` a scalar or (T,); ``poses``: ``motion.poses(times)`` if already made."""
    c, th = motion.poses(times) if poses is None else poses
    d = np.asarray(points, dtype=float) - c
    cs, sn = np.cos(th), np.sin(th)
    xb = d[:, 0] * cs + d[:, 1] * sn
    yb = -d[:, 0] * sn + d[:, 1] * cs
    return (np.abs(xb) <= half_length + grow) & (np.abs(yb) <= half_width + grow)


def sample_count(t0: float, t1: float) -> int:
    """How many :func:`sample_times` from t0 to t1."""
    return 1 if t1 <= t0 else max(2, int(math.ceil((t1 - t0) / SAMPLE_DT)) + 1)


def sample_times(t0: float, t1: float) -> np.ndarray:
    """Times from t0 to t1 at most ``SAMPLE_DT`` apart (just t0 when t1 <= t0)."""
    if t1 <= t0:
        return np.array([t0])
    return np.linspace(t0, t1, sample_count(t0, t1))


def sample_times_at(t0: float, t1: float, lo: int, hi: int) -> np.ndarray:
    """``sample_times(t0, t1)[lo:hi]``, made alone (np.linspace's operations)."""
    n = sample_count(t0, t1)
    if n == 1:
        return np.array([t0])[lo:hi]
    hi = min(hi, n)
    div, delta = n - 1, t1 - t0
    step = delta / div
    y = np.arange(lo, hi, dtype=float)
    if step == 0:
        y /= div
        y *= delta
    else:
        y *= step
    y += t0
    if hi == n > lo:
        y[-1] = t1
    return y


def sample_time(t0: float, t1: float, i: int) -> float:
    """``sample_times(t0, t1)[i]`` as a float (the same operations)."""
    n = sample_count(t0, t1)
    if n == 1:
        return t0
    if i == n - 1:
        return t1
    div, delta = n - 1, t1 - t0
    step = delta / div
    if step == 0:
        return float(i) / div * delta + t0
    return float(i) * step + t0


def count_before(t0: float, t1: float, t: float, inclusive: bool) -> int:
    """How many of :func:`sample_times` (t0, t1) (ascending) are < t (``inclusive``: <= t)."""
    n = sample_count(t0, t1)
    if n == 1:
        return int(t0 <= t if inclusive else t0 < t)
    step = (t1 - t0) / (n - 1)
    if not step > 0.0:  # (a span of denormals: sample_time's other formula)
        return sum(1 for i in range(n) if _before(sample_time(t0, t1, i), t, inclusive))
    guess = (t - t0) / step
    i = min(max(int(guess), 0), n) if math.isfinite(guess) else (n if guess > 0 else 0)

    def at(j: int) -> float:  # (sample_time)
        return t1 if j == n - 1 else j * step + t0

    # (the guess within a sample or two of the count: moved onto it)
    while i > 0 and not _before(at(i - 1), t, inclusive):
        i -= 1
    while i < n and _before(at(i), t, inclusive):
        i += 1
    return i


def _before(s: float, t: float, inclusive: bool) -> bool:
    return s <= t if inclusive else s < t


def corner_reach2(half_length: float, half_width: float) -> float:
    """Squared reach of a rectangle of half-sizes (already grown), a little beyond its corners:
    a point farther than that from its centre is outside it whatever the orientation (the
    rotation keeps |d| to a few ulps), so only nearer points need rotating."""
    return (half_length * half_length + half_width * half_width) * (1.0 + 1e-9) + 1e-300


def covered_samples(
    x, y, th, px, py, half_length: float, half_width: float, grow: float
) -> np.ndarray:
    """Indices of the samples (stick poses x, y, theta: arrays; the point px, py: floats or
    arrays alike) at which the point is within ``grow`` of the stick rectangle: the samples of
    :func:`covered_along` (the same operations) that are True, ascending; cos and sin only of
    the samples within the corner reach."""
    gl, gw = half_length + grow, half_width + grow
    dx, dy = px - x, py - y
    near = np.flatnonzero(dx * dx + dy * dy <= corner_reach2(gl, gw))
    if not near.size:
        return near
    dx, dy, a = dx[near], dy[near], th[near]
    c, s = np.cos(a), np.sin(a)
    return near[(np.abs(dx * c + dy * s) <= gl) & (np.abs(-dx * s + dy * c) <= gw)]


def _span(px, py, cx, cy, vx, vy, r: float) -> tuple[float, float] | None:
    """The s for which |(cx, cy) + s (vx, vy) - (px, py)| <= r, as (s_lo, s_hi) (may be
    infinite), or None."""
    wx, wy = cx - px, cy - py
    a = vx * vx + vy * vy
    c = wx * wx + wy * wy - r * r
    if a < 1e-24:  # (not moving: near or not at all)
        return (-math.inf, math.inf) if c <= 0.0 else None
    b = 2.0 * (wx * vx + wy * vy)
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return None
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))  # (the stable roots)
    s1 = q / a
    s2 = c / q if q != 0.0 else s1
    return (s1, s2) if s1 <= s2 else (s2, s1)


def near_samples(
    motion: Motion, t0: float, t1: float, lo: int, hi: int, px: float, py: float, reach2: float
) -> list[tuple[int, int]]:
    """Ranges [a, b) of sample indices (within [lo, hi), ascending, disjoint) outside which the
    stick's centre is farther than sqrt(reach2) from (px, py) at every one of
    :func:`sample_times` (t0, t1): where the centre's straight line(s) of :meth:`Motion.poses`
    pass within that reach, widened by a micrometre and two samples for rounding."""
    n = sample_count(t0, t1)
    hi = min(hi, n)
    if hi <= lo:
        return []
    e, ts, u = motion.est, motion.t_switch, motion.u_after
    r = math.sqrt(reach2) * (1.0 + 1e-6) + 1e-6
    if n <= 2 or not math.isfinite(px + py + r + e.x + e.y + e.vx + e.vy + e.t_ref + t0 + t1):
        return [(lo, hi)]
    step = (t1 - t0) / (n - 1)
    if not step > 0.0:
        return [(lo, hi)]
    # (t_from, t_to, the centre at t_at, its velocity, t_at): before and after t_switch
    pieces = [(-math.inf, ts, e.x, e.y, e.vx, e.vy, e.t_ref)]
    if math.isfinite(ts):
        if not math.isfinite(u[0] + u[1]):
            return [(lo, hi)]
        d = ts - e.t_ref
        pieces.append((ts, math.inf, e.x + e.vx * d, e.y + e.vy * d, u[0], u[1], ts))
    out: list[tuple[int, int]] = []
    for t_from, t_to, cx, cy, vx, vy, t_at in pieces:
        found = _span(px, py, cx, cy, vx, vy, r)
        if found is None:
            continue
        ta, tb = max(t_at + found[0], t_from), min(t_at + found[1], t_to)
        if ta > tb:
            continue
        a = lo if ta == -math.inf else max(lo, math.floor((ta - t0) / step) - 2)
        b = hi if tb == math.inf else min(hi, math.ceil((tb - t0) / step) + 3)
        if a < b:
            if out and a <= out[-1][1]:
                out[-1] = (out[-1][0], max(out[-1][1], b))
            else:
                out.append((a, b))
    return out


def covered_fixed(
    motion: Motion,
    t0: float,
    t1: float,
    lo: int,
    hi: int,
    point,
    half_length: float,
    half_width: float,
    grow: float,
    last: bool = False,
) -> int | None:
    """The first (``last``: the last) index in [lo, hi) of :func:`sample_times` (t0, t1) at
    which the fixed ``point`` is within ``grow`` of the stick rectangle (:func:`covered`), or
    None. Only the samples :func:`near_samples` finds are looked at, one at a time in order,
    each as :func:`covered` does it (the pose of :meth:`Motion.poses`, cos and sin, whose
    float64 values are libm's, as math's: test_coverage_paths.py); from one not covered, the
    samples the stick cannot reach the point by are skipped: the point's margin outside the
    grown rectangle (or the centre's distance beyond its corner reach) shrinks no faster than
    the centre's speed plus the spin times the distance."""
    px, py = float(point[0]), float(point[1])
    gl, gw = half_length + grow, half_width + grow
    r2 = corner_reach2(gl, gw)
    ranges = near_samples(motion, t0, t1, lo, hi, px, py, r2)
    if not ranges:
        return None
    e, ts, u = motion.est, motion.t_switch, motion.u_after
    x0, y0, th0, vx, vy, w, t_ref = e.x, e.y, e.theta, e.vx, e.vy, e.omega, e.t_ref
    u0, u1, u2 = u
    switches = math.isfinite(ts)
    v_max = max(math.hypot(vx, vy), math.hypot(u0, u1) if switches else 0.0)
    w_max = max(abs(w), abs(u2) if switches else 0.0)
    n = sample_count(t0, t1)
    r = math.sqrt(r2)
    step = (t1 - t0) / (n - 1) if n > 1 else 0.0
    # a sample's distance beyond the corner reach, or margin outside the grown rectangle, g:
    # the centre moves at most v_max (a sample apart: move), so no sooner than g / v_max is the
    # distance within reach; in the stick's frame the point moves at most v_max + w_max |d|,
    # and while it moves by g |d| grows by at most g, so no sooner than
    # g / (v_max + w_max (|d| + g)) is the margin gone (each a little larger: rounding)
    move = v_max * step * (1.0 + 1e-6)
    spin = w_max * step * (1.0 + 1e-6)
    if not math.isfinite(move + spin + x0 + y0 + th0 + w + u2) or step == 0.0:
        move = spin = 0.0  # (every sample looked at)
    for a, b in reversed(ranges) if last else ranges:
        i, di = (b - 1, -1) if last else (a, 1)
        while a <= i < b:
            # sample_times (np.linspace) and Motion.poses at sample i, as floats
            t = i * step + t0 if i < n - 1 and step != 0.0 else sample_time(t0, t1, i)
            ta = (t if t < ts else ts) - t_ref
            cx, cy, th = x0 + vx * ta, y0 + vy * ta, th0 + w * ta
            if switches:
                tb = t - ts
                tb = tb if tb > 0.0 else 0.0
                cx, cy, th = cx + u0 * tb, cy + u1 * tb, th + u2 * tb
            dx, dy = px - cx, py - cy
            d2 = dx * dx + dy * dy
            d = math.sqrt(d2)
            if d2 > r2:
                gap = d - r - 1e-12
                rate = move
            else:
                c, sn = math.cos(th), math.sin(th)
                xb, yb = dx * c + dy * sn, -dx * sn + dy * c
                if abs(xb) <= gl and abs(yb) <= gw:
                    return i
                gap = max(abs(xb) - gl, abs(yb) - gw) - 1e-12
                rate = move + spin * (d + gap)
            k = int(gap / rate) if rate > 0.0 and gap > 0.0 else 1
            i += di * (k if k > 1 else 1)
    return None


def first_covered(
    motion: Motion,
    t0: float,
    t1: float,
    point,
    half_length: float,
    half_width: float,
    grow: float,
    last: bool = False,
) -> float | None:
    """The first (``last``: the last) of :func:`sample_times` (t0, t1) at which the fixed
    ``point`` is within ``grow`` of the stick rectangle (:func:`covered`), or None."""
    n = sample_count(t0, t1)
    i = covered_fixed(motion, t0, t1, 0, n, point, half_length, half_width, grow, last)
    return None if i is None else sample_time(t0, t1, i)


class Coverage:
    """The stick's sweep over :func:`sample_times` (t0, t1), for many "is this fixed point ever
    covered" questions (the same answer as :func:`covered`, asked one point at a time)."""

    def __init__(self, motion: Motion, t0: float, t1: float) -> None:
        self.motion, self.t0, self.t1 = motion, t0, t1

    def hits(self, point, half_length: float, half_width: float, grow: float) -> bool:
        """``point`` within ``grow`` of the stick rectangle at some sample time."""
        m = self.motion
        return first_covered(m, self.t0, self.t1, point, half_length, half_width, grow) is not None
