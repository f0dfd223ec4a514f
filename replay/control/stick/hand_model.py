"""The hand as the stick-capture controllers model it: configurations, the open-loop motion
model, and the candidate bases and postures the planners try.

Higashimori et al. 2007, Sec. IV-A: two fingers with two joints each on x-y sliders, no degree of
freedom for the hand's orientation. The paper neglects the links and the arm (Assumption 9) and
gives no equations for them; the kinematics are ``replay.robot.hand2d``'s (``finger_tip``,
``finger_ik``, ``travel_time``) with the limits of the :class:`~replay.robot.hand2d.HandSpec`.

The controllers have no hand feedback. They track their own commands with the plant's motion
model: every axis moves toward its target at its speed limit, from where the spec says the hand
was homed. :class:`HandModel` follows it in time; :func:`route_configs` and :func:`route_tips`
sample it along a planned route of waypoints [(t_start, Config)] (:func:`route_target`) for the
planner's route check (``ContactPlanner.route_clear``).

Pure NumPy.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from replay.robot import hand2d
from replay.robot.hand2d import HandCommand, HandSpec


# ------------------------------------------------------------------------------------------
# Hand configurations and the open-loop hand model
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True, init=False)
class Config:
    base: tuple  # (x, y) m
    joints: tuple  # ((q1, q2), (q1, q2)) rad

    def __init__(self, base: tuple, joints: tuple) -> None:
        # the fields straight into the instance's dict (a frozen dataclass's generated __init__ sets
        # each through object.__setattr__, ~1 us a field on Python 3.11; test_stick_fast_paths.py
        # holds this one to the generated one's result)
        d = self.__dict__
        d["base"], d["joints"] = base, joints

    def with_finger(self, k: int, q) -> "Config":
        j = [tuple(self.joints[0]), tuple(self.joints[1])]
        j[k] = (float(q[0]), float(q[1]))
        return Config(self.base, tuple(j))

    def tip(self, hand: HandSpec, k: int) -> np.ndarray:
        return hand2d.finger_tip(hand, self.base, k, self.joints[k])

    @functools.cached_property
    def command(self) -> HandCommand:
        """This configuration as the plant's command (made once per configuration)."""
        (a1, a2), (b1, b2) = self.joints  # the two fingers' (q1, q2)
        return HandCommand(
            base=(float(self.base[0]), float(self.base[1])),
            joints=((float(a1), float(a2)), (float(b1), float(b2))),
        )


def travel(hand: HandSpec, a: Config, b: Config) -> float:
    return hand2d.travel_time(hand, a.base, b.base, a.joints, b.joints)


class HandModel:
    """Where the hand is, assuming each axis moves to its target at its speed limit."""

    def __init__(self, hand: HandSpec, start: Config) -> None:
        self.hand = hand
        self.config = start
        self.target = start
        self._t: float | None = None

    def advance(self, t: float) -> None:
        now, target = self.config, self.target
        # (Config equality field by field: what the dataclass's == compares, without its tuples)
        if (
            self._t is not None
            and t > self._t
            and now is not target
            and (now.base != target.base or now.joints != target.joints)
        ):
            dt = t - self._t
            sb = self.hand.base_speed * dt
            sq = self.hand.joint_speed * dt
            (x, y), ((a, b), (c, d)) = now.base, now.joints
            (tx, ty), ((ta, tb), (tc, td)) = target.base, target.joints
            moved = Config(
                (x + min(sb, max(-sb, tx - x)), y + min(sb, max(-sb, ty - y))),
                (
                    (a + min(sq, max(-sq, ta - a)), b + min(sq, max(-sq, tb - b))),
                    (c + min(sq, max(-sq, tc - c)), d + min(sq, max(-sq, td - d))),
                ),
            )
            # on the target: the target itself (equal numbers), so later ticks see it at once
            same = moved.base == target.base and moved.joints == target.joints
            self.config = target if same else moved
        self._t = t


# ------------------------------------------------------------------------------------------
# Routes: waypoints [(t_start, Config)] and the hand's motion along them
# ------------------------------------------------------------------------------------------


def route_target(route: list, t: float, default: Config) -> Config:
    """The waypoint of [(t_start, Config)] to command at time ``t``."""
    out = route[0][1] if route else default
    for t_start, cfg in route:
        if t >= t_start:
            out = cfg
    return out


def route_configs(hand: HandSpec, starts, frm, to, times):
    """Base (T, 2) and joints (T, 2, 2) along waypoint segments, each axis moving toward its
    target at its speed limit (the plant's motion model). ``times`` ascending; segment i covers
    starts[i] <= t < starts[i + 1] (the first one also what comes before its start)."""
    out = route_axes(hand, starts, frm, to, times)
    return out[:, :2], out[:, 2:].reshape(-1, 2, 2)


@functools.lru_cache(maxsize=16)
def _axis_speeds(base_speed: float, joint_speed: float) -> np.ndarray:
    """The six axes' speed limits (base x, y, the four joints), made once (read only)."""
    speed = np.array([base_speed] * 2 + [joint_speed] * 4)
    speed.flags.writeable = False
    return speed


def route_axes(hand: HandSpec, starts, frm, to, times) -> np.ndarray:
    """:func:`route_configs` as one (T, 6) array: base x, y, then the four joints."""
    times = np.asarray(times, dtype=float)
    out = np.empty((len(times), 6))  # base x, y, then the four joints
    speed = _axis_speeds(hand.base_speed, hand.joint_speed)
    # first sample at or after each start (one segment, the straight route: none needed)
    edges = np.searchsorted(times, starts, side="left").tolist() if len(starts) > 1 else [0]
    for i, (s0, a, b) in enumerate(zip(starts, frm, to)):
        lo = 0 if i == 0 else int(edges[i])
        hi = int(edges[i + 1]) if i + 1 < len(starts) else len(times)
        if hi <= lo:
            continue
        tau = np.maximum(times[lo:hi] - s0, 0.0)[:, None]
        va = np.array([*a.base, *a.joints[0], *a.joints[1]], dtype=float)
        vb = np.array([*b.base, *b.joints[0], *b.joints[1]], dtype=float)
        step = tau * speed
        out[lo:hi] = va + np.minimum(np.maximum(vb - va, -step), step)  # clip
    return out


def route_tips(hand: HandSpec, base, joints) -> np.ndarray:
    """Fingertip centres (T, 2 fingers, 2) for bases (T, 2) and joints (T, 2, 2)."""
    l1, l2 = hand.link_lengths
    out = np.empty(np.shape(joints))
    q1, q12 = joints[..., 0], joints[..., 0] + joints[..., 1]
    out[..., 0] = l1 * np.cos(q1) + l2 * np.cos(q12)
    out[..., 1] = l1 * np.sin(q1) + l2 * np.sin(q12)
    out += np.array(hand.root_offsets)[None, :, :] + np.asarray(base)[:, None, :]  # the roots
    return out


def finger_tips(hand: HandSpec, axes: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Finger k's tip centres (x, y arrays) for rows of :func:`route_axes`: :func:`route_tips`'
    values for that finger alone."""
    l1, l2 = hand.link_lengths
    q1 = axes[:, 2 + 2 * k]
    q12 = q1 + axes[:, 3 + 2 * k]
    rx, ry = hand.root_offsets[k]
    x = l1 * np.cos(q1) + l2 * np.cos(q12)
    y = l1 * np.sin(q1) + l2 * np.sin(q12)
    x += rx + axes[:, 0]  # (the root: its offset + the base, as route_tips adds them)
    y += ry + axes[:, 1]
    return x, y


# ------------------------------------------------------------------------------------------
# Candidates for the planners' inverse-kinematics search
# ------------------------------------------------------------------------------------------


def posture_grid(hand: HandSpec) -> list[tuple]:
    """5 x 5 finger postures (q1, q2) spanning the joint limits (for an idle finger)."""
    (a0, a1), (b0, b1) = hand.joint_limits
    return [
        (float(q1), float(q2)) for q1 in np.linspace(a0, a1, 5) for q2 in np.linspace(b0, b1, 5)
    ]


def base_candidates(hand: HandSpec, k: int, tip, here: tuple) -> list[tuple]:
    """The current base ``here`` (when the tip is comfortably within reach from it, so later
    refinements stay reachable), then bases putting finger k's root below the tip at a few
    comfortable reaches and angles (clamped to the slider range)."""
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    root = np.array(hand.root_offsets[k])
    reach = sum(hand.link_lengths)
    out = []
    if np.linalg.norm(np.asarray(tip) - root - np.array(here)) <= 0.85 * reach:
        out.append(here)
    # (tip - root - rho (cos a, sin a)) clipped to the range, in scalars: NumPy's operations
    tx, ty = float(tip[0]) - float(root[0]), float(tip[1]) - float(root[1])
    for rho in (0.7 * reach, 0.5 * reach, 0.85 * reach):
        for deg in (90.0, 65.0, 115.0, 40.0, 140.0):
            a = math.radians(deg)
            bx, by = tx - rho * math.cos(a), ty - rho * math.sin(a)
            out.append((hand2d.clip_scalar(bx, xlo, xhi), hand2d.clip_scalar(by, ylo, yhi)))
    return out


def close_bases(hand: HandSpec, F, Rr, front: int, rear: int, here: tuple) -> list[tuple]:
    """The current base ``here``, then bases putting the two finger roots' midpoint below the
    midpoint of the fingertip spots F (front) and Rr (rear) at a few reaches and sideways
    offsets (clamped to the slider range)."""
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    mid = 0.5 * (np.asarray(F) + np.asarray(Rr))
    roots = 0.5 * (np.array(hand.root_offsets[front]) + np.array(hand.root_offsets[rear]))
    reach = sum(hand.link_lengths)
    out = [here]
    for frac in (0.7, 0.55, 0.85, 0.4):
        for dx in (0.0, -0.03, 0.03):
            b = mid - roots - np.array([dx, frac * reach])
            out.append((float(np.clip(b[0], xlo, xhi)), float(np.clip(b[1], ylo, yhi))))
    return out
