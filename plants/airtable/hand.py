"""Rate-limited position servo of the slider base and the finger joints (no simulator).

Each axis (base x, base y, each joint) moves toward its target by at most ``speed * dt`` per step,
independently (paper Sec. IV-A: 1.0 m/s per slider axis, 14.0 rad/s per joint). Targets outside
the workspace or the joint ranges are clamped. The plant's step advances the servo
(:meth:`HandServo.advance`) and aims the tips at :meth:`HandServo.tip_list`.
"""

from __future__ import annotations

import numpy as np

from replay.robot.hand2d import HandSpec, clip, finger_tip_xy


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


# HandServo.state: its layout
BASE, JOINTS, BASE_TARGET, JOINT_TARGETS = slice(0, 2), slice(2, 6), slice(6, 8), slice(8, 12)
SETTLED, TIPS, TIPS_VALID = 12, slice(13, 17), 17
ROOTS, LINKS, BASE_SPEED, JOINT_SPEED, STATE_SIZE = slice(18, 22), slice(22, 24), 24, 25, 26


class HandServo:
    """Base position and joint angles of the two fingers, and their (clamped) targets.

    The state is one list of floats (``state``, the layout above: base, joints, their targets,
    whether on them, the tips' cache and the spec's kinematics and speeds; a list, not
    array("d"): read and written every step without re-boxing); ``base``,
    ``joints``, ``base_target`` and ``joint_targets`` give it as arrays."""

    def __init__(self, spec: HandSpec, base, joints) -> None:
        self.spec = spec
        self._base_lo = np.array([spec.base_limits[0][0], spec.base_limits[1][0]])
        self._base_hi = np.array([spec.base_limits[0][1], spec.base_limits[1][1]])
        self._q_lo = np.array([spec.joint_limits[0][0], spec.joint_limits[1][0]])
        self._q_hi = np.array([spec.joint_limits[0][1], spec.joint_limits[1][1]])
        # (lows, highs) of base x, y and the four joints, as floats (set_targets)
        self._limits = (
            [float(v) for v in (*self._base_lo, *self._q_lo, *self._q_lo)],
            [float(v) for v in (*self._base_hi, *self._q_hi, *self._q_hi)],
        )
        base = np.asarray(base, dtype=float)
        joints = np.asarray(joints, dtype=float).reshape(2, 2)
        s = self.state = [0.0] * STATE_SIZE
        s[BASE] = self.clamp_base(base)[0].tolist()
        s[JOINTS] = self.clamp_joints(joints)[0].ravel().tolist()
        s[BASE_TARGET], s[JOINT_TARGETS] = s[BASE], s[JOINTS]
        s[SETTLED] = 1.0  # at the targets: advance() has nothing to do
        s[TIPS_VALID] = 0.0  # the tips' cache (tip_list) not computed yet
        s[ROOTS] = [float(v) for off in spec.root_offsets for v in off]
        s[LINKS] = [float(v) for v in spec.link_lengths]
        s[BASE_SPEED], s[JOINT_SPEED] = float(spec.base_speed), float(spec.joint_speed)

    @property
    def base(self) -> np.ndarray:
        return np.array(self.state[BASE])

    @property
    def joints(self) -> np.ndarray:
        return np.array(self.state[JOINTS]).reshape(2, 2)

    @property
    def base_target(self) -> np.ndarray:
        return np.array(self.state[BASE_TARGET])

    @property
    def joint_targets(self) -> np.ndarray:
        return np.array(self.state[JOINT_TARGETS]).reshape(2, 2)

    def state_lists(self) -> tuple[list, list, list, list]:
        """(base, joints, base_target, joint_targets) as nested lists (for the state log)."""
        s = self.state
        return (
            [s[0], s[1]],
            [[s[2], s[3]], [s[4], s[5]]],
            [s[6], s[7]],
            [[s[8], s[9]], [s[10], s[11]]],
        )

    def clamp_base(self, base: np.ndarray) -> tuple[np.ndarray, bool]:
        c = np.clip(base, self._base_lo, self._base_hi)
        return c, bool(np.any(c != base))

    def clamp_joints(self, joints: np.ndarray) -> tuple[np.ndarray, bool]:
        c = np.clip(joints, self._q_lo, self._q_hi)
        return c, bool(np.any(c != joints))

    def set_targets(self, base, joints) -> dict | None:
        """Set new targets (clamped to the limits); the clamping as a dict, or None if none.
        ``base`` (x, y), ``joints`` ((q1, q2), (q1, q2)); clamped as :meth:`clamp_base` and
        :meth:`clamp_joints` do (``np.clip``), in scalars (:func:`~replay.robot.hand2d.clip`)."""
        b = [float(v) for v in base]
        q = [float(v) for row in joints for v in row]
        lo, hi = self._limits
        bc = [clip(v, lo[i], hi[i]) for i, v in enumerate(b)]
        qc = [clip(v, lo[2 + i], hi[2 + i]) for i, v in enumerate(q)]
        s = self.state
        s[BASE_TARGET], s[JOINT_TARGETS] = bc, qc
        s[SETTLED] = 0.0
        # elementwise, as np.any(c != v) (a list's == would take a NaN as equal to itself)
        base_clamped = any(c != v for c, v in zip(bc, b))
        joints_clamped = any(c != v for c, v in zip(qc, q))
        if not (base_clamped or joints_clamped):
            return None
        return {
            "base_requested": b,
            "base_target": bc,
            "joints_requested": [q[0:2], q[2:4]],
            "joint_targets": [qc[0:2], qc[2:4]],
            "base_clamped": base_clamped,
            "joints_clamped": joints_clamped,
        }

    def advance(self, dt: float) -> None:
        """One step toward the targets at the speed limits (nothing to do once on them)."""
        s = self.state
        if s[SETTLED]:
            return
        b, q = s[BASE], s[JOINTS]  # (copies)
        at_b = _toward(b, s[BASE_TARGET], s[BASE_SPEED] * dt)
        at_q = _toward(q, s[JOINT_TARGETS], s[JOINT_SPEED] * dt)
        s[BASE], s[JOINTS] = b, q
        s[TIPS_VALID] = 0.0
        s[SETTLED] = float(at_b and at_q)

    def tip_list(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """Fingertip centres ((x, y), (x, y)) (world, m) for the current base and joints (cached
        until the hand moves)."""
        s = self.state
        if not s[TIPS_VALID]:
            b, q = s[BASE], s[JOINTS]
            tips = finger_tip_xy(self.spec, b, 0, q[0:2]) + finger_tip_xy(self.spec, b, 1, q[2:4])
            s[TIPS], s[TIPS_VALID] = tips, 1.0
            t0x, t0y, t1x, t1y = tips
            self._tip_pair = (t0x, t0y), (t1x, t1y)  # (the same object until the hand moves)
        return self._tip_pair

    def tips(self) -> np.ndarray:
        """Fingertip centres (2 x 2, world, m) for the current base and joints (a copy)."""
        return np.array(self.tip_list())
