"""Rate-limited position servo of the slider base and the finger joints (no simulator).

Each axis (base x, base y, each joint) moves toward its target by at most ``speed * dt`` per step,
independently (paper Sec. IV-A: 1.0 m/s per slider axis, 14.0 rad/s per joint). Targets outside
the workspace or the joint ranges are clamped.
"""

from __future__ import annotations

import numpy as np

from replay.robot.hand2d import HandSpec, finger_tip_xy


def _toward(current: list, target: list, max_delta: float) -> bool:
    """Move each entry of ``current`` (in place) toward its target by at most ``max_delta``;
    land exactly when in reach. True when every entry is on its target."""
    done = True
    for i, (c, g) in enumerate(zip(current, target)):
        d = g - c
        if abs(d) <= max_delta:
            current[i] = g
        else:
            current[i] = c + max_delta if d > 0.0 else c - max_delta
            done = False
    return done


class HandServo:
    """Base position and joint angles of the two fingers, and their (clamped) targets.

    The state is kept as Python floats (one step is six scalar moves); ``base``, ``joints``,
    ``base_target`` and ``joint_targets`` give it as arrays."""

    def __init__(self, spec: HandSpec, base, joints) -> None:
        self.spec = spec
        self._base_lo = np.array([spec.base_limits[0][0], spec.base_limits[1][0]])
        self._base_hi = np.array([spec.base_limits[0][1], spec.base_limits[1][1]])
        self._q_lo = np.array([spec.joint_limits[0][0], spec.joint_limits[1][0]])
        self._q_hi = np.array([spec.joint_limits[0][1], spec.joint_limits[1][1]])
        base = np.asarray(base, dtype=float)
        joints = np.asarray(joints, dtype=float).reshape(2, 2)
        self._b = self.clamp_base(base)[0].tolist()  # [x, y]
        self._q = self.clamp_joints(joints)[0].ravel().tolist()  # [q1, q2, q1, q2]
        self._b_target, self._q_target = list(self._b), list(self._q)
        self._settled = True  # at the targets: advance() has nothing to do
        self._tips: tuple | None = None  # tip_list() of the current base and joints, once computed

    @property
    def base(self) -> np.ndarray:
        return np.array(self._b)

    @property
    def joints(self) -> np.ndarray:
        return np.array(self._q).reshape(2, 2)

    @property
    def base_target(self) -> np.ndarray:
        return np.array(self._b_target)

    @property
    def joint_targets(self) -> np.ndarray:
        return np.array(self._q_target).reshape(2, 2)

    def state_lists(self) -> tuple[list, list, list, list]:
        """(base, joints, base_target, joint_targets) as nested lists (for the state log)."""
        q, qt = self._q, self._q_target
        return list(self._b), [q[0:2], q[2:4]], list(self._b_target), [qt[0:2], qt[2:4]]

    def clamp_base(self, base: np.ndarray) -> tuple[np.ndarray, bool]:
        c = np.clip(base, self._base_lo, self._base_hi)
        return c, bool(np.any(c != base))

    def clamp_joints(self, joints: np.ndarray) -> tuple[np.ndarray, bool]:
        c = np.clip(joints, self._q_lo, self._q_hi)
        return c, bool(np.any(c != joints))

    def set_targets(self, base, joints) -> dict | None:
        """Set new targets (clamped to the limits); the clamping as a dict, or None if none."""
        base = np.asarray(base, dtype=float)
        joints = np.asarray(joints, dtype=float).reshape(2, 2)
        base_c, base_clamped = self.clamp_base(base)
        joints_c, joints_clamped = self.clamp_joints(joints)
        self._b_target = base_c.tolist()
        self._q_target = joints_c.ravel().tolist()
        self._settled = False
        if not (base_clamped or joints_clamped):
            return None
        return {
            "base_requested": base.tolist(),
            "base_target": base_c.tolist(),
            "joints_requested": joints.tolist(),
            "joint_targets": joints_c.tolist(),
            "base_clamped": base_clamped,
            "joints_clamped": joints_clamped,
        }

    def advance(self, dt: float) -> None:
        """One step toward the targets at the speed limits (nothing to do once on them)."""
        if self._settled:
            return
        at_b = _toward(self._b, self._b_target, self.spec.base_speed * dt)
        at_q = _toward(self._q, self._q_target, self.spec.joint_speed * dt)
        self._tips = None
        self._settled = at_b and at_q

    def tip_list(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Fingertip centres ((x, y), (x, y)) (world, m) for the current base and joints (cached
        until the hand moves)."""
        tips = self._tips
        if tips is None:
            b, q = self._b, self._q
            tips = self._tips = (
                finger_tip_xy(self.spec, b, 0, q[0:2]),
                finger_tip_xy(self.spec, b, 1, q[2:4]),
            )
        return tips

    def tips(self) -> np.ndarray:
        """Fingertip centres (2 x 2, world, m) for the current base and joints (a copy)."""
        return np.array(self.tip_list())
