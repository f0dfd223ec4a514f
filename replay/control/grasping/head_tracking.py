"""Tracking control of the active vision (Namiki et al. 1999, Sec. 4.1.2, eq. 1), pure NumPy:

    theta_dot_d^v = K^v J_image^-1 (xi_d - xi) - K^vv theta_dot^v                    (1)

J_image = d xi / d theta^v is the head model's (recognition publishes it with each frame, at
the estimated object point and the head angles of that frame). Without a target the head is
only damped (the second term).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from replay.control.grasping.payloads import HeadLoop
from replay.interfaces import Controller
from replay.messages import TOPIC_GRASP_HEAD, TOPIC_GRASP_OBJECT, TOPIC_HEAD_ENCODERS
from replay.params import param
from replay.robot.arm_types import GraspSpec, ServoCommand


@dataclass
class HeadParams:
    K_v: list = param(
        [60.0, 60.0],
        unit="1/s",
        length=2,
        ge=0.0,
        doc="eq. 1's K^v (diagonal): image error to head rate (assumed)",
    )
    K_vv: list = param(
        [0.02, 0.02],
        unit="1",
        length=2,
        ge=0.0,
        doc="eq. 1's K^vv (diagonal): damping of the head's rate (assumed)",
    )
    xi_d: list = param([], unit="px", doc="objective image position; [] = the image centre")
    width: int = param(16, unit="px", ge=2, doc="chip width (for the default xi_d)")
    height: int = param(16, unit="px", ge=2, doc="chip height")


class HeadTrackingTask(Controller):
    """Eq. 1: active-vision tracking with the head model's image Jacobian."""

    Params = HeadParams
    spec_type = GraspSpec
    command_type = ServoCommand
    reads = (TOPIC_GRASP_OBJECT, TOPIC_HEAD_ENCODERS)
    description = "eq. 1: active-vision tracking with the head's image Jacobian"

    def __init__(self, params: HeadParams, *, spec: GraspSpec) -> None:
        super().__init__(params, spec=spec)
        self.xi_d = (
            np.asarray(params.xi_d, float)
            if params.xi_d
            else np.array([(params.width - 1) / 2.0, (params.height - 1) / 2.0])
        )
        self.K_v, self.K_vv = np.asarray(params.K_v, float), np.asarray(params.K_vv, float)
        if spec.head is None:
            raise ValueError("head tracking needs a plant with a head")
        self.limit = np.asarray(spec.head.velocity_limit, float)
        self.rate = np.zeros(2)
        self.obj: Any = None
        self._out: HeadLoop | None = None

    def update(self, t: float, measurements) -> ServoCommand:
        for topic, m in measurements:
            if topic == TOPIC_HEAD_ENCODERS:
                self.rate = np.asarray(m.velocity, float)
            elif topic == TOPIC_GRASP_OBJECT:
                self.obj = m
        err = np.zeros(2)
        cmd = -self.K_vv * self.rate
        if self.obj is not None and self.obj.found:
            err = self.xi_d - np.asarray(self.obj.xi, float)
            cmd = self.K_v * np.linalg.solve(np.asarray(self.obj.jacobian, float), err) + cmd
        cmd = np.clip(cmd, -self.limit, self.limit)
        self._out = HeadLoop(t, err.tolist(), cmd.tolist())
        return ServoCommand(head=cmd)

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_HEAD: self._out}
