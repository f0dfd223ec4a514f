"""A catching controller from a file, no packaging: ``examples/my_controller.yaml`` names it
``type: my_controller:GoalKeeper``, and the loader imports this file from the scenario's folder.

    .venv/bin/replay run examples/my_controller.yaml -o out/keeper.mcap
    .venv/bin/replay run catch_optimised --set controller.type=my_controller:GoalKeeper

(the second from the folder holding this file). Not a paper's method: the arm moves to and holds
a posture (joint PD plus the nominal model's gravity torque) and the hand closes once the ball,
as the stereo cameras see it, comes within ``close_distance`` of the palm. It publishes no
``/effector/state``, so the catching paper's figures and claims that read it say they skipped
it (docs/catching.md lists the topics each one reads).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replay.interfaces import Controller, Occurrence
from replay.messages import TOPIC_ARM_ENCODERS, TOPIC_VISION_OBJECT
from replay.params import param
from replay.robot.arm_types import ArmCommand, ArmSpec


@dataclass
class GoalKeeperParams:
    hold_q: list = param(
        [0.0, 0.7853981634, 0.0, 1.5707963268],
        unit="rad",
        length=4,
        doc="the posture held (the paper's catch posture: the palm where the throw arrives)",
    )
    kp: float = param(400.0, unit="N*m/rad", ge=0, doc="PD stiffness of every joint")
    kd: float = param(20.0, unit="N*m*s/rad", ge=0, doc="PD damping of every joint")
    close_distance: float = param(
        0.12, unit="m", gt=0, doc="close the hand when the seen ball is this near the palm"
    )


class GoalKeeper(Controller):
    Params = GoalKeeperParams
    spec_type = ArmSpec
    command_type = ArmCommand
    reads = (TOPIC_VISION_OBJECT, TOPIC_ARM_ENCODERS)
    description = "holds still, closes the hand when the ball is near the palm"

    def __init__(self, params: GoalKeeperParams, *, spec: ArmSpec) -> None:
        super().__init__(params, spec=spec)
        self.q_hold = np.asarray(params.hold_q, float)
        self.limit = np.asarray(spec.torque_limits, float)
        self.palm = spec.model.fk(self.q_hold)[:3, 3]  # the tool frame's origin, held there
        self.q = np.asarray(spec.initial_q, float)
        self.qd = np.zeros_like(self.q)
        self.closing = False
        self._events: list[Occurrence] = []

    def update(self, t: float, measurements: list) -> ArmCommand:
        for topic, m in measurements:
            if topic == TOPIC_ARM_ENCODERS:
                self.q = np.asarray(m.position, float)
                self.qd = np.asarray(m.velocity, float)
            elif topic == TOPIC_VISION_OBJECT and not self.closing:
                d = float(np.linalg.norm(np.asarray(m.position, float) - self.palm))
                if d <= self.params.close_distance:
                    self.closing = True
                    self._events.append(Occurrence("hand_close", {"distance": d}))
        P = self.params
        tau = (
            self.spec.model.gravity_torque(self.q) + P.kp * (self.q_hold - self.q) - P.kd * self.qd
        )
        hand = self.spec.hand
        posture = None
        if hand is not None:
            posture = list(hand.closed_posture if self.closing else hand.open_posture)
        return ArmCommand(torque=np.clip(tau, -self.limit, self.limit).tolist(), hand=posture)

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict:
        return {"hand_closed": self.closing}
