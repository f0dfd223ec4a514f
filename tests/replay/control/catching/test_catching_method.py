"""Namiki & Ishikawa catching (replay/control/catching): mapping, optimisation, controller."""

from __future__ import annotations

import math
import time

import numpy as np
import pytest

from replay.control.catching import (
    ArmModel,
    BallisticEstimator,
    CatchingController,
    Params,
    PolynomialB,
    ProblemConfig,
    build_problem,
    launch_velocity,
    load_alpha,
)
from replay.control.catching.optimise import initial_alpha
from replay.control.catching.trajectories import sample_throw
from replay.params import ParamError
from replay.messages import EffectorState, JointCommand, JointState, OptimizationCost, VisionObject
from replay.robot import ArmCommand, ArmSpec, HandSpec, ObjectSpec, wam_chain
from replay.robot.hand import CATCH3, hand_body, hand_mass
from replay.robot.wam import wam_joint_limits, wam_torque_limits

QA = math.pi / 2
G = np.array([0.0, 0.0, -9.81])
OFFSET = CATCH3.palm_size[2] + 0.0175  # palm thickness + ball radius


def fdot_rd(mp, r, rd) -> np.ndarray:
    """Fdot(r_o) r_o' (eq. 16): the part of qdd_d not due to r_o''."""
    _, _, qdd, _ = mp.evaluate(r, rd, np.zeros_like(np.atleast_2d(rd)))
    return qdd


def _chain():
    return wam_chain(4, payload=hand_body(CATCH3))


def _model():
    return ArmModel.from_chain(
        _chain(), q_fixed=np.array([0, math.pi / 4, 0, 0]), point_in_tool=(0.0, 0.0, OFFSET)
    )


def _spec(vel=3.0):
    chain = _chain()
    lo, hi = wam_joint_limits(4)
    ht = CATCH3
    hand = HandSpec(
        ht.name,
        ht.joint_names,
        np.array([j.lower for j in ht.joints]),
        np.array([j.upper for j in ht.joints]),
        ht.open_posture,
        ht.closed_posture,
        ht.closing_speed,
        ht.max_torque,
        hand_mass(ht),
        ht,
    )
    return ArmSpec(
        "wam4",
        chain.joint_names,
        lo,
        hi,
        wam_torque_limits(4),
        np.full(4, vel),
        ("J3",),
        np.array([0.0, math.pi / 4, 0.0, 0.0]),
        chain,
        chain.tool,
        hand,
        ObjectSpec("ball", 0.025, 0.0175),
    )


@pytest.fixture(scope="module")
def problem():
    return build_problem(
        _model(), ProblemConfig(tau_max=(60.0, 60.0, 30.0), omega_max=(3.0, 3.0, 3.0))
    )


@pytest.fixture(scope="module")
def solved(problem):
    t0 = time.process_time()
    res = problem.solve()
    return res, time.process_time() - t0  # CPU time: wall time is noisy on a shared host


@pytest.fixture(scope="module")
def alpha_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("catching") / "alpha.json"
    CatchingController(Params(), spec=_spec()).write_alpha_file(path)
    return str(path)


# ---------------------------------------------------------------------------- l_c (eq. 6)
def test_geometry_from_wam_fk(problem):
    geo = problem.geometry
    assert np.allclose(geo.origin, [0.0, 0.0, 0.346], atol=1e-9)  # J1/J2 meet at the shoulder
    assert np.allclose(np.abs(geo.w1), [0, 0, 1], atol=1e-12)
    assert abs(geo.w1 @ geo.w2) < 1e-12
    # the catching point l(q)|q4=q_alpha at the nominal (q1, q2)
    q = np.array([0.0, math.pi / 4, 0.0, QA])
    assert np.allclose(problem.catch_point, problem.model.fk(q), atol=1e-12)


def test_lc_closed_form_is_eq6(problem):
    geo, model = problem.geometry, problem.model
    rng = np.random.default_rng(1)
    P = np.column_stack(
        [rng.uniform(-1.5, 1.5, 30), rng.uniform(-1.0, 1.8, 30), QA + rng.uniform(-6.0, 1.0, 30)]
    )
    assert np.abs(geo.lc(P) - geo.lc_eq6(model.fk, P)).max() < 1e-8
    # at q4 = q_alpha, l_c is the kinematics itself
    P[:, 2] = QA
    assert np.abs(geo.lc(P) - np.array([model.point(p) for p in P])).max() < 1e-12


def test_lc_inverse_round_trip(problem):
    geo = problem.geometry
    rng = np.random.default_rng(2)
    # joint space -> task space -> joint space, on the branch through the catching point (the
    # other root of the two-axis problem, (q1 +- pi, -q2), is nearer the reference elsewhere)
    P = np.column_stack(
        [
            rng.uniform(-1.5, 1.5, 200),
            rng.uniform(0.02, 1.8, 200),
            QA + rng.uniform(-8.0, geo.s_min_dist - 0.05, 200),
        ]
    )
    inv = geo.inverse(geo.lc(P))
    assert inv.in_domain.all()
    assert np.abs(inv.p - P).max() < 1e-9
    # task space -> joint space -> task space over the whole throw region
    R = np.column_stack(
        [rng.uniform(0.3, 4.0, 200), rng.uniform(-1.0, 1.0, 200), rng.uniform(0.0, 2.0, 200)]
    )
    inv = geo.inverse(R)
    ok = inv.in_domain
    assert ok.mean() > 0.9
    assert np.abs(geo.lc(inv.p[ok]) - R[ok]).max() < 1e-9


def test_lc_inverse_outside_domain_is_clamped_and_flagged(problem):
    geo = problem.geometry
    direction = np.array([0.3, 0.2, 0.5])
    direction /= np.linalg.norm(direction)
    r = geo.origin + 0.5 * geo.d_min * direction  # closer to the shoulder than d_min
    inv = geo.inverse(r)
    assert not inv.in_domain[0]
    reached = geo.lc(inv.p)[0]
    # nearest reachable point: distance d_min from O, same direction
    assert np.linalg.norm(reached - geo.origin) == pytest.approx(geo.d_min, abs=1e-9)
    assert np.allclose((reached - geo.origin) / geo.d_min, direction, atol=1e-9)
    assert inv.p[0, 2] - QA == pytest.approx(geo.s_min_dist, abs=1e-12)
    # on the J1 axis q1 is undetermined: reference q1, flagged, still reaches the point
    r_axis = geo.origin + np.array([0.0, 0.0, 1.0])
    inv = geo.inverse(r_axis)
    assert not inv.in_domain[0]
    assert np.allclose(geo.lc(inv.p)[0], r_axis, atol=1e-9)


def test_lc_derivatives_match_finite_differences(problem):
    geo = problem.geometry
    p = np.array([[0.3, 0.9, QA - 2.0]])
    _, J, H = geo.derivatives(p)
    h = 1e-6
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        assert np.allclose((geo.lc(p + e) - geo.lc(p - e))[0] / (2 * h), J[0, :, k], atol=1e-8)
        _, Jp, _ = geo.derivatives(p + e)
        _, Jm, _ = geo.derivatives(p - e)
        assert np.allclose((Jp - Jm)[0] / (2 * h), H[0, :, :, k], atol=1e-7)


# ---------------------------------------------------------------------------- b (eqs. 8, 12)
def test_polynomial_structure():
    poly = PolynomialB(4, QA)
    assert poly.n_mono == 10 and poly.n_alpha == 30  # j1 + j2 + j3 <= N - 2 = 2
    assert (poly.powers[:, 2] >= 2).all() and (poly.powers.sum(axis=1) <= 4).all()


def test_b_and_its_jacobian_vanish_at_q_alpha():
    poly = PolynomialB(4, QA)
    rng = np.random.default_rng(3)
    A = rng.normal(size=30)
    P = np.column_stack([rng.uniform(-2, 2, 50), rng.uniform(-2, 2, 50), np.full(50, QA)])
    assert np.abs(poly.value(P, A)).max() < 1e-15
    assert np.abs(poly.jacobian(P, A)).max() < 1e-15
    h = 1e-5  # numerically: central differences at q4 = q_alpha
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = (poly.value(P + e, A) - poly.value(P - e, A)) / (2 * h)
        assert np.abs(fd).max() < 1e-8
    # and away from q_alpha, the analytic Jacobian is right
    P[:, 2] = QA + rng.uniform(-2, 2, 50)
    Jb = poly.jacobian(P, A)
    for k in range(3):
        e = np.zeros(3)
        e[k] = h
        fd = (poly.value(P + e, A) - poly.value(P - e, A)) / (2 * h)
        assert np.allclose(fd, Jb[:, :, k], rtol=1e-6, atol=1e-6)


def test_terminal_constraint_eq4(problem):
    """r_e = l(f(r_o)) - r_o = 0 and its rate = 0 wherever the target is on the catch surface."""
    mp, model, geo = problem.mapping, problem.model, problem.geometry
    rng = np.random.default_rng(4)
    mp.A = rng.normal(scale=0.05, size=mp.A.shape)
    for th in problem.throws.throws[::4]:
        r_c = th.r[-1]  # arrival on |r - O| = |c|
        assert np.linalg.norm(r_c - geo.origin) == pytest.approx(geo.catch_radius, abs=1e-9)
        q_d = mp(r_c)[0]
        assert q_d[2] == pytest.approx(QA, abs=1e-12)
        assert np.linalg.norm(model.point(q_d) - r_c) < 1e-9  # r_e(t_c) = 0
        # r_e'(t_c) = d/dt l(f(r_o(t))) - r_o' = 0, by central differences in time
        h = 1e-6
        rp = r_c + th.rd[-1] * h + 0.5 * G * h * h
        rm = r_c - th.rd[-1] * h + 0.5 * G * h * h
        v_hand = (model.point(mp(rp)[0]) - model.point(mp(rm)[0])) / (2 * h)
        assert np.allclose(v_hand, th.rd[-1], atol=1e-4)
    mp.A = np.zeros(mp.A.shape)


# ---------------------------------------------------------------------------- F, eq. 16-17
def test_F_matches_finite_differences(problem):
    mp = problem.mapping
    rng = np.random.default_rng(5)
    mp.A = rng.normal(scale=0.02, size=mp.A.shape)
    th = problem.throws.throws[problem.throws.nominal]
    h = 1e-6
    for r, rd in zip(th.r[::3], th.rd[::3]):
        F = mp.F(r)[0]
        Ffd = np.column_stack([(mp(r + h * e)[0] - mp(r - h * e)[0]) / (2 * h) for e in np.eye(3)])
        assert np.allclose(F, Ffd, rtol=1e-6, atol=1e-6)
        # Fdot r' (eq. 16): d/dt of F(r_o(t)) r' along a straight line r_o = r + r' t
        Fdot_rd = (mp.F(r + h * rd)[0] - mp.F(r - h * rd)[0]) / (2 * h) @ rd
        assert np.allclose(fdot_rd(mp, r, rd)[0], Fdot_rd, rtol=1e-5, atol=1e-4)
    mp.A = np.zeros(mp.A.shape)


def test_torque_eq17_equals_inverse_dynamics(problem, solved):
    """tau = M F r'' + M Fdot r' + H qd + g (eq. 17) vs the chain's RNEA on q_d(t) differentiated
    numerically in time along a ballistic throw."""
    res, _ = solved
    mp, model = problem.mapping, problem.model
    mp.A = res.alpha.reshape(mp.A.shape)
    chain = _chain()
    th = problem.throws.throws[0]
    h = 1e-4
    for tk in np.linspace(0.0, th.t[-1] - 2 * h, 7):
        ts = tk + np.array([-h, 0.0, h]) + h
        r = th.r[0] + np.outer(ts, th.rd[0]) + 0.5 * np.outer(ts * ts, G)
        q3 = mp(r)
        qd_fd = (q3[2] - q3[0]) / (2 * h)
        qdd_fd = (q3[2] - 2 * q3[1] + q3[0]) / h**2
        r1, rd1 = r[1], th.rd[0] + G * ts[1]
        F = mp.F(r1)[0]
        qd = F @ rd1  # eq. 23
        qdd = F @ G + fdot_rd(mp, r1, rd1)[0]  # eq. 16
        assert np.allclose(qd, qd_fd, rtol=1e-5, atol=1e-5)
        full = model.full
        M = chain.mass_matrix(full(q3[1]))[np.ix_([0, 1, 3], [0, 1, 3])]
        Hg = chain.rnea(full(q3[1]), model.full_rate(qd), np.zeros(4))[[0, 1, 3]]
        tau17 = M @ (F @ G) + M @ fdot_rd(mp, r1, rd1)[0] + Hg
        tau_id = chain.rnea(full(q3[1]), model.full_rate(qd_fd), model.full_rate(qdd_fd))
        assert np.allclose(tau17, tau_id[[0, 1, 3]], rtol=2e-3, atol=2e-2)
        assert np.allclose(tau17, model.tau(q3[1], qd, qdd), atol=1e-9)
    mp.A = np.zeros(mp.A.shape)


# ---------------------------------------------------------------------------- eq. 13-14, 25
def test_initial_alpha_is_min_norm_and_feasible(problem):
    a0 = initial_alpha(problem.C, problem.rhs)
    assert problem.C.shape == (6, 30)
    assert np.abs(problem.C @ a0 - problem.rhs).max() < 1e-9
    # minimum norm: orthogonal to the null space of C
    _, s, Vt = np.linalg.svd(problem.C)
    assert np.abs(Vt[6:] @ a0).max() < 1e-9 * max(1.0, np.linalg.norm(a0))


def test_optimisation_keeps_equality_and_lowers_both_costs(problem, solved):
    res, cpu = solved
    assert cpu < 60.0  # a bound on the work (make bench times it)
    assert res.constraint_residual < 1e-8
    first, last = res.history[0], res.history[-1]
    assert last.torque_cost < first.torque_cost
    assert last.velocity_cost < first.velocity_cost
    assert last.objective < first.objective
    assert [h.iteration for h in res.history] == list(range(len(res.history)))
    # eq. 9: the desired trajectory starts at the arm's posture, at rest (nominal throw)
    mp = problem.mapping
    mp.A = res.alpha.reshape(mp.A.shape)
    q, qd, _, _ = mp.evaluate(problem.config.throw_start, problem.nominal_velocity, G)
    assert np.allclose(q[0], [0.0, math.pi / 4, 0.0], atol=1e-8)
    assert np.allclose(qd[0], 0.0, atol=1e-8)
    mp.A = np.zeros(mp.A.shape)


def test_optimisation_is_deterministic(solved):
    res, _ = solved
    again = build_problem(
        _model(), ProblemConfig(tau_max=(60.0, 60.0, 30.0), omega_max=(3.0, 3.0, 3.0))
    ).solve()
    assert np.array_equal(res.alpha, again.alpha)


# ---------------------------------------------------------------------------- estimator
def test_ballistic_estimator_and_time_to_contact():
    est = BallisticEstimator(G, window=0.05)
    r0, v0 = np.array([3.0, 0.1, 1.0]), np.array([-9.0, -0.2, 0.5])
    for k in range(30):
        t = k * 1e-3
        est.add(t, r0 + v0 * t + 0.5 * G * t * t)
    t = 0.035
    r, v, a = est.state(t)
    assert np.allclose(r, r0 + v0 * t + 0.5 * G * t * t, atol=1e-9)
    assert np.allclose(v, v0 + G * t, atol=1e-9)
    origin, R = np.array([0.0, 0.0, 0.346]), 0.7
    tc = est.time_to_radius(t, origin, R)
    rc = r0 + v0 * tc + 0.5 * G * tc * tc
    assert np.linalg.norm(rc - origin) == pytest.approx(R, abs=1e-9)


def test_launch_velocity():
    v0, T = launch_velocity([3, 0, 1], [0.7, 0, 0.5], 9.0, G)
    assert np.linalg.norm(v0) == pytest.approx(9.0)
    th = sample_throw([3, 0, 1], v0, T, 5, G)
    assert np.allclose(th.r[-1], [0.7, 0, 0.5], atol=1e-12)


# ---------------------------------------------------------------------------- controller
def _closed_loop(ctl, spec, speed=9.0, offset=(0.0, 0.0, 0.0)):
    """Arm integrated with the model's own dynamics (J3 locked), ball ballistic, vision = true
    position one 1 ms frame late, joint state without delay."""
    chain, act = spec.model, [0, 1, 3]
    q, qd = spec.initial_q.copy(), np.zeros(4)
    start = np.array(ctl.params.throw_start)
    v0, T = launch_velocity(start, ctl.problem.catch_point + np.asarray(offset), speed, G)
    pending, out = None, []
    for k in range(int((T + 0.03) / 1e-3)):
        t = k * 1e-3
        rb = start + v0 * t + 0.5 * G * t * t
        meas = [
            (
                "/arm/joint_state",
                JointState(t, list(chain.joint_names), q.tolist(), qd.tolist(), []),
            )
        ]
        if pending is not None:
            meas.append(("/vision/object", pending))
        pending = VisionObject(t, rb.tolist())
        cmd = ctl.update(t, meas)
        tel = ctl.telemetry(t)
        tau = np.asarray(cmd.torque)
        M = chain.mass_matrix(q)[np.ix_(act, act)]
        b = chain.rnea(q, qd, np.zeros(4))[act]
        qdd = np.zeros(4)
        qdd[act] = np.linalg.solve(M, tau[act] - b)
        qd = qd + qdd * 1e-3
        q = q + qd * 1e-3
        out.append((t, np.linalg.norm(ctl.model.fk(q) - rb), cmd, tel))
    return T, out


def test_controller_catches_nominal_throw(alpha_file):
    spec = _spec()
    ctl = CatchingController(Params(alpha_file=alpha_file), spec=spec)
    assert ctl.result is None  # read from the file, not solved
    T, out = _closed_loop(ctl, spec)
    dist = np.array([o[1] for o in out])
    assert dist.min() < 0.01
    cmd, tel = out[0][2], out[0][3]
    assert isinstance(cmd, ArmCommand) and len(cmd.torque) == 4 and len(cmd.hand) == 3
    assert np.all(np.abs(np.array([o[2].torque for o in out])) <= spec.torque_limits + 1e-9)
    assert isinstance(tel["/arm/joint_command"], JointCommand)
    assert isinstance(tel["/effector/state"], EffectorState)
    assert len(tel["/effector/state"].position) == 3
    events = ctl.pop_events()
    close = [e for e in events if e.kind == "hand_close"]
    assert len(close) == 1
    assert close[0].data["predicted_catch_time"] == pytest.approx(T, abs=2e-3)
    t_closed = next(o[0] for o in out if o[2].hand[0] > 0.0)
    assert t_closed == pytest.approx(T - ctl.close_time, abs=2e-3)  # closing ends on arrival
    assert ctl.intent()["catch_time"] == pytest.approx(T, abs=2e-3)
    costs = ctl.optimization_costs()
    assert costs and isinstance(costs[0], OptimizationCost)


def test_controller_initial_mapping_and_stale_alpha_file(tmp_path, alpha_file):
    spec = _spec()
    ctl = CatchingController(Params(mapping="initial"), spec=spec)
    assert np.allclose(ctl.mapping.alpha, ctl.alpha0)
    assert len(ctl.optimization_costs()) == 1
    T, out = _closed_loop(ctl, spec, speed=8.0)
    assert min(o[1] for o in out) < 0.02
    data = load_alpha(alpha_file)
    assert data["meta"]["key"] and len(data["alpha"]) == 30
    # a file made for another configuration is not used silently
    other = CatchingController(
        Params(alpha_file=alpha_file, throw_spread=0.05, max_iterations=2), spec=spec
    )
    assert any(e.kind == "warning" for e in other.pop_events())
    # nor is a file that is not there replaced by an optimum without a word
    missing = CatchingController(
        Params(alpha_file=str(tmp_path / "typo.json"), max_iterations=2), spec=spec
    )
    said = [e.data["reason"] for e in missing.pop_events() if e.kind == "warning"]
    assert said == ["alpha_file not found; optimised here"]


def test_controller_holds_pose_before_the_ball_is_seen():
    spec = _spec()
    ctl = CatchingController(Params(mapping="initial"), spec=spec)
    q = spec.initial_q
    js = JointState(0.0, list(spec.joint_names), q.tolist(), [0.0] * 4, [])
    cmd = ctl.update(0.0, [("/arm/joint_state", js)])
    g = spec.model.gravity_torque(q)
    assert np.allclose(np.asarray(cmd.torque)[[0, 1, 3]], g[[0, 1, 3]], atol=1e-9)
    assert np.allclose(cmd.hand, spec.hand.open_posture)
    assert "/catching/state" not in ctl.telemetry(0.0)


def test_params_refuse_a_held_selected_joint_and_unpaired_gains():
    """Checked on the params themselves (so ``replay validate --static`` and the scenario's
    line:col point at them), not only when the controller is built."""
    with pytest.raises(ParamError) as held:
        Params(selected_joint="J4", held_joints=["J3", "J4"])
    assert held.value.field == "selected_joint"
    with pytest.raises(ParamError) as gains:
        Params(kp=[1.0, 2.0, 3.0, 4.0], kd=[1.0, 2.0])
    assert gains.value.field == "kd" and "(4), got 2" in gains.value.message
    assert Params(selected_joint="J4", held_joints=["J3"]).selected_joint == "J4"


# ---------------------------------------------------------------------------- approach (extension)
@pytest.fixture(scope="module")
def approach_problem():
    """The default throw set with eq. 24's omega_max that eq. 4 permits and the approach term."""
    return build_problem(
        _model(),
        ProblemConfig(
            tau_max=(60.0, 60.0, 30.0),
            omega_max=(4.0, 14.0, 40.0),
            approach_weight=10.0,
            max_iter=15,
        ),
    )


def test_approach_term_is_the_relative_acceleration_at_tc(approach_problem):
    """r_e''(t_c) of approach.py (linear in alpha) against a central difference of
    r_e(t) = l(f(r_o(t))) - r_o(t) along the sampled throws, for two alphas."""
    pb = approach_problem
    term = pb.objective.approach
    rng = np.random.default_rng(3)
    alphas = [
        initial_alpha(pb.C, pb.rhs),
        initial_alpha(pb.C, pb.rhs) + 0.05 * rng.standard_normal(pb.poly.n_alpha),
    ]
    h = 2e-4
    for alpha in alphas:
        acc = term.accel(alpha)
        for k, th in enumerate(pb.throws.throws[::4]):
            kk = 4 * k
            t_c = th.t[-1]
            v0 = th.rd[0]
            rs = [th.r[0] + v0 * t + 0.5 * G * t * t for t in (t_c - h, t_c, t_c + h)]
            A = np.asarray(alpha).reshape(pb.poly.n_mono, 3)
            re = [pb.model.point(pb.mapping.evaluate(r[None], A=A)[0][0]) - r for r in rs]
            fd = (re[0] + re[2] - 2 * re[1]) / (h * h)
            assert np.linalg.norm(re[1]) < 1e-9  # eq. 4 at t_c
            assert np.allclose(acc[kk], fd, rtol=1e-3, atol=1e-2 * np.linalg.norm(fd)), kk
    # the ball approaches from in front of the palm (angle < 90 deg) with the initial alpha
    assert np.all(term.angles(alphas[0]) < 30.0)


def test_approach_jacobian_and_the_extension_lowers_it(approach_problem):
    pb = approach_problem
    term = pb.objective.approach
    a0 = initial_alpha(pb.C, pb.rhs)
    rng = np.random.default_rng(5)
    d = rng.standard_normal(a0.shape) * 1e-3
    fd = (term.residuals(a0 + d) - term.residuals(a0 - d)) / 2
    assert np.allclose(term.jacobian() @ d, fd, atol=1e-10)  # linear in alpha
    res = pb.solve()
    assert res.history[-1].approach_cost < res.history[0].approach_cost
    assert res.history[-1].objective < res.history[0].objective
    assert res.constraint_residual < 1e-9


# ------------------------------------------- the clamp-aware extension (not in the paper, #21)
def test_clamped_cost_jacobian_and_its_reduction_to_eq25():
    """The 'clamped' torque cost's Jacobian matches central differences at a random alpha near
    alpha0 (away from the clamp's kinks), and with limits no sample reaches it is eq. 25."""
    from dataclasses import replace

    model = _model()
    base = ProblemConfig(tau_max=(60.0, 60.0, 30.0), omega_max=(3.0, 13.5, 37.0), max_iter=3)
    pb = build_problem(model, replace(base, torque_cost="clamped", excess_weight=0.1))
    obj = pb.objective
    rng = np.random.default_rng(21)
    a = initial_alpha(pb.C, pb.rhs) + rng.standard_normal(pb.C.shape[1]) * 1e-3
    r, tau, J = obj.jacobian(a)
    d = rng.standard_normal(a.shape) * 1e-6
    fd = (obj.residuals(a + d)[0] - obj.residuals(a - d)[0]) / 2
    # rows whose torque sample crosses a limit within +-d are kinks: leave them out
    tp, tm = obj.torques(a + d), obj.torques(a - d)
    lim = obj.tau_max
    kink = ((np.abs(tp) > lim) != (np.abs(tm) > lim)).ravel()
    n = tau.size
    keep = np.ones(len(r), bool)
    for k in (0, 1, 3):  # sat, excess and the eq.-22 hinge rows kink at the limits
        keep[k * n : (k + 1) * n][kink] = False
    assert np.any(np.abs(tau) > lim)  # the 9 m/s set saturates: the test sees both branches
    np.testing.assert_allclose((J @ d)[keep], fd[keep], rtol=1e-3, atol=1e-9)
    big = replace(base, tau_max=(1e5, 1e5, 1e5))
    e25 = build_problem(model, big).objective
    ext = build_problem(model, replace(big, torque_cost="clamped")).objective
    assert ext.record(0, a).objective == pytest.approx(e25.record(0, a).objective, rel=1e-12)
    assert ProblemConfig().key() == replace(ProblemConfig(), excess_weight=0.1).key()
    assert ProblemConfig().key() != replace(ProblemConfig(), torque_cost="clamped").key()
