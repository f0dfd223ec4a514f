"""The stick controller's fast paths against their plain references (issue #10): the closed-form
J_i against the matrix formula of eq. 22, the estimator's running sums against a least-squares
solve, the sweep's compiled check (a far point skips the trigonometry) against sampling every
time, and re-planning only when a new
estimate moves the committed contact (the plan then equals a full re-plan within tolerance)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from replay.control.stick import collision as sc
from replay.control.stick.estimator import StickEstimate, StickEstimator
from replay.control.stick.hand_model import base_candidates
from replay.control.stick.plan import Shortfall
from replay.control.stick.strategy import ThreeStepController, ThreeStepParams
from replay.control.stick.coverage import Motion, Coverage, covered, sample_times

from tests.replay.control.stick import oracles
from tests.replay.control.stick.test_stick_method import V0, SyntheticStick, air_spec


def test_closed_form_collision_is_eq_22():
    """contact_at's u_i and C_i (closed forms, floats) against eqs. 22 and 26 in matrix form."""
    rng = np.random.default_rng(10)
    for _ in range(500):
        m, inertia, e = rng.uniform(0.005, 0.2), rng.uniform(5e-6, 2e-4), rng.uniform(0.0, 1.0)
        theta, side = rng.uniform(-math.pi, math.pi), int(rng.choice([1, -1]))
        r_x, u = rng.uniform(-0.06, 0.06), rng.normal(size=3) * [1.0, 1.0, 10.0]
        sol = sc.contact_at(m, inertia, e, theta, side, u, r_x)
        J = oracles.axis_map(m, inertia, e, theta, r_x, side)
        np.testing.assert_allclose(sol.u_after, J @ u, rtol=0, atol=1e-9 * (1 + abs(u).max()))
        assert sol.condition == pytest.approx(
            oracles.contact_condition(m, inertia, e, theta, r_x, side, u), abs=1e-9
        )
        n = oracles.tangent_normal(theta, side)[1]
        H = oracles.contact_jacobian(theta, (r_x, 0.0))
        assert sc.approach_speed(theta, r_x, side, u) == pytest.approx(-float(n @ H @ u), abs=1e-12)
        assert sc.normal(theta, side) == pytest.approx(tuple(n), abs=1e-15)


def lstsq_fit(samples) -> tuple[np.ndarray, np.ndarray, float, float]:
    data = np.array(samples)
    tau = data[:, 0] - data[-1, 0]
    A = np.column_stack([np.ones(len(tau)), tau])
    coef, *_ = np.linalg.lstsq(A, data[:, 1:], rcond=None)
    res = data[:, 1:] - A @ coef
    return (
        coef[0],
        coef[1],
        math.sqrt(np.mean(res[:, 0] ** 2 + res[:, 1] ** 2)),
        math.sqrt(np.mean(res[:, 2] ** 2)),
    )


def test_running_sums_fit_equals_least_squares_over_a_long_run():
    """Several seconds (re-anchored sums), spin changes (restarts), noise: the fit equals a
    least-squares solve of the same window."""
    rng = np.random.default_rng(11)
    est = StickEstimator()
    x, y, th, u = 0.1, -0.1, 0.3, np.array([0.5, 0.8, 7.0])
    breaks = 0
    for k in range(1500):  # 5 s at 300 fps
        if k % 211 == 0:
            u = rng.normal(size=3) * [0.5, 0.5, 8.0]
        x, y, th = x + u[0] / 300, y + u[1] / 300, th + u[2] / 300
        meas = (th + rng.normal() * 1e-3 + math.pi / 2) % math.pi - math.pi / 2
        breaks += est.add(k / 300, x + rng.normal() * 1e-4, y + rng.normal() * 1e-4, meas)
        if est.estimate().n < 2:
            continue
        value, rate, rms_xy, rms_th = lstsq_fit(est._samples)
        e = est.estimate()
        assert [e.x, e.y, e.theta] == pytest.approx(list(value), abs=1e-9)
        assert [e.vx, e.vy, e.omega] == pytest.approx(list(rate), abs=1e-7)
        assert e.rms_xy == pytest.approx(rms_xy, abs=1e-7)
        assert e.rms_theta == pytest.approx(rms_th, abs=1e-7)
    assert breaks >= 5  # the restarts were exercised


def test_sweep_answers_as_sampling_every_time():
    rng = np.random.default_rng(12)
    agree = hits = 0
    for _ in range(200):
        e = StickEstimate(
            0.0,
            *rng.uniform(-0.1, 0.1, 2),
            rng.uniform(-3, 3),
            *rng.normal(size=2),
            rng.normal() * 8.0,
            30,
            0.0,
            0.0,
        )
        motion = Motion(e, rng.uniform(0.0, 0.3), tuple(rng.normal(size=3) * [0.3, 0.3, 4.0]))
        t1 = rng.uniform(0.05, 0.6)
        times = sample_times(0.0, t1)
        sweep = Coverage(motion, 0.0, t1)
        for p in rng.uniform(-0.15, 0.15, (10, 2)):
            grow = rng.uniform(0.0, 0.01)
            ref = bool(covered(motion, times, [p], 0.05, 0.005, grow).any())
            agree += sweep.hits(p, 0.05, 0.005, grow) == ref
            hits += ref
    assert agree == 2000 and 100 < hits < 1900  # both answers were exercised


NOISE = 3e-5  # m, the rendered camera's position noise is of this order (0.02 px)


def three_step_run(replan_tol: float, t_end: float = 0.28):
    """The 3-step controller on a synthetic throw (no collision happens: the plan is refined
    up to its freeze), with every reach() call and its result recorded."""
    params = ThreeStepParams(replan_tol=replan_tol)
    ctrl = ThreeStepController(params, spec=air_spec())
    rng = np.random.default_rng(13)
    stick = SyntheticStick([-0.1, 0.35, 0.3, 0.0, -V0, 9.9])
    reach, calls = ctrl.planner.reach, []

    def counted(*a, **k):
        calls.append(a[1])
        return reach(*a, **k)

    ctrl.planner.reach = counted
    plans = []
    for i in range(int(round(t_end * 1000)) + 1):
        t = i / 1000.0
        ms = []
        for topic, m in stick.delivered(t):
            m = type(m)(m.t, m.x + rng.normal() * NOISE, m.y + rng.normal() * NOISE, m.theta)
            ms.append((topic, m))
        ctrl.update(t, ms)
        plans.append((t, ctrl.plan))
    return ctrl, calls, plans


def test_a_plan_is_refined_only_when_a_new_estimate_moves_it():
    ctrl, calls, plans = three_step_run(1e-4)
    _, calls_all, plans_all = three_step_run(0.0)  # refine on every estimate (as before)
    assert ctrl.plan is not None and ctrl.plan.index == 1
    frames = 0.28 * 300
    assert len(calls_all) > 0.5 * frames  # every estimate re-planned
    assert len(calls) < 0.25 * len(calls_all)
    # the committed fingertip spot never strays from the fully refined one by much more than
    # the tolerance (the two runs see the same measurements)
    worst = 0.0
    for (t, p), (_, q) in zip(plans, plans_all):
        if p is not None and q is not None and p.index == q.index:
            worst = max(worst, float(np.hypot(*(p.tip - q.tip))))
    assert worst < 3 * ctrl.params.replan_tol
    p, q = plans[-1][1], plans_all[-1][1]
    assert abs(p.t - q.t) < ctrl.params.replan_dt


def test_reach_bound_finds_the_exhaustive_search_plan():
    """reach() stops trying bases once their travel-time bound exceeds the best arrival: the
    plan equals the quickest of trying every base on its own (ties: finger, then base order)."""
    ctrl, _, _ = three_step_run(1e-4, t_end=0.03)
    est, planner, t = ctrl.est.estimate(), ctrl.planner, 0.03
    sol = ctrl._contacts(est, 1)[0]
    now = ctrl.model.config
    compared = 0
    for t_c in planner.crossings(t, est, sol.theta)[:3]:
        fast = planner.reach(1, t, est, sol, None, t_c, (0, 1), False, Shortfall())
        tip = planner.spot(est, sol, t_c)[1]
        motion = Motion(est, t_c, sol.u_after)
        best = None
        for rank, k in enumerate((0, 1)):
            for i, base in enumerate(
                base_candidates(ctrl.hand, k, tip, tuple(ctrl.model.target.base))
            ):
                plan = planner.reach(1, t, est, sol, None, t_c, (k,), True, Shortfall(), [base])
                if plan is None:
                    continue
                cost = planner.route_clear(t, now, plan.route, k, motion, t_c)
                if best is None or (cost, rank, i) < best[0]:
                    best = ((cost, rank, i), plan)
        assert (fast is None) == (best is None)
        if fast is not None:
            compared += 1
            slow = best[1]
            assert fast.finger == slow.finger and fast.config == slow.config
            assert fast.route == slow.route
    assert compared >= 1


def test_base_candidates_in_scalars_are_numpys():
    """base_candidates works in scalars (hand2d.clip_scalar for np.clip): the bases NumPy's and
    np.clip gave, to the bit, for seeded random tips and current bases (in and beyond the
    slider range)."""
    hand = air_spec().hand
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    rng = np.random.default_rng(21)
    reach = sum(hand.link_lengths)
    for _ in range(300):
        k = int(rng.integers(2))
        tip, here = rng.uniform(-0.45, 0.45, 2), tuple(float(v) for v in rng.uniform(-0.3, 0.3, 2))
        root = np.array(hand.root_offsets[k])
        ref = [here] if np.linalg.norm(tip - root - np.array(here)) <= 0.85 * reach else []
        for rho in (0.7 * reach, 0.5 * reach, 0.85 * reach):
            for deg in (90.0, 65.0, 115.0, 40.0, 140.0):
                a = math.radians(deg)
                b = np.asarray(tip) - root - rho * np.array([math.cos(a), math.sin(a)])
                ref.append((float(np.clip(b[0], xlo, xhi)), float(np.clip(b[1], ylo, yhi))))
        got = base_candidates(hand, k, tip, here)
        assert repr(got) == repr(ref)  # (repr: -0.0 and 0.0 told apart)


def test_hand2d_clips_are_np_clips():
    """hand2d.clip against np.clip of arrays, clip_scalar against np.clip of a float64 scalar
    (NumPy's two paths differ at signed zeros): NaN, signed zeros, limits and beyond."""
    from replay.robot.hand2d import clip, clip_scalar

    rng = np.random.default_rng(4)
    vals = [math.nan, -0.0, 0.0, math.inf, -math.inf, *rng.uniform(-3.0, 3.0, 200)]
    lims = [(-1.0, 1.0), (0.0, 2.0), (-2.0, -0.0), (-0.0, 0.0), (0.5, 0.5)]
    for v in vals:
        for lo, hi in lims:
            arr = np.clip(np.array([v]), np.array([lo]), np.array([hi]))[0]
            assert repr(clip(float(v), lo, hi)) == repr(float(arr))
            assert repr(clip_scalar(float(v), lo, hi)) == repr(
                float(np.clip(np.float64(v), lo, hi))
            )


def test_passive_posture_search_is_the_array_references():
    """ContactPlanner._passive (postures in order of distance, each tip worked out only when its
    turn comes) against oracles.passive (every tip and distance as arrays, then the first
    clear one): the same posture or None, for seeded random idle postures, active tips and
    spinning sticks over the idle tip (so that nearer postures are often swept)."""
    ctrl, _, _ = three_step_run(1e-4, t_end=0.12)
    planner, hand, rng = ctrl.planner, ctrl.hand, np.random.default_rng(31)
    (a0, a1), (b0, b1) = hand.joint_limits
    moved = compared = 0
    for _ in range(300):
        j = int(rng.integers(2))
        cfg = ctrl.model.config.with_finger(j, (rng.uniform(a0, a1), rng.uniform(b0, b1)))
        x, y = cfg.tip(hand, j) + rng.normal(0.0, 0.02, 2)
        est = StickEstimate(
            0.0, x, y, 0.0, *rng.normal(0.0, 0.3, 2), rng.normal(0.0, 30.0), 6, 0, 0
        )
        sweep = Coverage(Motion(est, 0.1, tuple(rng.normal(0.0, 1.0, 3))), 0.0, 0.3)
        active = cfg.tip(hand, 1 - j) + rng.normal(0.0, 0.01, 2)
        got = planner._passive(cfg, j, sweep, active)
        assert got == oracles.passive(planner, cfg, j, sweep, active)
        compared += 1
        moved += got is not None and got != tuple(cfg.joints[j])
    print(f"_passive = reference in {compared} cases ({moved} moved the idle finger)")
    assert moved > 0.3 * compared


def test_exit_config_in_floats_is_the_array_references():
    """ContactPlanner._exit_config (floats) against oracles.exit_config (NumPy arrays, a
    2-vector's norm by np.linalg.norm): the same configuration or None, for seeded random hands
    with fingertips inside, at the edge of and outside the stick's reach. Within 1e-12: NumPy's
    2-element dot is BLAS's, which may fuse x x + y y on another CPU (equal to the bit here)."""
    ctrl, _, _ = three_step_run(1e-4, t_end=0.12)
    planner, hand, rng = ctrl.planner, ctrl.hand, np.random.default_rng(41)
    (a0, a1), (b0, b1) = hand.joint_limits
    moved = none = 0
    for _ in range(400):
        cfg = ctrl.model.config
        for k in (0, 1):
            cfg = cfg.with_finger(k, (rng.uniform(a0, a1), rng.uniform(b0, b1)))
        k = int(rng.integers(2))
        x, y = cfg.tip(hand, k) + rng.normal(0.0, 0.04, 2)
        est = StickEstimate(0.0, x, y, 0.0, *rng.normal(0.0, 0.3, 3), 6, 0, 0)
        motion = Motion(est, 0.05, tuple(rng.normal(0.0, 1.0, 3)))
        t = float(rng.uniform(0.0, 0.1))
        got = planner._exit_config(t, cfg, motion)
        want = oracles.exit_config(planner, t, cfg, motion)
        assert (got is None) == (want is None)
        if got is not None:
            np.testing.assert_allclose(got.base, want.base, rtol=0.0, atol=1e-12)
            np.testing.assert_allclose(got.joints, want.joints, rtol=0.0, atol=1e-12)
        moved += got is not None
        none += got is None
    print(f"_exit_config = reference in 400 cases ({moved} moved a tip out)")
    assert moved > 50 and none > 50


def test_hand_written_frozen_inits_are_the_generated_ones():
    """StickEstimate, ContactSolution and Config store their fields straight into the instance
    dict (a frozen dataclass's generated __init__ costs ~1 us a field): what dataclasses would
    generate (tests/replay/test_scene_inits.py says what that means)."""
    from replay.control.stick.hand_model import Config
    from tests.replay.test_scene_inits import assert_generated_init

    rng = np.random.default_rng(9)
    for cls in (StickEstimate, sc.ContactSolution, Config):
        assert_generated_init(cls, rng)
