"""What the catch-family controllers share: the arm, the hand, the measurements and the messages.

The direct mapping (:mod:`.controller`, Namiki & Ishikawa's method), the predict-then-intercept
baseline (``replay/control/predictive``) and feedback alone (``replay/control/feedback``) drive
the same arm and hand from the same sensors: the stereo ball (``/vision/object``) and the joint
encoders (``/arm/encoders``). :class:`CatchArmController` reads the spec once (the joints, three
of them moving, Sec. IV-A; the torque limits; the arm model with its catch point l(q); the PD
gains; the hand's postures and closing time), hands each stereo frame to the method (``_see``)
and keeps the joint state, and makes what they all send: the PD torque saturated at the torque
limits, the command with the hand open or closed, the ``hand_close`` event and the arm's
telemetry (``/arm/joint_command``, ``/effector/state``). A method keeps its own law: what a frame
tells it, q_d and the feed-forward, and when to close the hand.

The per-step path works on Python floats (joint vectors are lists of n floats): for 4 joints
that is faster than NumPy, and the arithmetic is the NumPy formula's, element by element.
"""

from __future__ import annotations

from abc import abstractmethod
from typing import Any

import numpy as np

from replay.control.catching.model import ArmModel, active_joints, catch_point_offset
from replay.interfaces import Controller, Occurrence
from replay.messages import (
    TOPIC_ARM_ENCODERS,
    TOPIC_ARM_JOINT_COMMAND,
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_STATE,
    TOPIC_VISION_OBJECT,
    EffectorState,
    JointCommand,
)
from replay.robot.arm_types import ArmCommand, ArmSpec


def saturated(tau, limit) -> list[float]:
    """tau saturated at +-limit (np.clip(tau, -limit, limit), the same floats)."""
    return [lim if x > lim else (-lim if x < -lim else x) for x, lim in zip(tau, limit)]


def pd_torque(ff, kp, q_d, q, kd, qd_d, qd, limit) -> list[float]:
    """tau = ff + Kp (q_d - q) + Kd (qd_d - qd), saturated at +-limit."""
    return saturated(
        [
            f + p * (a - b) + d * (c - e)
            for f, p, a, b, d, c, e in zip(ff, kp, q_d, q, kd, qd_d, qd)
        ],
        limit,
    )


class CatchArmController(Controller):
    """The set-up and plumbing of a controller that catches a ball with the arm and hand.

    Its Params must hold ``held_joints``, ``selected_joint``, ``catch_offset``, ``kp`` and ``kd``.
    """

    spec_type = ArmSpec
    command_type = ArmCommand
    reads = (TOPIC_VISION_OBJECT, TOPIC_ARM_ENCODERS)  # the stereo ball, the joint encoders

    def __init__(self, params: Any, *, spec: ArmSpec, who: str) -> None:
        """``who`` names the method in the error on a wrong set of active joints."""
        super().__init__(params, spec=spec)
        names = tuple(spec.joint_names)
        self.names, self.n = names, len(names)
        self.active = active_joints(names, params.held_joints, params.selected_joint, who)
        self.q_init = np.asarray(spec.initial_q, float).copy()
        self.tau_limit = np.asarray(spec.torque_limits, float)
        self.gravity = np.array([0.0, 0.0, -float(spec.gravity)])
        off = catch_point_offset(spec, params.catch_offset)
        self.model = ArmModel.from_chain(
            spec.model, active=self.active, q_fixed=self.q_init, point_in_tool=(0.0, 0.0, off)
        )
        self.kp = np.asarray(params.kp, float)
        self.kd = np.asarray(params.kd, float)
        if self.kp.shape != (self.n,) or self.kd.shape != (self.n,):
            raise ValueError(f"kp and kd need {self.n} values")
        self.hand = spec.hand
        self.close_time = 0.0  # s: the hand's closing, |closed - open| / closing speed
        if self.hand is not None:
            opened = np.asarray(self.hand.open_posture, float)
            closed = np.asarray(self.hand.closed_posture, float)
            self.hand_open, self.hand_closed = opened.tolist(), closed.tolist()
            self.close_time = float(np.max(np.abs(closed - opened)) / self.hand.closing_speed)
        self.closing = False
        self.q: list[float] | None = None  # the joint state (rad, rad/s); None until measured
        self.qd: list[float] | None = None
        self._events: list[Occurrence] = []
        self._kp, self._kd = self.kp.tolist(), self.kd.tolist()
        self._tau_limit = self.tau_limit.tolist()
        self._zeros = [0.0] * self.n
        self._names_seen: list[str] | None = None  # joint-name layout of the last joint state
        self._idx: list[int] | None = None  # our joints in that layout (None: taken as it is)
        self._identity = list(range(self.n))
        self._fk_desired: tuple = (None, [])  # (the q_d list it is of, l(q_d))

    # ------------------------------------------------------------------ measurements
    @abstractmethod
    def _see(self, m: Any) -> None:
        """A stereo frame of the ball (``/vision/object``: ``t``, measured ``position``)."""

    def _measure(self, measurements: list) -> None:
        for topic, m in measurements:
            if topic == TOPIC_VISION_OBJECT:
                self._see(m)
            elif topic == TOPIC_ARM_ENCODERS or topic == TOPIC_ARM_JOINT_STATE:
                self._joint_state(m)

    def _joint_state(self, m: Any) -> None:
        """q, qd from a joint state, reordered to the spec's joints where its names differ."""
        names = getattr(m, "name", None) or []
        if names != self._names_seen and list(names) != self._names_seen:  # once per layout
            self._names_seen = list(names)
            idx = (
                [names.index(n) for n in self.names]
                if names and set(self.names) <= set(names)
                else None
            )
            self._idx = idx if idx is not None and idx != self._identity else None
        idx = self._idx
        pos, vel = m.position, m.velocity
        if idx is not None:  # reordered to ours
            pos = [pos[i] for i in idx]
            vel = [vel[i] for i in idx] if len(vel) == len(names) else []
        else:
            pos, vel = list(pos), list(vel)
        if len(pos) == self.n:
            self.q, self.qd = pos, (vel if len(vel) == self.n else list(self._zeros))

    # ------------------------------------------------------------------ commands
    def _pd(self, ff, q_d: list[float], qd_d: list[float]) -> list[float]:
        """tau = ff + Kp (q_d - q) + Kd (qd_d - qd), saturated at the torque limits; before the
        first joint state the feed-forward alone, saturated."""
        q, qd = self.q, self.qd
        if q is None or qd is None:
            return saturated(ff, self._tau_limit)
        return pd_torque(ff, self._kp, q_d, q, self._kd, qd_d, qd, self._tau_limit)

    def _close_hand(self, data: dict) -> None:
        """Start closing the hand (it closes at the hand's closing speed); ``data`` says why."""
        self.closing = True
        self._events.append(Occurrence("hand_close", data))

    def _command(self, tau: list[float]) -> ArmCommand:
        """The arm's torques and, with a hand, its open or closed posture."""
        hand = None
        if self.hand is not None:
            hand = list(self.hand_closed if self.closing else self.hand_open)
        return ArmCommand(torque=list(tau), hand=hand)

    # ------------------------------------------------------------------ reporting
    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def _arm_telemetry(self, t: float, q_d: list[float], tau: list[float]) -> dict:
        """``/arm/joint_command`` (q_d, tau) and ``/effector/state`` (l(q), l(q_d)). The messages
        take the lists as they are: a caller makes new ones when they change, never in place."""
        fk_d = self._fk_desired  # l(q_d) once per desired posture
        if fk_d[0] is not q_d:
            fk_d = self._fk_desired = (q_d, list(self.model.fk_tuple(q_d)))
        q = self.q
        return {
            TOPIC_ARM_JOINT_COMMAND: JointCommand(t, q_d, tau),
            TOPIC_EFFECTOR_STATE: EffectorState(
                t, list(self.model.fk_tuple(q)) if q is not None else [], fk_d[1]
            ),
        }
