"""Rate-limited position servo of the slider base and the finger joints (no simulator).

Each axis (base x, base y, each joint) moves toward its target by at most ``speed * dt`` per step,
independently (paper Sec. IV-A: 1.0 m/s per slider axis, 14.0 rad/s per joint). Targets outside
the workspace or the joint ranges are clamped.
"""

from __future__ import annotations

import numpy as np

from replay.robot.hand2d import HandSpec, finger_tip


def _toward(current: np.ndarray, target: np.ndarray, max_delta: float) -> np.ndarray:
    """Move each entry toward its target by at most ``max_delta``; land exactly when in reach."""
    diff = target - current
    out = current + np.clip(diff, -max_delta, max_delta)
    reached = np.abs(diff) <= max_delta
    out[reached] = target[reached]
    return out


class HandServo:
    """Base position and joint angles of the two fingers, and their (clamped) targets."""

    def __init__(self, spec: HandSpec, base, joints) -> None:
        self.spec = spec
        self._base_lo = np.array([spec.base_limits[0][0], spec.base_limits[1][0]])
        self._base_hi = np.array([spec.base_limits[0][1], spec.base_limits[1][1]])
        self._q_lo = np.array([spec.joint_limits[0][0], spec.joint_limits[1][0]])
        self._q_hi = np.array([spec.joint_limits[0][1], spec.joint_limits[1][1]])
        base = np.asarray(base, dtype=float)
        joints = np.asarray(joints, dtype=float).reshape(2, 2)
        self.base, _ = self.clamp_base(base)
        self.joints, _ = self.clamp_joints(joints)
        self.base_target = self.base.copy()
        self.joint_targets = self.joints.copy()
        self._settled = True  # at the targets: advance() has nothing to do
        self._tips: np.ndarray | None = None  # tips() of the current base and joints, once computed

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
        self.base_target = base_c
        self.joint_targets = joints_c
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
        self.base = _toward(self.base, self.base_target, self.spec.base_speed * dt)
        self.joints = _toward(self.joints, self.joint_targets, self.spec.joint_speed * dt)
        self._tips = None
        self._settled = np.array_equal(self.base, self.base_target) and np.array_equal(
            self.joints, self.joint_targets
        )

    def tips(self) -> np.ndarray:
        """Fingertip centres (2 x 2, world, m) for the current base and joints (a copy)."""
        tips = self._tips
        if tips is None:
            tips = self._tips = np.array(
                [finger_tip(self.spec, self.base, k, self.joints[k]) for k in (0, 1)]
            )
        return tips.copy()
