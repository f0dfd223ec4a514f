"""The stick's predicted motion and the area it sweeps, for the stick-capture planners.

Higashimori et al. 2007: between collisions the stick moves with constant velocities
(Assumption 6), those of the estimator's fit; after a planned contact it moves with the
velocities the contact solution predicts, u_i = J_i u_{i-1} (eq. 22). A point is covered by the
stick when it lies within a margin of the spec's L x W rectangle (W may be 0, the paper's
Assumption 5). The planners sample the sweep every ``SAMPLE_DT``.

NumPy: each check one vectorised pass over the samples (:func:`covered`, :func:`covered_along`).
The sampled checks the planners repeat most (:func:`first_covered`, ``ContactPlanner
.route_clear``) have an optional compiled accelerator (``_sweep.c``, ``replay.accel``: the same
operations element by element, held to these NumPy paths by
tests/replay/control/stick/test_sweep_kernel.py): ~20 % of a stick_3step run.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from replay.accel import accelerator
from replay.control.stick.estimator import StickEstimate

_sweep = accelerator("replay.control.stick._sweep")

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

    @functools.cached_property
    def packed(self) -> tuple:
        """(x, y, theta, vx, vy, omega, t_ref, t_switch, u0, u1, u2): the accelerator's motion."""
        e, u = self.est, self.u_after
        return (
            float(e.x),
            float(e.y),
            float(e.theta),
            float(e.vx),
            float(e.vy),
            float(e.omega),
            float(e.t_ref),
            float(self.t_switch),
            float(u[0]),
            float(u[1]),
            float(u[2]),
        )

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
    if _sweep is not None:
        found = _sweep.covered_index(
            motion.packed,
            float(t0),
            float(t1),
            sample_count(t0, t1),
            float(point[0]),
            float(point[1]),
            half_length,
            half_width,
            grow,
            last,
        )
        return None if found is None else found[1]
    times = sample_times(t0, t1)
    hit = np.flatnonzero(covered(motion, times, [point], half_length, half_width, grow)[:, 0])
    if not hit.size:
        return None
    return float(times[hit[-1] if last else hit[0]])


class Sweep:
    """The stick's sweep over :func:`sample_times` (t0, t1), for many "is this fixed point ever
    covered" questions (the same answer as :func:`covered`, asked one point at a time)."""

    def __init__(self, motion: Motion, t0: float, t1: float) -> None:
        self.motion, self.t0, self.t1 = motion, t0, t1

    def hits(self, point, half_length: float, half_width: float, grow: float) -> bool:
        """``point`` within ``grow`` of the stick rectangle at some sample time."""
        m = self.motion
        return first_covered(m, self.t0, self.t1, point, half_length, half_width, grow) is not None
