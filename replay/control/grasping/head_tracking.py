"""Tracking control of the active vision (Namiki et al. 1999, Sec. 4.1.2, eq. 1), in floats:

    theta_dot_d^v = K^v J_image^-1 (xi_d - xi) - K^vv theta_dot^v                    (1)

J_image = d xi / d theta^v is the head model's (recognition publishes it with each frame, at
the estimated object point and the head angles of that frame). Without a target the head is
only damped (the second term).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from replay.control.grasping.gain_rule import check_period, delayed_gain
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
    gain_period: float = param(
        0.0,
        unit="s",
        ge=0.0,
        omit_empty=True,
        doc="the gain rule: 0 keeps K^v as given (tuned for 1 ms loops); a period T (s, the "
        "task's 1 / rate) re-designs K^v for it, the 1 ms loop's dominant pole kept given the "
        "chip's one-frame latency (gain_rule.delayed_gain)",
    )


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
        T = params.gain_period  # the gain rule (gain_rule.py): 0 keeps K^v
        K_v = [delayed_gain(k, T) for k in params.K_v] if T > 0.0 else params.K_v
        self.K_v, self.K_vv = np.asarray(K_v, float), np.asarray(params.K_vv, float)
        if spec.head is None:
            raise ValueError("head tracking needs a plant with a head")
        self.limit = np.asarray(spec.head.velocity_limit, float)
        self.rate: list[float] = [0.0, 0.0]
        self._xi_d, self._K_v = self.xi_d.tolist(), self.K_v.tolist()
        self._K_vv, self._limit = self.K_vv.tolist(), self.limit.tolist()
        self.obj: Any = None
        self._out: HeadLoop | None = None
        self._t_last: float | None = None

    def update(self, t: float, measurements) -> ServoCommand:
        for topic, m in measurements:
            if topic == TOPIC_HEAD_ENCODERS:
                self.rate = m.velocity
            elif topic == TOPIC_GRASP_OBJECT:
                self.obj = m
        if self.params.gain_period > 0.0:
            if self._t_last is not None:
                check_period(self.params.gain_period, t - self._t_last, "head")
            self._t_last = t
        # eq. 1 per axis in floats (2 x 2: J^-1 e by Cramer's rule)
        (kv0, kv1), (kvv0, kvv1), (lim0, lim1) = self._K_v, self._K_vv, self._limit
        c0, c1 = -kvv0 * self.rate[0], -kvv1 * self.rate[1]
        err = [0.0, 0.0]
        obj = self.obj
        if obj is not None and obj.found:
            err = [self._xi_d[0] - obj.xi[0], self._xi_d[1] - obj.xi[1]]
            (a, b), (c, d) = obj.jacobian
            det = a * d - b * c
            if det == 0.0:
                raise np.linalg.LinAlgError(f"singular image Jacobian {obj.jacobian}")
            c0 += kv0 * ((d * err[0] - b * err[1]) / det)
            c1 += kv1 * ((a * err[1] - c * err[0]) / det)
        cmd = [  # np.clip's
            lim0 if c0 > lim0 else (-lim0 if c0 < -lim0 else c0),
            lim1 if c1 > lim1 else (-lim1 if c1 < -lim1 else c1),
        ]
        self._out = HeadLoop(t, err, cmd)
        return ServoCommand(head=cmd)

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_HEAD: self._out}
