"""Namiki & Ishikawa's catching controller: q_d = g o l_c^-1(r_o) (eq. 7) tracked by PD + dynamics.

At each control step (1 kHz) the controller

1. takes the newest stereo position r_o ("/vision/object", one frame old) and the joint state
   ("/arm/encoders", from the joint_encoders sensor; without it the torque is the feed-forward only);
2. estimates r_o' (and r_o'' = g) with a ballistic least-squares fit (:mod:`.estimator`) and,
   optionally, carries r_o forward over the measurement's age (latency compensation); or, with
   ``estimator: last``, takes the newest frame and the two newest frames' difference quotient
   (no flight model, no extrapolation: the prediction-free variant);
3. maps q_d = f(r_o) (eq. 7), qd_d = F r_o' (eq. 23), qdd_d = F r_o'' + Fdot r_o' (eq. 16);
4. commands tau = tau_ff + Kp (q_d - q) + Kd (qd_d - qd), tau_ff = M(q_d) qdd_d + H qd_d + g(q_d)
   (eqs. 17-21, "dynamics") or g(q) ("gravity") or 0, saturated at the spec's torque limits.
   Joint 3 is held at its initial value (the paper fixes axis 3 at 0);
5. closes the hand so that its closing (90 deg in 20 ms: |closed - open| / closing speed) ends at
   the predicted arrival on the catch surface |r_o - O| = |c| (where q4 = q_alpha, eq. 4).

Before the ball is seen the arm holds its initial posture. Once the ball reaches the catch
surface the desired posture is frozen (``after_catch: hold``), because past it the ball sits in
the hand and the mapping would chase the hand itself.

The set-up, the joint state, the PD law, the hand's command and the arm's telemetry are the
catch-family base's (:mod:`.base`), shared with the predictive and feedback baselines.

Mapping parameters (``mapping``): "optimised" = alpha minimising eq. 25 under eq. 13 (computed at
start-up, ~3 s, or read from ``alpha_file``); "initial" = the paper's unoptimised parameters, which
we define as the minimum-norm alpha satisfying only the initial constraint C alpha = rhs (eq. 13).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from replay.control.catching.base import CatchArmController
from replay.control.catching.payloads import CatchingState
from replay.control.catching.estimator import BallisticEstimator, LastFrameEstimator
from replay.control.catching.optimise import (
    CostRecord,
    OptimResult,
    initial_alpha,
    load_alpha,
    save_alpha,
)
from replay.control.catching.model import ARM_JOINTS
from replay.control.catching.problem import ProblemConfig, build_problem
from replay.interfaces import Occurrence
from replay.messages import TOPIC_CATCHING_STATE, TOPIC_OPTIMIZATION_COST, OptimizationCost
from replay.params import ParamError, param
from replay.robot.arm_types import ArmCommand, ArmSpec


@dataclass
class Params:
    mapping: str = param(
        "optimised",
        choices=("optimised", "initial"),
        doc="b(q) parameters: 'optimised' (eq. 25 under eq. 13) or 'initial' "
        "(minimum-norm alpha meeting only the initial constraint, eq. 13)",
    )
    alpha_file: str = param(
        "",
        max_length=1000,
        doc="JSON with precomputed alpha (write_alpha_file), relative to the "
        "scenario file; used when its key matches this "
        "configuration, else alpha is recomputed",
    )
    q_alpha: float = param(
        math.pi / 2,
        unit="rad",
        ge=-10,
        le=10,
        doc="catching angle of the selected joint (Sec. IV-A: pi/2)",
    )
    selected_joint: str = param(
        "J4", choices=ARM_JOINTS, doc="the joint i of eq. 6 (Sec. IV-A: axis 4)"
    )
    held_joints: list[str] = param(
        ["J3"],
        choices=ARM_JOINTS,
        max_length=7,
        doc="joints held at their initial angle (Sec. IV-A: axis 3 "
        "at 0); with them the arm must keep 3 active joints",
    )
    order: int = param(4, ge=2, le=8, doc="N of eq. 12 (Sec. IV-B: 4th order)")
    catch_q: list[float] = param(
        [0.0, math.pi / 4],
        unit="rad",
        length=2,
        ge=-10,
        le=10,
        doc="(q1, q2) of the nominal catching point l(q)|q4=q_alpha; also the "
        "branch l_c^-1 prefers",
    )
    catch_offset: float = param(
        -1.0,
        unit="m",
        ge=-1.0,
        le=1.0,
        doc="l(q) is this far along the tool z axis (the ball centre on "
        "the palm); negative = palm thickness + ball radius from the "
        "spec (0 without hand/ball)",
    )
    throw_start: list[float] = param(
        [3.2, 0.0, 1.0],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="r_o(t0): where the ball is first seen in the nominal throw; "
        "every throw of the optimisation set starts here",
    )
    throw_speeds: list[float] = param(
        [8.0, 9.0, 10.0],
        unit="m/s",
        gt=0.0,
        le=100,
        min_length=1,
        max_length=10,
        doc="launch speeds of the set (Sec. IV-B: 8 ~ 10 m/s); the middle "
        "one is the nominal throw of eq. 13",
    )
    throw_spread: float = param(
        0.1, unit="m", ge=0.0, le=10, doc="half-width of the arrival grid around the catching point"
    )
    throw_grid: int = param(3, ge=1, le=10, doc="arrival grid points per axis (grid x grid)")
    samples_per_throw: int = param(15, ge=2, le=200, doc="samples of each throw from t0 to arrival")
    opt_torque_limits: list[float] = param(
        [],
        unit="N*m",
        gt=0.0,
        le=1e4,
        max_length=7,
        doc="tau_max of eq. 22 for the active joints; [] = spec",
    )
    opt_velocity_limits: list[float] = param(
        [],
        unit="rad/s",
        gt=0.0,
        le=1000,
        max_length=7,
        doc="omega_max of eq. 24 for the active joints; [] = spec",
    )
    w_tau: float = param(1.0, unit="1", gt=0.0, le=1e6, doc="K_tau = w_tau diag(1/tau_max^2)")
    w_omega: float = param(
        1.0, unit="1", gt=0.0, le=1e6, doc="K_omega = w_omega diag(1/omega_max^2)"
    )
    limit_penalty: float = param(
        100.0, unit="1", ge=0.0, le=1e9, doc="weight of the hinge penalties for eqs. 22 and 24"
    )
    torque_limit_penalty: float = param(
        -1.0, unit="1", ge=-1.0, le=1e9, doc="weight of eq. 22's hinge alone; < 0 = limit_penalty"
    )
    approach_weight: float = param(
        0.0,
        unit="1",
        ge=0.0,
        le=1e9,
        doc="weight of the approach-direction term (not in the paper, "
        "approach.py): the ball down the palm axis; 0 = eq. 25 only",
    )
    torque_cost: str = param(
        "eq25",
        choices=("eq25", "clamped"),
        doc="'eq25': the paper's unclamped eq.-17 torque; 'clamped': an EXTENSION (not in the "
        "paper): sat(tau) at the limits plus excess_weight times the undeliverable rest",
    )
    excess_weight: float = param(
        0.1, unit="1", ge=0.0, le=1e6, doc="weight of tau - sat(tau) in the 'clamped' extension"
    )
    max_iterations: int = param(40, ge=0, le=1000, doc="Levenberg-Marquardt iterations at most")
    kp: list[float] = param(
        [900.0, 1500.0, 300.0, 150.0],
        unit="N*m/rad",
        ge=0.0,
        le=1e6,
        min_length=1,
        max_length=7,
        doc="PD stiffness per arm joint",
    )
    kd: list[float] = param(
        [30.0, 45.0, 10.0, 4.0],
        unit="N*m*s/rad",
        ge=0.0,
        le=1e6,
        min_length=1,
        max_length=7,
        doc="PD damping per arm joint",
    )
    feedforward: str = param(
        "dynamics",
        choices=("dynamics", "gravity", "none"),
        doc="tau_ff: eq. 17 at q_d ('dynamics'), g(q) or none",
    )
    estimator: str = param(
        "ballistic",
        choices=("ballistic", "last"),
        doc="r_o, r_o' for eqs. 7, 23: 'ballistic' (fit with known g over fit_window, carried "
        "over the latency) or 'last' (newest frame, difference of the two newest: no prediction)",
    )
    latency_compensation: bool = param(
        True,
        doc="carry r_o forward over the measurement's age with the fitted velocity (ballistic only)",
    )
    fit_window: float = param(
        0.1, unit="s", gt=0.0, le=10, doc="ballistic fit over this much history"
    )
    close_lead: float = param(
        0.0,
        unit="s",
        ge=-1,
        le=1,
        doc="start closing this much earlier than (arrival - closing time)",
    )
    after_catch: str = param(
        "hold",
        choices=("hold", "track"),
        doc="at the catch surface: freeze q_d ('hold') or keep mapping",
    )
    scenario_dir: str = field(default="", metadata={"internal": True})  # set by the loader

    def __post_init__(self) -> None:
        if self.selected_joint in self.held_joints:
            raise ParamError(
                "selected_joint",
                f"{self.selected_joint} is also held (held_joints): the selected joint must move",
            )
        if len(self.kp) != len(self.kd):
            raise ParamError(
                "kd", f"expected one value per joint as kp ({len(self.kp)}), got {len(self.kd)}"
            )


def alpha_path(params: Params) -> Path | None:
    """``alpha_file`` resolved against the scenario file's directory (absolute paths kept)."""
    if not params.alpha_file:
        return None
    path = Path(params.alpha_file)
    return (
        path if path.is_absolute() or not params.scenario_dir else Path(params.scenario_dir) / path
    )


def problem_config(
    P: Params, q_start: np.ndarray, *, tau_max: np.ndarray, omega_max: np.ndarray, gravity: float
) -> ProblemConfig:
    """The offline problem of eq. 25 under eq. 13 as the parameters state it; ``tau_max`` (eq.
    22) and ``omega_max`` (eq. 24), the spec's limits of the active joints, stand where the
    parameters leave them empty; ``gravity`` in m/s^2."""
    if P.opt_torque_limits:
        tau_max = np.asarray(P.opt_torque_limits, float)
    if P.opt_velocity_limits:
        omega_max = np.asarray(P.opt_velocity_limits, float)
    return ProblemConfig(
        q_alpha=P.q_alpha,
        order=P.order,
        q_start=tuple(q_start.tolist()),
        catch_q=tuple(P.catch_q),
        throw_start=tuple(P.throw_start),
        speeds=tuple(P.throw_speeds),
        spread=P.throw_spread,
        grid=P.throw_grid,
        n_samples=P.samples_per_throw,
        gravity=gravity,
        tau_max=tuple(tau_max.tolist()),
        omega_max=tuple(omega_max.tolist()),
        w_tau=P.w_tau,
        w_omega=P.w_omega,
        penalty=P.limit_penalty,
        torque_penalty=P.torque_limit_penalty,
        approach_weight=P.approach_weight,
        max_iter=P.max_iterations,
        torque_cost=P.torque_cost,
        excess_weight=P.excess_weight,
    )


# the annotations' name for Params (inside the controller, ``Params`` is its class attribute)
CatchingParams = Params


class CatchingController(CatchArmController):
    Params = CatchingParams
    description = (
        "Namiki & Ishikawa: direct mapping q_d = g o l_c^-1(r_o) from stereo "
        "positions to joint targets, PD + dynamics feed-forward, hand timed by TTC"
    )

    def __init__(self, params: CatchingParams, *, spec: ArmSpec) -> None:
        super().__init__(params, spec=spec, who="the catching mapping")
        P = params
        act = list(self.active)
        self.config = problem_config(
            P,
            self.q_init,
            tau_max=self.tau_limit[act],
            omega_max=np.asarray(spec.velocity_limits, float)[act],
            gravity=-float(self.gravity[2]),
        )
        self.problem = build_problem(self.model, self.config)
        self.geo = self.problem.geometry
        self.history: list[CostRecord] = []
        self.result: OptimResult | None = None
        self.alpha0 = initial_alpha(self.problem.C, self.problem.rhs)
        self.alpha_opt = None
        if P.mapping == "optimised":
            self.alpha_opt = self._optimised_alpha()
            alpha = self.alpha_opt
        else:
            self.history = [self.problem.objective.record(0, self.alpha0)]
            alpha = self.alpha0
        self.mapping = self.problem.mapping
        self.mapping.A = np.asarray(alpha, float).reshape(self.mapping.A.shape)
        self.est: BallisticEstimator | LastFrameEstimator = (
            BallisticEstimator(self.gravity, P.fit_window)
            if P.estimator == "ballistic"
            else LastFrameEstimator()
        )
        # the per-step path works on Python floats: joint vectors are lists of n floats
        self._act = tuple(int(i) for i in self.model.active)
        self._q_fixed = self.model.q_fixed.tolist()
        self._origin = tuple(self.geo.origin.tolist())
        # run-time state
        self.q_d: list[float] = self.q_init.tolist()
        self.qd_d: list[float] = list(self._zeros)
        self.tau: list[float] = list(self._zeros)
        self.t_catch = None
        self.holding = False
        self._in_domain = True
        self._warned_state = False
        # the feed-forward of the current desired state (q_d, qd_d, qdd_d); None when the
        # update set a new one (before the ball is seen and while holding, it is computed once)
        self._ff: tuple | None = None
        self._state_lists: tuple | None = None  # (r_o, r_o', q_o) lists of /catching/state
        self._costs_logged = False  # /optimization/cost goes out with the first telemetry

    # ------------------------------------------------------------------ parameters
    def _optimised_alpha(self, progress=None) -> np.ndarray:
        key = self.config.key(self.model)
        path = alpha_path(self.params)
        if path is not None and path.is_file():
            data = load_alpha(path)
            if data.get("meta", {}).get("key") == key:
                self.history = data["history"]
                return data["alpha"]
            why = "alpha_file made for another configuration; recomputed"
            self._events.append(Occurrence("warning", {"reason": why, "file": str(path)}))
        elif path is not None:  # (a mistyped or misplaced file is said, not silently replaced)
            why = "alpha_file not found; optimised here"
            self._events.append(Occurrence("warning", {"reason": why, "file": str(path)}))
        res = self.problem.solve(progress)
        self.history = res.history
        self.result = res
        return res.alpha

    def write_alpha_file(self, path, progress=None) -> None:
        """Store the optimised alpha (and alpha0, the cost history) for ``alpha_file``;
        ``progress(CostRecord)`` is called at each iteration when it is optimised here."""
        if self.alpha_opt is None:
            self.alpha_opt = self._optimised_alpha(progress)
        res = OptimResult(
            alpha=np.asarray(self.alpha_opt),
            alpha0=self.alpha0,
            history=self.history,
            constraint_residual=float(
                np.max(np.abs(self.problem.C @ self.alpha_opt - self.problem.rhs))
            ),
        )
        save_alpha(
            path,
            res,
            {
                "key": self.config.key(self.model),
                "config": {k: v for k, v in vars(self.config).items()},
            },
        )

    def optimization_costs(self) -> list[OptimizationCost]:
        """``/optimization/cost`` messages (t = 0: the optimisation precedes the run)."""
        return [
            OptimizationCost(0.0, h.iteration, h.torque_cost, h.velocity_cost) for h in self.history
        ]

    # ------------------------------------------------------------------ control
    def _see(self, m) -> None:
        self.est.add(m.t, m.position)

    def update(self, t: float, measurements: list) -> ArmCommand:
        self._measure(measurements)
        P, est = self.params, self.est
        qdd_d = self._zeros
        if est.buf and not self.holding:
            r, v, a = est.state_f(t) if P.latency_compensation else est.state_f(est.buf[-1][0])
            # eqs. 7, 23, 16 (compiled, 3-tuples)
            try:
                q_a, qd_a, qdd_a, q_o, in_dom = self.mapping.evaluate_one_tuple(r, v, a)
            except np.linalg.LinAlgError:  # the mapping's Jacobian is singular at r_o
                return self._hold_singular(t, r)
            if in_dom != self._in_domain and not in_dom:
                self._events.append(
                    Occurrence(
                        "infeasible",
                        {
                            "reason": "r_o outside the domain of l_c^-1 (clamped)",
                            "r_o": list(r),
                            "d_min": self.geo.d_min,
                        },
                    )
                )
            self._in_domain = in_dom
            self._state_lists = (list(r), list(v), list(q_o))  # /catching/state's, until the next
            O = self._origin
            dx, dy, dz = r[0] - O[0], r[1] - O[1], r[2] - O[2]
            reached = math.sqrt(dx * dx + dy * dy + dz * dz) <= self.geo.catch_radius
            if reached and P.after_catch == "hold":
                self.holding = True
                self.qd_d = list(self._zeros)
                self._ff = None
                self._events.append(
                    Occurrence("mapping_hold", {"q_d": list(self.q_d), "r_o": list(r)})
                )
            else:  # the 3 active joints' values in the full vector (q3 held, model.full)
                k0, k1, k2 = self._act
                q_d, qd_d, qdd_d = self._q_fixed[:], self._zeros[:], self._zeros[:]
                q_d[k0], q_d[k1], q_d[k2] = q_a
                qd_d[k0], qd_d[k1], qd_d[k2] = qd_a
                qdd_d[k0], qdd_d[k1], qdd_d[k2] = qdd_a
                self.q_d, self.qd_d = q_d, qd_d
                self._ff = None
            if not self.holding:
                self.t_catch = est.time_to_radius(t, self._origin, self.geo.catch_radius)
        if (
            self.hand is not None
            and not self.closing
            and self.t_catch is not None
            and t >= self.t_catch - self.close_time - P.close_lead - 1e-9
        ):
            self._close_hand(
                {"predicted_catch_time": self.t_catch, "closing_time": self.close_time}
            )
        self.tau = self._torque(qdd_d)
        return self._command(self.tau)

    def _hold_singular(self, t: float, r) -> ArmCommand:
        """Freeze q_d where the mapping cannot be inverted (``after_catch: track`` carries the
        ball past the catch surface into the hand, where d(l_c^-1)/dr_o is singular): the arm
        holds, said once by a ``mapping_singular`` event."""
        self.holding = True
        self.qd_d = list(self._zeros)
        self._ff = None
        self._events.append(Occurrence("mapping_singular", {"t": t, "r_o": list(r)}))
        self.tau = self._torque(self._zeros)
        return self._command(self.tau)

    def _torque(self, qdd_d: list[float]) -> list[float]:
        ff: list[float] | tuple
        mode = self.params.feedforward
        if mode == "dynamics":  # eqs. 17-21: M(q_d) qdd_d + H(q_d, qd_d) qd_d + g(q_d)
            if self._ff is None:
                self._ff = self.model.inverse_dynamics_tuple(self.q_d, self.qd_d, qdd_d)
            ff = self._ff
        elif mode == "gravity":
            ff = self.model.gravity_full(self.q if self.q is not None else self.q_d).tolist()
        else:
            ff = self._zeros
        if self.q is None and not self._warned_state:
            self._warned_state = True
            self._events.append(
                Occurrence(
                    "warning",
                    {"reason": "no /arm/joint_state delivered: feed-forward torque only"},
                )
            )
        return self._pd(ff, self.q_d, self.qd_d)

    # ------------------------------------------------------------------ reporting
    def intent(self) -> dict:
        out = {
            "mapping": self.params.mapping,
            "hand_closing": self.closing,
            "holding": self.holding,
        }
        if self.t_catch is not None:
            st = self.est.state(self.t_catch, from_fit=True)
            out["catch_time"] = self.t_catch
            out["close_start"] = self.t_catch - self.close_time - self.params.close_lead
            if st is not None:
                out["catch_point"] = st[0].tolist()
        return out

    def outcome(self, t: float) -> dict:
        """The method's metrics for the run's outcome: which mapping, when it predicted the ball
        on the catch surface (t_c of eq. 4) and whether it reached it (``mapping_hold``)."""
        out = {"mapping": self.params.mapping, "reached_catch_surface": self.holding}
        if self.t_catch is not None:
            out["predicted_catch_time"] = round(float(self.t_catch), 6)
        return out

    def telemetry(self, t: float) -> dict:
        # The messages take the controller's lists as they are: update never changes one in
        # place (it makes new q_d, qd_d, tau and /catching/state lists), so none is copied here.
        out = self._arm_telemetry(t, self.q_d, self.tau)
        if not self._costs_logged:  # the offline optimisation's history, once (t = 0)
            self._costs_logged = True
            out[TOPIC_OPTIMIZATION_COST] = self.optimization_costs()
        if self._state_lists is not None:
            r, v, q_o = self._state_lists
            out[TOPIC_CATCHING_STATE] = CatchingState(
                t,
                r,
                v,
                q_o,
                self.qd_d,
                self._in_domain,
                float(self.t_catch) if self.t_catch is not None else -1.0,
                self.closing,
                self.holding,
            )
        return out
