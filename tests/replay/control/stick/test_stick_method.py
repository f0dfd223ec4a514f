"""Higashimori et al. 2007: the friction independent collision (Sec. II), the side rules of the
2-step and 3-step strategies (Sec. III), numbers derived from Sec. IV, and the controllers driven
by synthetic measurements (no simulator)."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from replay.robot import hand2d
from replay.control.stick import collision as sc
from replay.robot import stick_impact as si
from replay.control.stick.strategy import (
    HandModel,
    ThreeStepController,
    ThreeStepParams,
    TwoStepController,
    TwoStepParams,
    Config,
)
from replay.robot.hand2d import AirTableSpec, HandSpec, StickSpec
from replay.interfaces import Controller
from replay.messages import VisionStick

from tests.replay.control.stick import oracles

# Sec. IV-A: L = 100 mm, W = 10 mm, m = 22.5 g, I = 32.0e3 g mm^2, e = 0.19
M, INERTIA, E, L, W = 0.0225, 3.2e-5, 0.19, 0.100, 0.010
V0 = 1.1  # m/s, Fig. 7
OMEGA_1 = -10.0  # rad/s, Fig. 7


def J(theta, r_x, side, u, m=M, inertia=INERTIA, e=E):
    return oracles.axis_map(m, inertia, e, theta, r_x, side) @ np.asarray(u, dtype=float)


# ---------------------------------------------------------------------------------------------
# Sec. II-D: the quadratics reproduce the desired velocity through J exactly
# ---------------------------------------------------------------------------------------------


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    m=st.floats(0.005, 0.5),
    inertia=st.floats(1e-6, 1e-3),
    e=st.floats(0.0, 1.0),
    theta=st.floats(-3.2, 3.2),
    vx=st.floats(-3, 3),
    vy=st.floats(-3, 3),
    w=st.floats(-40, 40),
    side=st.sampled_from([1, -1]),
    w_d=st.floats(-40, 40),
)
def test_f_omega_roots_give_the_desired_spin(m, inertia, e, theta, vx, vy, w, side, w_d):
    u = np.array([vx, vy, w])
    for r in sc.f_omega(m, inertia, e, theta, side, u, w_d):  # eq. 25
        if abs(r) > 10.0:
            continue
        after = J(theta, r, side, u, m, inertia, e)  # eq. 24
        assert after[2] == pytest.approx(w_d, abs=1e-7 * (1 + abs(w) + abs(w_d)))


@settings(max_examples=300, deadline=None, derandomize=True)
@given(
    m=st.floats(0.005, 0.5),
    inertia=st.floats(1e-6, 1e-3),
    e=st.floats(0.0, 1.0),
    heading=st.floats(-3.2, 3.2),
    speed=st.floats(0.05, 3),
    w=st.floats(-40, 40),
    side=st.sampled_from([1, -1]),
    v_d=st.floats(-3, 3),
    flip=st.booleans(),
)
def test_f_v_roots_give_the_desired_speed(m, inertia, e, heading, speed, w, side, v_d, flip):
    v = speed * np.array([math.cos(heading), math.sin(heading)])
    u = np.array([v[0], v[1], w])
    theta = sc.alpha(v) + (math.pi if flip else 0.0)  # eq. 23 (either branch)
    assert sc.friction_independent(theta, v, side)  # eq. 12
    for r in sc.f_v(m, inertia, e, theta, side, u, v_d):  # eq. 28
        if abs(r) > 10.0:
            continue
        after = J(theta, r, side, u, m, inertia, e)
        V = -float(np.dot(v / speed, after[:2]))  # eq. 27
        assert V == pytest.approx(v_d, abs=1e-7 * (1 + speed + abs(v_d)))
        s, _ = oracles.tangent_normal(theta, side)
        assert float(np.dot(s, after[:2])) == pytest.approx(0.0, abs=1e-9 * (1 + speed))  # eq. 17


def test_paper_b1_holds_for_the_upper_side_only():
    """Eq. 25 as printed (b_1 = -(1+e) m n^T v) gives the stated omega for ^B r_y = +W/2; for
    -W/2 it gives -r_x (its r_x is measured along s_i = -x_B there)."""
    u = np.array([V0, 0.0, 9.9])
    theta = sc.alpha(u[:2])
    for side in (1, -1):
        _, n = oracles.tangent_normal(theta, side)
        a1, b1, c1 = M * (0 + E * u[2]), -(1 + E) * M * float(n @ u[:2]), INERTIA * (0 - u[2])
        printed = sorted(np.roots([a1, b1, c1]).real)
        ours = sc.f_omega(M, INERTIA, E, theta, side, u, 0.0)
        if side > 0:
            assert np.allclose(printed, ours)
        else:
            assert np.allclose(sorted(-r for r in printed), ours)
            assert abs(J(theta, printed[0], side, u)[2]) > 1.0  # the printed root misses


def test_side_enters_only_through_the_approach():
    """With W ~ 0, J_i is the same on both sides (n n^T); the side decides which root approaches."""
    u = np.array([0.3, -0.8, 7.0])
    theta = 0.4
    for r in (-0.04, 0.01, 0.03):
        assert np.allclose(
            oracles.axis_map(M, INERTIA, E, theta, r, 1),
            oracles.axis_map(M, INERTIA, E, theta, r, -1),
        )
        assert np.allclose(
            oracles.axis_map(M, INERTIA, E, theta, r, 1),
            oracles.axis_map(M, INERTIA, E, theta + math.pi, -r, -1),
        )
        up, down = sc.approach_speed(theta, r, 1, u), sc.approach_speed(theta, r, -1, u)
        assert up == pytest.approx(-down)


def test_condition_c_picks_the_approaching_root():
    u = np.array([V0, 0.0, 9.9185])
    theta = sc.alpha(u[:2])
    for side in (1, -1):
        roots = sc.f_omega(M, INERTIA, E, theta, side, u, 0.0)
        assert len(roots) == 2
        cs = [oracles.contact_condition(M, INERTIA, E, theta, r, side, u) for r in roots]
        ap = [sc.approach_speed(theta, r, side, u) for r in roots]
        for c, a in zip(cs, ap):
            assert c == pytest.approx(E * a)  # eq. 10: C = -e n^T v_C,before
        assert sum(c > 0 for c in cs) == 1  # one approaching root per side
        sol = oracles.solve_contact(M, INERTIA, E, theta, side, u, omega=0.0, length=L)
        assert sol.condition > 0 and sc.approach_speed(theta, sol.r_x, side, u) > 0
    # the contact point of the rejected root moves away from the fingertip before the collision
    bad = [
        r
        for r in sc.f_omega(M, INERTIA, E, theta, -1, u, 0.0)
        if oracles.contact_condition(M, INERTIA, E, theta, r, -1, u) <= 0
    ]
    assert bad and sc.approach_speed(theta, bad[0], -1, u) < 0


def test_solve_contact_without_a_valid_root():
    # a stick at rest: nothing approaches any fingertip
    assert oracles.solve_contact(M, INERTIA, E, 0.3, 1, [0.0, 0.0, 0.0], omega=1.0) is None
    with pytest.raises(ValueError):
        oracles.solve_contact(M, INERTIA, E, 0.3, 1, [1.0, 0.0, 0.0])


# ---------------------------------------------------------------------------------------------
# Sec. III: side rules
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("heading", [0.0, -math.pi / 2, 2.3, -0.7])
@pytest.mark.parametrize("w0", [9.9185, -6.0, 20.0])
def test_two_step_first_collision(heading, w0):
    v0 = V0 * np.array([math.cos(heading), math.sin(heading)])
    sol = sc.two_step_first(M, INERTIA, E, [*v0, w0], L)  # eq. 30
    after = np.array(sol.u_after)
    assert sol.theta == pytest.approx(sc.alpha(v0))
    assert after[2] == pytest.approx(0.0, abs=1e-9)  # omega_1 = 0
    assert np.dot(after[:2], v0) < 0  # eq. 31, p = -1
    assert abs(after[0] * v0[1] - after[1] * v0[0]) < 1e-9  # along the line of v_0
    assert sol.within and sol.condition > 0
    # the alternative on the other side keeps moving forward (p = +1) beyond the stick
    others = [
        s
        for s in sc.contact_options(M, INERTIA, E, sol.theta, [*v0, w0], omega=0.0, length=L)
        if s.side != sol.side
    ]
    assert all(np.dot(s.u_after[:2], v0) > 0 for s in others)


def test_three_step_first_collision_fig7():
    """Fig. 7: v_0 = 1.1 m/s stopped, omega_1 = -10 rad/s; eq. 35 picks r_x = -25.75 mm."""
    (w0, d), _ = si.spin_before_pure_rotation(M, INERTIA, E, V0, OMEGA_1)
    u0 = np.array([V0, 0.0, w0])
    sol = sc.three_step_first(M, INERTIA, E, u0, L)  # eq. 34
    after = np.array(sol.u_after)
    assert np.allclose(after[:2], 0.0, atol=1e-12)  # v_1 = 0
    assert after[2] == pytest.approx(OMEGA_1)
    assert after[2] * w0 < 0  # eq. 35
    assert abs(sol.r_x) == pytest.approx(d)
    # both roots on that side approach (eq. 26 does not decide); eq. 35 does
    opts = sc.contact_options(M, INERTIA, E, sol.theta, u0, speed=0.0, length=L)
    assert len([o for o in opts if o.side == sol.side]) == 2
    assert [o.u_after[2] * w0 < 0 for o in opts].count(True) == 1


@pytest.mark.parametrize("lam", [(1, 0), (-1, 0), (0, 1), (0.6, -0.8)])
@pytest.mark.parametrize("w1", [OMEGA_1, 25.0])
def test_three_step_second_collision_follows_lambda(lam, w1):
    lam = np.array(lam, dtype=float)
    sol = sc.three_step_second(M, INERTIA, E, [0.0, 0.0, w1], lam, L)  # eq. 36
    after = np.array(sol.u_after)
    assert sol.theta == pytest.approx(sc.alpha(lam))
    assert after[2] == pytest.approx(0.0, abs=1e-9)  # omega_2 = 0
    assert np.allclose(after[:2] / np.linalg.norm(after[:2]), lam)  # eq. 37
    assert abs(sol.r_x) == pytest.approx(si.pure_rotation_stop_distance(M, INERTIA, E))
    assert not sol.within  # 86.5 mm > L/2


def test_closing_contact_reverses_the_translation():
    theta = 0.7
    v = 0.3 * np.array([-math.sin(theta), math.cos(theta)])
    sol = sc.closing_contact(M, INERTIA, E, [*v, 0.0], L)  # eq. 32 / 38
    assert sol.r_x == 0.0 and sol.condition > 0
    assert np.allclose(sol.u_after, [*(-E * v), 0.0])  # eq. 33
    assert sc.closing_contact(M, INERTIA, E, [0.0, 0.0, 3.0]) is None


# ---------------------------------------------------------------------------------------------
# Derived numbers (Sec. IV-B, Fig. 7) -- stated values, not bent
# ---------------------------------------------------------------------------------------------


def test_initial_spin_for_fig7():
    pairs = si.spin_before_pure_rotation(M, INERTIA, E, V0, OMEGA_1)
    (w_a, d_a), (w_b, d_b) = pairs
    assert w_a == pytest.approx(9.92, abs=0.01) and d_a == pytest.approx(0.02575, abs=1e-5)
    assert w_b == pytest.approx(32.71, abs=0.01) and d_b == pytest.approx(0.0552, abs=1e-4)
    assert d_a < L / 2 < d_b
    for w0, d in pairs:  # round trip through J (eq. 22)
        after = J(sc.alpha([V0, 0.0]), -d, -1, [V0, 0.0, w0])
        assert np.allclose(after, [0.0, 0.0, OMEGA_1], atol=1e-9)
    # no initial spin leaves less than this spin after a full stop at 1.1 m/s
    w_min = si.pure_rotation_min_spin(M, INERTIA, E, V0)
    assert w_min == pytest.approx(9.314, abs=1e-3)
    assert si.spin_before_pure_rotation(M, INERTIA, E, V0, -0.999 * w_min) == []
    assert len(si.spin_before_pure_rotation(M, INERTIA, E, V0, -1.001 * w_min)) == 2


def test_second_collision_distance_with_the_stated_numbers():
    """Sec. IV-B states r_x,2 = 48.7 mm < L/2; with m, I, e of Sec. IV-A eq. 25 gives 86.5 mm."""
    d = si.pure_rotation_stop_distance(M, INERTIA, E)
    assert d == pytest.approx(0.0865, abs=5e-4)
    assert d > L / 2
    sol = oracles.solve_contact(
        M, INERTIA, E, math.pi / 2, 1, [0.0, 0.0, OMEGA_1], omega=0.0, length=L
    )
    assert abs(sol.r_x) == pytest.approx(d) and not sol.within
    # what the stated 48.7 mm would need: e = I / (m r^2) = 0.60 with the same m and I
    assert INERTIA / (M * 0.0487**2) == pytest.approx(0.60, abs=0.01)
    # the least spin at the stick's tip (fallback) and what it leaves
    ratio = si.pure_rotation_residual_spin(M, INERTIA, E, 0.045)
    assert ratio == pytest.approx(0.301, abs=1e-3)
    after = J(math.pi / 2, 0.045, -1, [0.0, 0.0, OMEGA_1])
    assert after[2] == pytest.approx(ratio * OMEGA_1)


# ---------------------------------------------------------------------------------------------
# Controllers on synthetic measurements
# ---------------------------------------------------------------------------------------------


HOME = ((0.0, -0.1), ((math.pi / 2, 0.3), (math.pi / 2, -0.3)))
PLANT_HOME = ((0.0, 0.0), ((2.0, -1.0), (math.pi - 2.0, 1.0)))  # the airtable plant's default


def hand_spec(q1_limits=(-0.3, math.pi + 0.3), home=HOME) -> HandSpec:
    return HandSpec(
        root_offsets=((-0.03, 0.0), (0.03, 0.0)),
        link_lengths=(0.07, 0.07),
        joint_limits=(q1_limits, (-2.6, 2.6)),
        joint_speed=14.0,
        base_limits=((-0.2, 0.2), (-0.2, 0.2)),
        base_speed=1.0,
        tip_radius=0.005,
        start_base=home[0],
        start_joints=home[1],
    )


def air_spec(e=E, width=W, q1_limits=(-0.3, math.pi + 0.3), home=HOME) -> AirTableSpec:
    return AirTableSpec(
        hand_spec(q1_limits, home),
        StickSpec(mass=M, inertia=INERTIA, length=L, width=width, restitution=e),
    )


class SyntheticStick:
    """Piecewise constant velocities; the camera sees it at 300 fps with a latency."""

    def __init__(self, state, fps=300.0, latency=0.005):
        self.segments = [(0.0, np.array(state, dtype=float))]  # (t0, [x, y, th, vx, vy, w])
        self.fps, self.latency = fps, latency
        self.frame = 0

    def state(self, t):
        t0, s = [seg for seg in self.segments if seg[0] <= t][-1]
        return np.concatenate([s[:3] + s[3:] * (t - t0), s[3:]])

    def change(self, t, u):
        s = self.state(t)
        self.segments.append((t, np.concatenate([s[:3], u])))

    def delivered(self, t):
        out = []
        while self.frame / self.fps + self.latency <= t + 1e-12:
            tc = self.frame / self.fps
            x, y, th = self.state(tc)[:3]
            th = (th + math.pi / 2) % math.pi - math.pi / 2  # (-pi/2, pi/2]
            if th <= -math.pi / 2 + 1e-12:
                th += math.pi
            out.append(("/vision/stick", VisionStick(tc, float(x), float(y), float(th))))
            self.frame += 1
        return out


def drive(ctrl, stick, t_end, on_step=None):
    """Call the controller at 1 kHz; returns (commands, events)."""
    commands, events = [], []
    for i in range(int(round(t_end * 1000)) + 1):
        t = i / 1000.0
        cmd = ctrl.update(t, stick.delivered(t))
        commands.append((t, cmd))
        events += [(t, ev) for ev in ctrl.pop_events()]
        if on_step is not None:
            on_step(t, ctrl)
    return commands, events


def assert_reachable(hand: HandSpec, cmd):
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    assert xlo - 1e-9 <= cmd.base[0] <= xhi + 1e-9 and ylo - 1e-9 <= cmd.base[1] <= yhi + 1e-9
    for q in cmd.joints:
        for v, (lo, hi) in zip(q, hand.joint_limits):
            assert lo - 1e-9 <= v <= hi + 1e-9


def test_params_declare_unit_doc_and_range():
    for cls in (TwoStepParams, ThreeStepParams):
        for f in dataclasses.fields(cls):
            meta = f.metadata
            assert meta["unit"] and meta["doc"], f.name
            assert any(meta[k] is not None for k in ("ge", "gt", "le", "lt", "choices")), f.name
    assert issubclass(TwoStepController, Controller) and issubclass(ThreeStepController, Controller)


@pytest.mark.parametrize(
    "cls,params", [(TwoStepController, TwoStepParams), (ThreeStepController, ThreeStepParams)]
)
def test_first_collision_is_planned_at_alpha_and_the_right_spot(cls, params):
    spec = air_spec()
    w0 = 9.9185
    state0 = [-0.45, 0.0, 0.3, V0, 0.0, w0]
    stick = SyntheticStick(state0)
    ctrl = cls(params(), spec=spec)
    commands, events = drive(ctrl, stick, 0.30)
    plans = [ev for _, ev in events if ev.kind == "plan"]
    assert plans and ctrl.phase == "approach"
    intent = ctrl.intent()
    for key in ("index", "finger", "t", "theta", "r_x", "r_y", "v_after", "omega_after"):
        assert key in intent
    assert intent["index"] == 1
    # theta = alpha(v_0) (mod pi), at the time the ideal stick gets there
    theta_star = sc.alpha([V0, 0.0])
    t_c = intent["t"]
    x, y, th = stick.state(t_c)[:3]
    assert math.remainder(th - theta_star, math.pi) == pytest.approx(0.0, abs=1e-6)
    assert math.remainder(intent["theta"] - theta_star, math.pi) == pytest.approx(0.0, abs=1e-6)
    assert intent["theta"] == pytest.approx(th, abs=1e-6)  # same continuous frame
    # the contact point and the fingertip centre
    expected = (sc.two_step_first if cls is TwoStepController else sc.three_step_first)(
        M, INERTIA, E, [V0, 0.0, w0], L
    )
    flip = 1 if round((th - expected.theta) / math.pi) % 2 == 0 else -1
    assert intent["r_x"] == pytest.approx(flip * expected.r_x, abs=1e-6)
    assert intent["r_y"] == pytest.approx(flip * expected.side * W / 2)
    contact = np.array([x, y]) + oracles.rotation(th) @ np.array([intent["r_x"], intent["r_y"]])
    assert np.allclose(intent["contact"], contact, atol=1e-6)
    _, n = oracles.tangent_normal(th, intent["side"])
    assert np.allclose(intent["tip"], contact - spec.hand.tip_radius * n, atol=1e-6)
    assert np.allclose(intent["v_after"], expected.u_after[:2], atol=1e-6)
    assert intent["omega_after"] == pytest.approx(expected.u_after[2], abs=1e-6)
    # every command is within the hand's limits and the last one puts the finger on the spot
    for _, cmd in commands:
        assert_reachable(spec.hand, cmd)
    cmd = commands[-1][1]
    tip = hand2d.finger_tip(spec.hand, cmd.base, intent["finger"], cmd.joints[intent["finger"]])
    assert np.allclose(tip, intent["tip"], atol=1e-9)
    # the hand (moving at its limits from home) is there before the contact
    model = HandModel(spec.hand, ctrl._home())
    for t, c in commands:
        model.advance(t)
        model.target = Config(c.base, c.joints)
    model.advance(t_c - ctrl.params.arrive_margin)
    assert np.allclose(model.config.tip(spec.hand, intent["finger"]), intent["tip"], atol=1e-9)
    # the other fingertip is clear of the stick at the contact
    other = model.config.tip(spec.hand, 1 - intent["finger"])
    assert np.linalg.norm(other - np.array([x, y])) > W / 2 + spec.hand.tip_radius


def test_three_step_reports_the_86_mm_second_collision_and_falls_back():
    spec = air_spec()
    w0, _ = si.spin_before_pure_rotation(M, INERTIA, E, V0, OMEGA_1)[0]
    stick = SyntheticStick([-0.45, 0.0, 0.3, V0, 0.0, w0])
    ctrl = ThreeStepController(ThreeStepParams(), spec=spec)
    done = []

    def collide(t, c):  # the ideal stick obeys the plan at the planned instant
        intent = c.intent()
        if intent and intent["index"] == len(done) + 1 <= 2 and t >= intent["t"] - 1e-9:
            stick.change(intent["t"], [*intent["v_after"], intent["omega_after"]])
            done.append(intent)

    _, events = drive(ctrl, stick, 1.60, on_step=collide)
    for _, ev in events:
        json.dumps(ev.data, allow_nan=False)
    assert done and done[0]["omega_after"] == pytest.approx(OMEGA_1, abs=1e-3)
    infeasible = [ev.data for _, ev in events if ev.kind == "infeasible"]
    assert len(infeasible) == 1
    data = infeasible[0]
    assert data["step"] == 2 and data["reason"] == "r_x_beyond_stick"
    assert abs(data["r_x"]) == pytest.approx(0.0865, abs=5e-4)
    assert data["limit"] == pytest.approx(L / 2)
    assert abs(data["fallback_r_x"]) == pytest.approx(L / 2 - ctrl.params.tip_margin)
    ratio = si.pure_rotation_residual_spin(M, INERTIA, E, abs(data["fallback_r_x"]))
    assert data["omega_after"] == pytest.approx(ratio * OMEGA_1, rel=1e-3)
    plan2 = [ev.data for _, ev in events if ev.kind == "plan" and ev.data["index"] == 2]
    assert plan2 and plan2[0]["clamped"]
    # the second contact is at theta_2 = alpha(lambda_2) = pi/2 (mod pi): stick perpendicular
    assert math.remainder(plan2[0]["theta"] - math.pi / 2, math.pi) == pytest.approx(0.0, abs=1e-6)
    # the clamped contact leaves ~ -3 rad/s: a spin-stop collision (eq. 30) is added next
    assert len(done) == 2
    u2 = [*done[1]["v_after"], done[1]["omega_after"]]
    plan3 = [ev.data for _, ev in events if ev.kind == "plan" and ev.data["index"] == 3]
    assert plan3 and ctrl.extra == 1
    expected = sc.two_step_first(M, INERTIA, E, u2, L)
    assert abs(plan3[0]["r_x"]) == pytest.approx(abs(expected.r_x), abs=1e-4)
    assert abs(plan3[0]["omega_after"]) < 1e-6 and abs(plan3[0]["r_x"]) < L / 2
    # the outcome (not captured yet: this synthetic stick ignores the later contacts) names the
    # 86.5 mm of collision 2 once the run ends
    o = ctrl.outcome(1.60)
    assert o["infeasible"] == ["r_x_beyond_stick@2"] and o["as_planned"] is False
    assert o["success"] is False and o["method_reason"] == o["reason"]
    assert o["reason"].startswith(
        "infeasible: r_x beyond the stick at collision 2 (|r_x| = 86.5 mm"
    )
    json.dumps(o, allow_nan=False)


class IdealTable:
    """The paper's collision model (W ~ 0, eq. 22, fixed fingertips) on fingertip discs moving as
    commanded at the hand's speed limits. Only for these tests: no friction, no simulator."""

    def __init__(self, spec, ctrl, state, dt=2e-4):
        self.spec, self.ctrl, self.dt = spec, ctrl, dt
        self.s = np.array(state, dtype=float)
        self.hand = HandModel(spec.hand, ctrl.model.config)
        self.collisions = []

    def run(self, t_end, latency=0.005):
        frames, queue, events = 0, [], []
        h, stick = self.spec.hand, self.spec.stick
        for i in range(int(round(t_end / self.dt)) + 1):
            t = i * self.dt
            if frames / 300.0 <= t + 1e-12:
                th = (self.s[2] + math.pi / 2) % math.pi - math.pi / 2
                queue.append((t + latency, VisionStick(t, self.s[0], self.s[1], th)))
                frames += 1
            if i % int(round(1e-3 / self.dt)) == 0:
                ready = [("/vision/stick", m) for td, m in queue if td <= t + 1e-12]
                queue = [(td, m) for td, m in queue if td > t + 1e-12]
                cmd = self.ctrl.update(t, ready)
                self.hand.target = Config(cmd.base, cmd.joints)
                events += [(t, ev) for ev in self.ctrl.pop_events()]
            self.hand.advance(t)
            c, s_ = math.cos(self.s[2]), math.sin(self.s[2])
            for k in (0, 1):
                d = self.hand.config.tip(h, k) - self.s[:2]
                xb, yb = d[0] * c + d[1] * s_, -d[0] * s_ + d[1] * c
                if abs(xb) <= stick.length / 2 and abs(yb) <= stick.width / 2 + h.tip_radius:
                    side = 1 if yb > 0 else -1
                    if sc.approach_speed(self.s[2], xb, side, self.s[3:]) > 1e-9:
                        self.collisions.append((t, k, xb, self.s[3:].copy(), self.ctrl.intent()))
                        self.s[3:] = (
                            oracles.axis_map(
                                stick.mass, stick.inertia, stick.restitution, self.s[2], xb, side
                            )
                            @ self.s[3:]
                        )
            self.s[:3] += self.dt * self.s[3:]
        return events


def test_two_step_captures_on_the_ideal_table():
    spec = air_spec()
    ctrl = TwoStepController(TwoStepParams(), spec=spec)
    table = IdealTable(spec, ctrl, [-0.45, 0.0, 0.3, V0, 0.0, 9.9185])
    events = table.run(0.8)
    assert ctrl.phase == "captured"
    for _, ev in events:  # the log contract: JSON, no NaN
        json.dumps(ev.data, allow_nan=False)
    json.dumps(ctrl.telemetry(0.8), allow_nan=False)
    kinds = [ev.kind for _, ev in events]
    assert "capture" in kinds and "infeasible" not in kinds
    o = ctrl.outcome(0.8)
    assert "success" not in o and o["method_captured"] and o["as_planned"]
    assert o["t_capture_method"] == pytest.approx(
        [ev.data["t_since"] for _, ev in events if ev.kind == "capture"][0]
    )
    t1, k1, r1, u1, intent = table.collisions[0]
    assert intent["index"] == 1 and k1 == intent["finger"]
    assert t1 == pytest.approx(intent["t"], abs=1e-3)
    assert r1 == pytest.approx(intent["r_x"], abs=1e-3)
    assert np.allclose(u1, [V0, 0.0, 9.9185])
    assert abs(table.s[5]) < 0.5 and np.hypot(*table.s[3:5]) < 0.02


def test_three_step_captures_when_the_second_spot_is_on_the_stick():
    """With e = 0.60 (the restitution that makes F_omega,2(0) = 48.7 mm, as stated in Sec. IV-B)
    every contact is on the stick and the three steps run as planned."""
    spec = air_spec(e=0.60)
    ctrl = ThreeStepController(ThreeStepParams(), spec=spec)
    table = IdealTable(spec, ctrl, [-0.45, 0.0, 0.3, V0, 0.0, 5.0])
    events = table.run(0.8)
    kinds = [ev.kind for _, ev in events]
    assert "infeasible" not in kinds and "capture" in kinds
    plans = [ev.data for _, ev in events if ev.kind == "plan"]
    assert [p["index"] for p in plans[:3]] == [1, 2, 3]
    assert abs(plans[1]["r_x"]) == pytest.approx(0.0487, abs=1e-3)
    (t1, _, r1, _, i1), (t2, _, r2, u2, i2) = table.collisions[:2]
    assert np.hypot(*u2[:2]) < 0.01  # v_1 = 0 after the first collision
    assert u2[2] == pytest.approx(i1["omega_after"], rel=0.02)
    assert (i1["index"], i2["index"]) == (1, 2)
    assert t1 == pytest.approx(i1["t"], abs=1e-3) and r1 == pytest.approx(i1["r_x"], abs=1e-3)
    assert t2 == pytest.approx(i2["t"], abs=2e-3) and r2 == pytest.approx(i2["r_x"], abs=2e-3)


def test_two_step_goes_around_the_stick_to_close():
    """The stick comes at the palm (-y) and is sent back (+y): both fingertips start behind it,
    so the front one has to pass an end of the stick (scenario layout, plant's default hand)."""
    spec = air_spec(width=0.0, q1_limits=(-math.pi, math.pi), home=PLANT_HOME)
    ctrl = TwoStepController(TwoStepParams(), spec=spec)
    table = IdealTable(spec, ctrl, [0.0, 0.461, 0.06643, 0.0, -V0, 9.9185])
    events = table.run(0.75)
    kinds = [ev.kind for _, ev in events]
    assert "capture" in kinds and "infeasible" not in kinds
    t1, _, _, _, intent = table.collisions[0]
    assert t1 == pytest.approx(0.31, abs=2e-3)  # theta(0.31 s) = alpha(v_0) (mod pi)
    y1 = 0.461 - V0 * t1  # the stick's centre at collision 1
    closing = [ev.data for _, ev in events if ev.kind == "plan" and ev.data["index"] == 2][0]
    assert closing["finger"] != intent["finger"]
    assert closing["tip"][1] > y1 + 0.03  # waits ahead of the returning stick
    assert len(ctrl.close.route) == 3  # via two waypoints beside an end


def test_out_of_reach_is_reported_once_the_chance_has_passed():
    spec = air_spec()
    stick = SyntheticStick([-0.5, 0.6, 0.3, V0, 0.0, 9.9185])  # 0.6 m: beyond every fingertip
    ctrl = TwoStepController(TwoStepParams(), spec=spec)
    commands, events = drive(ctrl, stick, 0.7)
    assert not [ev for _, ev in events if ev.kind == "plan"]
    lost = [(t, ev.data) for t, ev in events if ev.kind == "infeasible"]
    assert len(lost) == 1
    t, data = lost[0]
    assert data["reason"] == "unreachable" and data["step"] == 1
    o = ctrl.outcome(0.7)
    assert o["success"] is False and o["reason"].startswith("out of reach: ")
    assert data["t_contact"] < t  # reported after the chance passed
    theta_star = sc.alpha([V0, 0.0])
    th = stick.state(data["t_contact"])[2]
    assert math.remainder(th - theta_star, math.pi) == pytest.approx(0.0, abs=0.05)
    json.dumps(data, allow_nan=False)
    for _, cmd in commands:
        assert_reachable(spec.hand, cmd)
