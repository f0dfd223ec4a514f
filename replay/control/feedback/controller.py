"""Feedback-only catching: servo the arm to the ball where it is seen now, nothing more.

Not Namiki & Ishikawa's method but the "simple feedback control" they say cannot catch a ball
at 8-10 m/s (Sec. IV-B; Sec. I: "feedback control based on a position error between an end
effector and target"). Each control step it

1. takes the latest stereo position r_o (no filter, no prediction, no trajectory);
2. maps it to the posture that points the palm at it on the same catch geometry as the direct
   mapping, q_o = l_c^-1(r_o) (``CatchGeometry.inverse``, eqs. 2-3; q3 held), i.e. the direct
   mapping with b(q) = 0 and without its feedforward;
3. applies joint PD toward q_o with gravity compensation only (no q̇_d, q̈_d, no inverse
   dynamics of a planned motion), saturated at the torque limits;
4. closes the hand when the measured ball is within ``close_distance`` of the catch point l(q).

Pure NumPy: it sees the stereo measurement and the arm's encoders, and the spec.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.control.catching.mapping import CatchGeometry
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
from replay.params import param
from replay.robot.arm_types import ArmCommand, ArmSpec


@dataclass
class FeedbackParams:
    q_alpha: float = param(
        math.pi / 2,
        unit="rad",
        doc="selected joint's angle on the catch surface (as the mapping's)",
    )
    selected_joint: str = param("J4", doc="the joint at q_alpha on the catch surface")
    held_joints: list = param(["J3"], doc="joints held at their initial angle")
    catch_q: list = param(
        [0.0, math.pi / 4], unit="rad", length=2, doc="(q1, q2) the inverse prefers (branch)"
    )
    catch_offset: float = param(
        -1.0,
        unit="m",
        doc="catch point this far along the tool z axis; negative = palm thickness + ball radius",
    )
    kp: list = param(
        [900.0, 1500.0, 300.0, 150.0],
        unit="N*m/rad",
        ge=0.0,
        doc="PD stiffness per arm joint (as the direct controller's)",
    )
    kd: list = param(
        [30.0, 45.0, 10.0, 4.0],
        unit="N*m*s/rad",
        ge=0.0,
        doc="PD damping per arm joint (as the direct controller's)",
    )
    close_distance: float = param(
        0.15,
        unit="m",
        gt=0.0,
        doc="close the hand when the seen ball is this near the catch point (our choice: "
        "at 9 m/s about the 20 ms the fingers take)",
    )


Params = FeedbackParams


class FeedbackController(Controller):
    Params = FeedbackParams
    spec_type = ArmSpec
    command_type = ArmCommand
    reads = (TOPIC_VISION_OBJECT, TOPIC_ARM_ENCODERS)
    description = (
        "feedback only: joint PD toward l_c^-1 of the ball as seen now, gravity compensated"
    )

    def __init__(self, params: FeedbackParams, *, spec) -> None:
        super().__init__(params, spec=spec)
        P = params
        names = tuple(spec.joint_names)
        self.names = names
        self.n = len(names)
        self.active = active_joints(names, P.held_joints, P.selected_joint, "the feedback baseline")
        self.q_init = np.asarray(spec.initial_q, float).copy()
        self.tau_limit = np.asarray(spec.torque_limits, float)
        off = catch_point_offset(spec, P.catch_offset)
        self.model = ArmModel.from_chain(
            spec.model, active=self.active, q_fixed=self.q_init, point_in_tool=(0.0, 0.0, off)
        )
        self.geo = CatchGeometry.from_fk(self.model.fk, P.q_alpha, p_ref=tuple(P.catch_q))
        self.kp = np.asarray(P.kp, dtype=float)
        self.kd = np.asarray(P.kd, dtype=float)
        if self.kp.shape != (self.n,) or self.kd.shape != (self.n,):
            raise ValueError(f"kp and kd need {self.n} values")
        self.hand = spec.hand
        if self.hand is not None:
            self.hand_open = np.asarray(self.hand.open_posture, float).tolist()
            self.hand_closed = np.asarray(self.hand.closed_posture, float).tolist()
        self.q: np.ndarray | None = None
        self.qd: np.ndarray | None = None
        self.r_o: np.ndarray | None = None
        self.q_d = self.q_init.copy()
        self.tau = np.zeros(self.n)
        self.closing = False
        self._events: list[Occurrence] = []

    def update(self, t: float, measurements: list) -> ArmCommand:
        for topic, m in measurements:
            if topic == TOPIC_VISION_OBJECT:
                self.r_o = np.asarray(m.position, float)
            elif topic in (TOPIC_ARM_ENCODERS, TOPIC_ARM_JOINT_STATE):
                self._joint_state(m)
        if self.r_o is not None:
            inv = self.geo.inverse(self.r_o)
            if bool(inv.in_domain[0]) and np.all(np.isfinite(inv.p[0])):
                self.q_d = self.model.full(inv.p[0])
        if (
            self.hand is not None
            and not self.closing
            and self.r_o is not None
            and self.q is not None
        ):
            d = float(np.linalg.norm(self.r_o - self.model.fk(self.q)))
            if d <= self.params.close_distance:
                self.closing = True
                self._events.append(Occurrence("hand_close", {"distance": d}))
        self.tau = self._torque()
        hand = None
        if self.hand is not None:
            hand = list(self.hand_closed if self.closing else self.hand_open)
        return ArmCommand(torque=self.tau.tolist(), hand=hand)

    def _joint_state(self, m) -> None:
        pos, vel = np.asarray(m.position, float), np.asarray(m.velocity, float)
        names = list(getattr(m, "name", []) or [])
        if names and set(self.names) <= set(names):
            idx = [names.index(n) for n in self.names]
            pos, vel = pos[idx], vel[idx]
        if pos.shape == (self.n,):
            self.q, self.qd = pos, (vel if vel.shape == (self.n,) else np.zeros(self.n))

    def _torque(self) -> np.ndarray:
        zero = np.zeros(self.n)
        if self.q is None or self.qd is None:
            ff = self.model.inverse_dynamics_full(self.q_d, zero, zero)
            return np.clip(ff, -self.tau_limit, self.tau_limit)
        ff = self.model.inverse_dynamics_full(self.q, zero, zero)  # gravity at the posture
        tau = ff + self.kp * (self.q_d - self.q) - self.kd * self.qd
        return np.clip(tau, -self.tau_limit, self.tau_limit)

    def intent(self) -> dict:
        return {"method": "feedback", "hand_closing": self.closing}

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict:
        return {"hand_closed": self.closing}

    def telemetry(self, t: float) -> dict:
        return {
            TOPIC_ARM_JOINT_COMMAND: JointCommand(
                t, position=self.q_d.tolist(), torque=self.tau.tolist()
            ),
            TOPIC_EFFECTOR_STATE: EffectorState(
                t,
                position=self.model.fk(self.q).tolist() if self.q is not None else [],
                desired_position=self.model.fk(self.q_d).tolist(),
            ),
        }
