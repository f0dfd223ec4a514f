"""The stick-capture hand as data: two planar 2-joint fingers on an XY slider base (no simulator).

Higashimori et al. 2007, Sec. IV-A: sliders 400 mm x 400 mm at up to 1.0 m/s per axis; two fingers
of two joints each, up to 14.0 rad/s per joint; no orientation degree of freedom. Link lengths and
the spacing of the finger roots are not given in the paper: scenarios state the values they assume.

Frames: world (= paper's Sigma_R) on the table, z up. The palm is parallel to the world x axis;
finger k's root is at ``base + root_offset[k]``; its tip centre is at
``root + l1 (cos q1, sin q1) + l2 (cos(q1 + q2), sin(q1 + q2))``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class StickSpec:
    """What the method may know of the object (paper Assumptions 7 and 10): not the friction."""

    mass: float  # kg
    inertia: float  # kg*m^2 about the centre of mass
    length: float  # m
    width: float  # m (the analysis takes it as ~0, Assumption 5)
    restitution: float  # Newton's e, eq. 2


@dataclass(frozen=True)
class HandSpec:
    root_offsets: tuple[tuple[float, float], tuple[float, float]]  # m, from the base
    link_lengths: tuple[float, float]  # l1, l2 (m), both fingers
    joint_limits: tuple[tuple[float, float], tuple[float, float]]  # (q1 lo, hi), (q2 lo, hi) rad
    joint_speed: float  # rad/s, each joint
    base_limits: tuple[tuple[float, float], tuple[float, float]]  # (x lo, hi), (y lo, hi) m
    base_speed: float  # m/s, each slider axis
    tip_radius: float  # m, fingertip disc radius
    start_base: tuple[float, float] = (0.0, 0.0)  # m, where the hand is homed at t = 0
    start_joints: tuple[tuple[float, float], tuple[float, float]] = ((0.0, 0.0), (0.0, 0.0))


@dataclass(frozen=True)
class AirTableSpec:
    hand: HandSpec
    stick: StickSpec


@dataclass(frozen=True)
class HandCommand:
    """Position targets; the plant moves toward them no faster than the spec's speed limits."""

    base: tuple[float, float]  # m
    joints: tuple[tuple[float, float], tuple[float, float]]  # rad, (q1, q2) per finger


def clip(v: float, lo: float, hi: float) -> float:
    """``np.clip`` of arrays, for one float: NumPy's clip loop (max, then min, each keeping a
    NaN ``v``, and ``v`` unless strictly beyond the limit: -0.0 at a limit 0.0 becomes the
    limit), without NumPy's call overhead (~5 us)."""
    m = v if (v > lo or v != v) else lo
    return m if (m < hi or m != m) else hi


def clip_scalar(v: float, lo: float, hi: float) -> float:
    """``float(np.clip(np.float64(v), lo, hi))`` with float limits: as :func:`clip` but ``v``
    kept when equal to a limit (NumPy's scalar path: -0.0 at a limit 0.0 stays -0.0)."""
    m = v if (v >= lo or v != v) else lo
    return m if (m <= hi or m != m) else hi


def _chain(base, root_offset, link_lengths, q) -> tuple[tuple[float, float], ...]:
    l1, l2 = link_lengths
    root = (base[0] + root_offset[0], base[1] + root_offset[1])
    elbow = (root[0] + l1 * math.cos(q[0]), root[1] + l1 * math.sin(q[0]))
    tip = (elbow[0] + l2 * math.cos(q[0] + q[1]), elbow[1] + l2 * math.sin(q[0] + q[1]))
    return root, elbow, tip


def finger_chain(base, root_offset, link_lengths, q) -> np.ndarray:
    """Root, elbow and tip centre (3 x 2, world, m) of a finger with joints ``q = (q1, q2)``."""
    return np.array(_chain(base, root_offset, link_lengths, q))


def finger_tip_xy(hand: HandSpec, base, k: int, q) -> tuple[float, float]:
    """:func:`finger_tip` as a tuple of floats (no array: for per-step use)."""
    return _chain(base, hand.root_offsets[k], hand.link_lengths, q)[2]


def finger_tip(hand: HandSpec, base, k: int, q) -> np.ndarray:
    """Tip centre of finger ``k`` (world, m) for base position and joints ``q = (q1, q2)``."""
    return np.array(finger_tip_xy(hand, base, k, q))


def finger_ik(hand: HandSpec, base, k: int, tip, q_near=None):
    """Joints putting finger ``k``'s tip at ``tip`` (world), or None when out of reach or limits.

    Of the two elbow solutions within the joint limits, the one nearest ``q_near`` is returned.
    """
    l1, l2 = hand.link_lengths
    rx, ry = hand.root_offsets[k]
    dx, dy = tip[0] - base[0] - rx, tip[1] - base[1] - ry
    c2 = (dx * dx + dy * dy - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)
    if c2 < -1.0 - 1e-12 or c2 > 1.0 + 1e-12:
        return None
    c2 = min(1.0, max(-1.0, c2))
    best = None
    (lo1, hi1), (lo2, hi2) = hand.joint_limits
    for sign in (1.0, -1.0):
        q2 = sign * math.acos(c2)
        q1 = math.atan2(dy, dx) - math.atan2(l2 * math.sin(q2), l1 + l2 * math.cos(q2))
        q1 = (q1 + math.pi) % (2.0 * math.pi) - math.pi
        q = (q1, q2)
        if not (lo1 - 1e-9 <= q1 <= hi1 + 1e-9 and lo2 - 1e-9 <= q2 <= hi2 + 1e-9):
            continue
        cost = 0.0 if q_near is None else abs(q1 - q_near[0]) + abs(q2 - q_near[1])
        if best is None or cost < best[0]:
            best = (cost, q)
    return None if best is None else best[1]


def travel_time(hand: HandSpec, base_from, base_to, joints_from, joints_to) -> float:
    """Least time (s) to move base and joints between two configurations at the speed limits
    (every axis moves independently at its own limit)."""
    (x0, y0), (x1, y1) = base_from, base_to
    ((a0, b0), (c0, d0)), ((a1, b1), (c1, d1)) = joints_from, joints_to
    t_base = max(abs(x1 - x0), abs(y1 - y0)) / hand.base_speed
    t_joint = max(abs(a1 - a0), abs(b1 - b0), abs(c1 - c0), abs(d1 - d0))
    return max(t_base, t_joint / hand.joint_speed)


def root_distance(hand: HandSpec, point) -> float:
    """Least distance (m) from ``point`` to a finger root anywhere on the slider's range (0 when a
    root can be right under it): with ``sum(link_lengths)`` a loose bound of what can be reached."""
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    best = math.inf
    for ox, oy in hand.root_offsets:
        dx = max(xlo + ox - point[0], 0.0, point[0] - xhi - ox)
        dy = max(ylo + oy - point[1], 0.0, point[1] - yhi - oy)
        best = min(best, math.hypot(dx, dy))
    return best
