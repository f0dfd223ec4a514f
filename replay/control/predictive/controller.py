"""A predict-then-intercept baseline for the catching arm (not in Namiki & Ishikawa: the classic
approach their direct mapping is set against, built here for the ablation; docs/catching.md).

Each control step it

1. filters the stereo positions with a Kalman filter (:mod:`.kalman`: state (r, v), known
   gravity); the first plan waits ``min_measurements`` frames spanning ``min_track_time``;
2. chooses an intercept on the predicted ballistic arc (:func:`.intercept.choose_intercept`):
   reachable (IK on J1, J2, J4, q3 held, inside the joint limits), the palm's inward normal
   aligned with the incoming ball, the hand on the ball's centre at arrival;
3. plans move -> glide -> brake (:class:`.trajectory.InterceptPlan`, velocity matching beta)
   and makes it torque-feasible: the reference is the arm model driven along it by this
   controller's own saturated law (:class:`.intercept.Rollout`), aimed by shooting so that it
   lands on the ball; **re-planned** (from the desired state) when the prediction at the
   planned arrival moves by more than ``replan_distance`` (at most every ``replan_interval``),
   until ``freeze_time`` before the arrival;
4. tracks it with the same PD + inverse-dynamics law and torque saturation as the direct
   controller, and starts closing the hand at the planned arrival (+ ``close_delay``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.control.catching.base import CatchArmController
from replay.control.catching.model import ARM_JOINTS
from replay.control.predictive.intercept import FeasiblePlan, Intercept, choose_intercept
from replay.control.predictive.kalman import BallKalman
from replay.interfaces import Occurrence
from replay.params import check_limit, param
from replay.robot.arm_types import ArmCommand, ArmSpec


@dataclass
class PredictiveParams:
    ik_seed: list = param(
        [0.0, math.pi / 4, math.pi / 2],
        unit="rad",
        length=3,
        doc="(q1, q2, q4) the inverse kinematics starts from (the elbow branch: q4 > 0)",
    )
    held_joints: list[str] = param(
        ["J3"], choices=ARM_JOINTS, max_length=7, doc="joints held at their initial angle"
    )
    selected_joint: str = param(
        "J4", choices=ARM_JOINTS, doc="the last active joint (as the direct mapping's)"
    )
    catch_offset: float = param(
        -1.0,
        unit="m",
        doc="catch point this far along the tool z axis; negative = "
        "palm thickness + ball radius from the spec",
    )
    meas_sigma: float = param(
        0.002,
        unit="m",
        gt=0.0,
        doc="Kalman measurement noise (the stereo's ~1-2 mm, sensors/stereo.py)",
    )
    accel_sigma: float = param(
        2.0, unit="m/s^2", gt=0.0, doc="Kalman process noise: unmodelled acceleration (drag, kicks)"
    )
    min_measurements: int = param(3, ge=1, doc="frames before the first plan, and ...")
    min_track_time: float = param(
        0.009, unit="s", ge=0.0, doc="... at least this long between the first and newest frame"
    )
    search_step: float = param(
        0.004, unit="s", gt=0.0, doc="arrival times tried along the predicted arc, this apart"
    )
    max_lead: float = param(0.4, unit="s", gt=0.0, doc="the latest arrival tried")
    settle: float = param(
        0.008,
        unit="s",
        ge=0.001,
        doc="the move ends this long before the arrival; then the hand glides at the matched "
        "velocity (holds still if beta = 0)",
    )
    brake: float = param(0.06, unit="s", gt=0.0, doc="after arrival, stop the glide over this long")
    match_max: float = param(
        0.25, unit="1", ge=0.0, le=1.0, doc="largest fraction of the ball's velocity matched"
    )
    match_levels: int = param(2, ge=1, doc="beta values tried, match_max down to 0")
    position_weight: float = param(
        1.0, unit="deg/mm", ge=0.0, doc="cost of the rollout's hand missing the ball's centre"
    )
    speed_weight: float = param(
        3.0, unit="deg/(m/s)", ge=0.0, doc="cost of the ball's speed relative to the hand"
    )
    switch_weight: float = param(
        200.0, unit="deg/s", ge=0.0, doc="cost of moving the planned arrival on a re-plan"
    )
    shoot_iterations: int = param(
        2, ge=0, doc="corrections of the target posture so that the rollout lands on the ball"
    )
    refine: int = param(6, ge=1, doc="best-aligned candidates whose rollouts are computed")
    replan_interval: float = param(
        0.005, unit="s", ge=0.0, doc="at least this long between two plans"
    )
    replan_distance: float = param(
        0.003,
        unit="m",
        ge=0.0,
        doc="re-plan when the prediction at the planned arrival moves this far",
    )
    freeze_time: float = param(
        0.01, unit="s", ge=0.0, doc="no re-planning this close to the planned arrival"
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
    close_delay: float = param(
        0.0,
        unit="s",
        doc="start closing the hand this long after the planned arrival (negative: before)",
    )

    def __post_init__(self) -> None:
        n = (self.max_lead - self.settle) / self.search_step  # the arrival times each plan tries
        check_limit(
            "table_rows",
            n,
            "search_step",
            "the arrival times a plan tries (max_lead / search_step)",
        )


Params = PredictiveParams


class PredictiveController(CatchArmController):
    Params = PredictiveParams
    description = (
        "predict-then-intercept baseline: Kalman filter, intercept chosen for reach, palm "
        "alignment and torque feasibility, move-glide-brake plan with velocity matching, PD + "
        "dynamics"
    )

    def __init__(self, params: PredictiveParams, *, spec: ArmSpec) -> None:
        super().__init__(params, spec=spec, who="the predictive baseline")
        P = params
        self.lower, self.upper = np.asarray(spec.lower, float), np.asarray(spec.upper, float)
        self.kf = BallKalman(self.gravity, meas_sigma=P.meas_sigma, accel_sigma=P.accel_sigma)
        self.q_d = self.q_init.copy()
        self.qd_d = np.zeros(self.n)
        self.qdd_d = np.zeros(self.n)
        self.tau: list[float] = list(self._zeros)
        self.plan: FeasiblePlan | None = None
        self.intercept: Intercept | None = None
        self.p_catch: np.ndarray = np.zeros(3)
        self.t_catch: float | None = None
        self.replans = 0
        self._t_plan = 0.0
        self._t_first: float | None = None

    # ------------------------------------------------------------------ control
    def _see(self, m) -> None:
        self.kf.add(m.t, m.position)

    def update(self, t: float, measurements: list) -> ArmCommand:
        P = self.params
        self._measure(measurements)
        if self.kf.n == 1 and self._t_first is None:
            self._t_first = self.kf.t
        if (
            self.kf.n >= P.min_measurements
            and self._t_first is not None
            and self.kf.t - self._t_first >= P.min_track_time - 1e-9
        ):
            self._maybe_replan(t)
        if self.plan is not None:
            self.q_d, self.qd_d, self.qdd_d = self.plan(t)
        if (
            self.hand is not None
            and not self.closing
            and self.t_catch is not None
            and t >= self.t_catch + P.close_delay - 1e-9
        ):  # closure on arrival (close_delay after it)
            self._close_hand({"predicted_catch_time": self.t_catch})
        self.tau = self._torque()
        return self._command(self.tau)

    def _maybe_replan(self, t: float) -> None:
        P = self.params
        if self.t_catch is not None and t >= self.t_catch - P.freeze_time:
            return
        r, v = self.kf.state(t)
        start = (self.q_d, self.qd_d, self.qdd_d)
        if self.t_catch is not None:  # has the prediction at the planned arrival moved?
            s = self.t_catch - t
            x = r + v * s + 0.5 * self.gravity * s * s
            if np.linalg.norm(x - self.p_catch) <= P.replan_distance:
                return
            if t < self._t_plan + P.replan_interval - 1e-9:
                return
        ic = choose_intercept(
            self.model,
            t,
            r,
            v,
            self.gravity,
            start,
            seed=np.asarray(P.ik_seed, float),
            lower=self.lower,
            upper=self.upper,
            kp=self.kp,
            kd=self.kd,
            tau_limit=self.tau_limit,
            s_min=P.settle + 0.005,
            s_max=P.max_lead,
            step=P.search_step,
            settle=P.settle,
            brake=P.brake,
            match_max=P.match_max,
            match_levels=P.match_levels,
            position_weight=P.position_weight,
            speed_weight=P.speed_weight,
            switch_weight=P.switch_weight,
            t_prev=self.t_catch,
            shoot_iterations=P.shoot_iterations,
            refine=P.refine,
        )
        if ic is None:
            return
        self.intercept, self.plan = ic, ic.plan
        self.t_catch, self.p_catch = ic.t_catch, ic.point
        self._t_plan = t
        self.replans += 1
        self._events.append(
            Occurrence(
                "plan",
                {
                    "catch_time": ic.t_catch,
                    "catch_point": ic.point.tolist(),
                    "q_goal": self.model.full(ic.p).tolist(),
                    "palm_angle_deg": ic.angle_deg,
                    "velocity_match": ic.beta,
                    "target_torque_ratio": ic.torque_ratio,
                    "rollout_error": ic.error,
                    "rollout_relative_speed": ic.relative_speed,
                    "candidates": ic.candidates,
                    "index": self.replans,
                    "position_sigma": self.kf.position_sigma(),
                    "velocity_sigma": self.kf.velocity_sigma(),
                },
            )
        )

    def _torque(self) -> list[float]:
        """The plan tracked by PD + inverse dynamics: tau = M(q_d) qdd_d + H qd_d + g(q_d)
        + Kp (q_d - q) + Kd (qd_d - qd), saturated (the direct controller's law)."""
        ff = self.model.inverse_dynamics_full(self.q_d, self.qd_d, self.qdd_d)
        return self._pd(ff.tolist(), self.q_d.tolist(), self.qd_d.tolist())

    # ------------------------------------------------------------------ reporting
    def intent(self) -> dict:
        out: dict = {"method": "predictive", "hand_closing": self.closing, "replans": self.replans}
        if self.t_catch is not None:
            out.update(catch_time=self.t_catch, catch_point=self.p_catch.tolist())
        return out

    def outcome(self, t: float) -> dict:
        out: dict = {"replans": self.replans}
        if self.t_catch is not None:
            out.update(
                predicted_catch_time=self.t_catch, predicted_catch_point=self.p_catch.tolist()
            )
        return out

    def telemetry(self, t: float) -> dict:
        return self._arm_telemetry(t, self.q_d.tolist(), self.tau)
