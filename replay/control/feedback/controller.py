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

from replay.control.catching.base import CatchArmController
from replay.control.catching.model import ARM_JOINTS
from replay.control.catching.mapping import CatchGeometry
from replay.params import param
from replay.robot.arm_types import ArmCommand, ArmSpec


@dataclass
class FeedbackParams:
    q_alpha: float = param(
        math.pi / 2,
        unit="rad",
        doc="selected joint's angle on the catch surface (as the mapping's)",
    )
    selected_joint: str = param(
        "J4", choices=ARM_JOINTS, doc="the joint at q_alpha on the catch surface"
    )
    held_joints: list[str] = param(
        ["J3"], choices=ARM_JOINTS, max_length=7, doc="joints held at their initial angle"
    )
    catch_q: list[float] = param(
        [0.0, math.pi / 4], unit="rad", length=2, doc="(q1, q2) the inverse prefers (branch)"
    )
    catch_offset: float = param(
        -1.0,
        unit="m",
        doc="catch point this far along the tool z axis; negative = palm thickness + ball radius",
    )
    kp: list[float] = param(
        [900.0, 1500.0, 300.0, 150.0],
        unit="N*m/rad",
        ge=0.0,
        le=1e6,
        min_length=1,
        max_length=7,
        doc="PD stiffness per arm joint (as the direct controller's)",
    )
    kd: list[float] = param(
        [30.0, 45.0, 10.0, 4.0],
        unit="N*m*s/rad",
        ge=0.0,
        le=1e6,
        min_length=1,
        max_length=7,
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


class FeedbackController(CatchArmController):
    Params = FeedbackParams
    description = (
        "feedback only: joint PD toward l_c^-1 of the ball as seen now, gravity compensated"
    )

    def __init__(self, params: FeedbackParams, *, spec: ArmSpec) -> None:
        super().__init__(params, spec=spec, who="the feedback baseline")
        self.geo = CatchGeometry.from_fk(self.model.fk, params.q_alpha, p_ref=tuple(params.catch_q))
        self.r_o: np.ndarray | None = None
        self.q_d = self.q_init.copy()
        self.tau: list[float] = list(self._zeros)

    def _see(self, m) -> None:
        self.r_o = np.asarray(m.position, float)

    def update(self, t: float, measurements: list) -> ArmCommand:
        self._measure(measurements)
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
                self._close_hand({"distance": d})
        self.tau = self._torque()
        return self._command(self.tau)

    def _torque(self) -> list[float]:
        """tau = g(q) + Kp (q_o - q) - Kd qd, saturated (g(q_o) alone before the first joint
        state): no qd_d, no qdd_d."""
        zero = np.zeros(self.n)
        if self.q is None or self.qd is None:
            ff = self.model.inverse_dynamics_full(self.q_d, zero, zero)
            return np.clip(ff, -self.tau_limit, self.tau_limit).tolist()
        q, qd = np.asarray(self.q, float), np.asarray(self.qd, float)
        ff = self.model.inverse_dynamics_full(q, zero, zero)  # gravity at the posture
        tau = ff + self.kp * (self.q_d - q) - self.kd * qd
        return np.clip(tau, -self.tau_limit, self.tau_limit).tolist()

    def intent(self) -> dict:
        return {"method": "feedback", "hand_closing": self.closing}

    def outcome(self, t: float) -> dict:
        return {"hand_closed": self.closing}

    def telemetry(self, t: float) -> dict:
        return self._arm_telemetry(t, self.q_d.tolist(), self.tau)
