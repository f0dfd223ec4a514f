"""Choosing where and when to intercept the ball, and how fast to move with it (not from the
papers: the standard intercept-planning pattern of the ball-catching literature, e.g. Hove &
Slotine 1991, Frese et al. 2001, Bäuml et al. 2010: predict the arc, pick a reachable point on it
by a cost, plan a dynamically feasible trajectory there).

Candidates are the predicted ballistic arc's points x(t) = r + v s + g s^2 / 2 at arrival times
t = now + s, every ``step`` seconds. For each:

1. **reachability**: the arm's inverse kinematics (:func:`solve_ik`, damped Newton on the active
   joints q1, q2, q4 with q3 held) must reach x(t) within 0.1 mm and inside the joint limits;
2. **palm alignment**: the angle between the palm's inward normal -z_tool(q) and the ball's
   velocity v(t) (0 = the ball comes straight down the palm axis);
3. **torque feasibility** (time scaling): the plan (:class:`~.trajectory.InterceptPlan`) from the
   start state must keep the model's inverse-dynamics torque (the same ``ArmModel`` as the
   direct mapping's eq. 17) within ``torque_margin`` of the limits at every sample; a later
   arrival lengthens the move, so searching the arrival time is the time scaling of this
   fixed-deadline problem;
4. **velocity matching**: the hand's velocity at arrival is beta v(t), beta tried from
   ``match_max`` down to 0 in ``match_levels`` steps; the largest feasible beta is kept.

The chosen candidate minimises ``angle_deg - match_weight * beta + switch_weight * |t - t_prev|
+ infeasibility_weight * max(0, ratio - torque_margin)`` (the third term keeps re-plans from
jumping between arrival times; the last prices a plan beyond the limits).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.control.catching.model import ArmModel
from replay.control.predictive.trajectory import InterceptPlan, Quintic


def jacobian(model: ArmModel, p: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """dl/dp (3, 3) at active coordinates p, central differences."""
    J = np.empty((3, len(p)))
    for k in range(len(p)):
        e = np.zeros(len(p))
        e[k] = h
        J[:, k] = (model.point(p + e) - model.point(p - e)) / (2 * h)
    return J


def solve_ik(model: ArmModel, x, seed, iters: int = 30, tol: float = 1e-4):
    """Active coordinates p with l(p) = x (damped Newton from ``seed``), and the residual (m)."""
    x = np.asarray(x, float)
    p = np.asarray(seed, float).copy()
    for _ in range(iters):
        e = x - model.point(p)
        if float(np.linalg.norm(e)) < tol * 1e-3:
            break
        J = jacobian(model, p)
        step = np.linalg.solve(J.T @ J + 1e-6 * np.eye(len(p)), J.T @ e)
        n = float(np.linalg.norm(step))
        if n > 0.5:  # rad: keep Newton on its branch
            step *= 0.5 / n
        p = p + step
    return p, float(np.linalg.norm(x - model.point(p)))


@dataclass
class Intercept:
    t_catch: float  # planned arrival (s)
    point: np.ndarray  # x(t_catch), the predicted ball centre there (m)
    ball_velocity: np.ndarray  # v(t_catch) (m/s)
    p: np.ndarray  # active coordinates of the catch posture
    angle_deg: float  # palm axis vs the incoming ball, where the rollout puts the hand
    beta: float  # fraction of the ball's velocity the target plan matches at arrival
    torque_ratio: float  # the *target* plan's peak |tau_i| / limit_i (model, unclamped)
    error: float  # |l(q) - x| at arrival in the rollout (m)
    relative_speed: float  # |v_ball - v_hand| at arrival in the rollout (m/s)
    plan: "FeasiblePlan"
    candidates: int


def palm_angle(model: ArmModel, p, v) -> float:
    """Degrees between the ball's velocity v and the palm's inward normal -z_tool at p."""
    n = model.tool_axis(p)
    c = float(-np.asarray(v, float) @ n) / float(np.linalg.norm(v))
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def plan_torque_ratio(model: ArmModel, plan, tau_limit_active: np.ndarray, n: int = 10) -> float:
    """max over the plan's samples and active joints of |tau_i| / limit_i (the model's eq. 17)."""
    act = model.active
    worst = 0.0
    for q, qd, qdd in plan.samples(n):
        tau = model.inverse_dynamics_full(q, qd, qdd)[act]
        worst = max(worst, float(np.max(np.abs(tau) / tau_limit_active)))
    return worst


def choose_intercept(
    model: ArmModel,
    t: float,
    r,
    v,
    g,
    start,  # (q, qd, qdd) full vectors: where the plan starts
    *,
    seed,
    lower,
    upper,
    kp,
    kd,
    tau_limit,
    s_min: float,
    s_max: float,
    step: float,
    settle: float,
    brake: float,
    match_max: float,
    match_levels: int,
    position_weight: float,
    speed_weight: float,
    switch_weight: float,
    t_prev: float | None,
    shoot_iterations: int = 2,
    refine: int = 6,
    window: tuple[float, float] | None = None,
    floor: float = 0.1,
    dt: float = 0.002,
) -> Intercept | None:
    """The best candidate (module doc) with its torque-feasible plan (a :class:`Rollout`), or
    None if no point of the arc is reachable. ``window`` (s, s) limits the arrival times tried
    (re-plans search near the previous one)."""
    r, v, g = (np.asarray(x, float) for x in (r, v, g))
    act = model.active
    lo, hi = np.asarray(lower, float)[act], np.asarray(upper, float)[act]
    tau_limit = np.asarray(tau_limit, float)
    betas = _match_fractions(match_max, match_levels)
    best: Intercept | None = None
    best_cost = math.inf
    q0, qd0, qdd0 = (np.asarray(x, float) for x in start)
    cands = _aligned(model, t, (r, v, g), seed, (lo, hi), (s_min, s_max, step), window, floor)
    if t_prev is not None:
        cands = [(a + switch_weight * abs(t + s - t_prev), s, *c) for a, s, *c in cands]
    n_cand = len(cands)
    cands.sort(key=lambda c: c[0])
    for _, s, x, vb, p in cands[:refine]:  # pass 2: rollouts of the best-aligned few
        J = jacobian(model, p)
        for beta in betas:
            pd = np.linalg.solve(J, beta * vb) if beta > 0 else np.zeros(len(p))
            p_aim = p.copy()
            for it in range(shoot_iterations + 1):
                # shooting: aim the target posture so that the rollout lands on x(t_c)
                target = InterceptPlan(
                    t, q0, qd0, qdd0, model.full(p_aim), model.full_rate(pd), t + s, settle, brake
                )
                ro = Rollout(model, target, t, t + s, q0, qd0, kp, kd, tau_limit, dt)
                qr, qdr, _ = ro(t + s)
                pr = qr[act]
                hand = model.point(pr)
                e = float(np.linalg.norm(hand - x))
                v_hand = jacobian(model, pr) @ qdr[act]
                v_rel = float(np.linalg.norm(vb - v_hand))
                ang = palm_angle(model, pr, vb)
                cost = ang + position_weight * 1e3 * e + speed_weight * v_rel
                if t_prev is not None:
                    cost += switch_weight * abs(t + s - t_prev)
                if cost < best_cost:
                    best_cost = cost
                    rho = plan_torque_ratio(model, target, tau_limit[act])
                    plan = FeasiblePlan(ro, target)
                    best = Intercept(t + s, x, vb, p, ang, beta, rho, e, v_rel, plan, 0)
                p_aim = p_aim + (p - pr)
    if best is not None:
        best.candidates = n_cand
    return best


def _match_fractions(match_max: float, levels: int) -> list[float]:
    """The speed-matching fractions tried at each candidate: ``levels`` from ``match_max``
    down to 0 (only 0 when ``match_max`` is 0)."""
    if not match_max > 0:
        return [0.0]
    return [match_max * (1.0 - k / max(1, levels - 1)) for k in range(levels)]


def _aligned(model, t, arc, seed, limits, times, window, floor) -> list[tuple]:
    """Pass 1 of :func:`choose_intercept`: the arc's points at arrival times ``s`` from
    ``times`` = (s_min, s_max, step) (within ``window``, above ``floor``) that the hand reaches
    inside the joint ``limits`` (IK seeded along the arc), each as (the palm's misalignment at
    its posture, s, the point, the ball's velocity there, the posture)."""
    r, v, g = arc
    lo, hi = limits
    s_min, s_max, step = times
    p_seed = np.asarray(seed, float)
    cands = []
    for s in np.arange(s_min, s_max + 1e-12, step):
        if window is not None and not (window[0] <= t + s <= window[1]):
            continue
        x = r + v * s + 0.5 * g * s * s
        if x[2] < floor:
            break
        vb = v + g * s
        p, err = solve_ik(model, x, p_seed)
        if err > 1e-4 or np.any(p < lo) or np.any(p > hi):
            continue
        p_seed = p  # continuation along the arc
        cands.append((palm_angle(model, p, vb), float(s), x, vb, p))
    return cands


class FeasiblePlan:
    """The rollout of the target plan up to the arrival (torque-feasible), then the target's
    brake from the rollout's arrival state: what the controller tracks."""

    def __init__(self, rollout: "Rollout", target: InterceptPlan) -> None:
        self.rollout, self.target = rollout, target
        self.t_catch = target.t_catch
        q, qd, _ = rollout(target.t_catch)
        self.stop = Quintic(
            target.t_catch,
            target.t_catch + target.brake,
            q,
            qd,
            np.zeros_like(q),
            q + 0.5 * qd * target.brake,
        )
        self.goal = q

    def __call__(self, t: float):
        if t < self.t_catch:
            return self.rollout(t)
        return self.stop(t)


class Rollout:
    """The arm model driven along a plan by the controller's own law (PD + inverse-dynamics
    feed-forward, saturated at the torque limits) over [t0, t1], dt steps: what the arm can do
    of the plan. Its (q, qd, qdd) is the torque-feasible reference: every sample's torque is
    within the limits by construction (tracking it needs only the PD's corrections), and its
    posture at the arrival is where the hand will really be."""

    def __init__(self, model: ArmModel, plan, t0, t1, q0, qd0, kp, kd, tau_limit, dt=0.001):
        n = model.n
        act = [int(i) for i in model.active]
        q, qd = np.asarray(q0, float).copy(), np.asarray(qd0, float).copy()
        locked = [i for i in range(n) if i not in act]
        q[locked] = model.q_fixed[locked]
        qd[locked] = 0.0
        steps = max(1, int(round((t1 - t0) / dt)))
        self.t = t0 + dt * np.arange(steps + 1)
        self.q = np.empty((steps + 1, n))
        self.qd = np.empty((steps + 1, n))
        self.qdd = np.zeros((steps + 1, n))
        self.tau = np.zeros((steps + 1, n))
        zero = [0.0] * n
        idt = model.inverse_dynamics_tuple
        for k in range(steps + 1):
            self.q[k], self.qd[k] = q, qd
            qr, qdr, qddr = plan(self.t[k])
            ff = np.asarray(idt(qr.tolist(), qdr.tolist(), qddr.tolist()))
            tau = np.clip(ff + kp * (qr - q) + kd * (qdr - qd), -tau_limit, tau_limit)
            ql, qdl = q.tolist(), qd.tolist()
            bias = np.asarray(idt(ql, qdl, zero))  # H qd + g
            g0 = np.asarray(idt(ql, zero, zero))
            M = np.empty((len(act), len(act)))
            for j, a in enumerate(act):
                e = list(zero)
                e[a] = 1.0
                M[:, j] = (np.asarray(idt(ql, zero, e)) - g0)[act]
            acc = np.zeros(n)
            acc[act] = np.linalg.solve(M, (tau - bias)[act])
            self.qdd[k], self.tau[k] = acc, tau
            qd = qd + acc * dt  # semi-implicit Euler
            q = q + qd * dt

    def __call__(self, t: float):
        """(q, qd, qdd) at t (the step at or before t; the last one after the end)."""
        k = int(np.clip(np.searchsorted(self.t, t + 1e-12) - 1, 0, len(self.t) - 1))
        return self.q[k].copy(), self.qd[k].copy(), self.qdd[k].copy()
