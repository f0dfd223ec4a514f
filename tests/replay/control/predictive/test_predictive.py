"""The predict-then-intercept baseline (replay/control/predictive): its Kalman filter, catch-point
prediction, inverse kinematics and trajectory, without a simulator."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from replay.control.predictive import BallKalman, PredictiveController, Quintic
from replay.messages import TOPIC_ARM_ENCODERS, TOPIC_VISION_OBJECT, JointState, VisionObject

ROOT = Path(__file__).resolve().parents[4]
G = np.array([0.0, 0.0, -9.81])


def _arc(r0, v0, t):
    return r0 + v0 * t + 0.5 * G * t * t


def test_kalman_recovers_velocity_from_noisy_positions():
    rng = np.random.default_rng(0)
    r0, v0 = np.array([2.3, 0.0, 0.9]), np.array([-8.9, 0.1, -1.5])
    kf = BallKalman(G, meas_sigma=0.002, accel_sigma=0.5)
    for k in range(100):
        t = k * 1e-3
        kf.add(t, _arc(r0, v0, t) + rng.normal(0.0, 0.002, 3))
    r, v = kf.state(0.099)
    assert np.linalg.norm(r - _arc(r0, v0, 0.099)) < 0.003
    assert np.linalg.norm(v - (v0 + G * 0.099)) < 0.15
    assert kf.velocity_sigma() < 0.2


def test_quintic_meets_its_boundary_conditions():
    q = Quintic(0.1, 0.3, [0.0, 1.0], [0.5, -1.0], [2.0, 0.0], [1.0, 0.2])
    p0, v0, a0 = q(0.1)
    np.testing.assert_allclose(p0, [0.0, 1.0], atol=1e-12)
    np.testing.assert_allclose(v0, [0.5, -1.0], atol=1e-12)
    np.testing.assert_allclose(a0, [2.0, 0.0], atol=1e-12)
    p1, v1, a1 = q(0.3 - 1e-12)
    np.testing.assert_allclose(p1, [1.0, 0.2], atol=1e-9)
    np.testing.assert_allclose(v1, [0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(a1, [0.0, 0.0], atol=1e-4)
    assert np.all(q(0.5)[0] == q.goal)


@pytest.fixture(scope="module")
def spec():
    from replay.runner import Runner
    from replay.scenario import load_scenario

    sc = load_scenario(ROOT / "scenarios" / "predictive_catch.yaml")
    runner = Runner(sc)
    spec, params = runner.plant.spec(), sc.controller.params
    runner.plant.close()
    return spec, params


def test_plans_land_the_palm_on_the_true_arc_over_throws(spec):
    """Seeded neighbourhood of the nominal throw (U(8, 10) m/s, arrival +-10 cm, 2 mm noise): the
    last plan's arrival point is within 2.5 cm of the true arc at the planned time (60 frames,
    the plan ~0.1 s ahead; accel_sigma 2 m/s^2 lets the filter follow kicks), and the
    torque-feasible rollout puts the catch point l(q) within 1 cm of it, palm within 45 deg of
    the incoming ball (the arm cannot turn it further in time: the runs' approach angles)."""
    from analysis.catching.throws import CATCH_POINT, THROW_START
    from replay.control.catching.trajectories import launch_velocity

    arm, params = spec
    rng = np.random.default_rng(11)
    trials, ok = 10, 0
    for _ in range(trials):
        target = CATCH_POINT + np.array([0.0, *rng.uniform(-0.1, 0.1, 2)])
        v0, _ = launch_velocity(THROW_START, target, rng.uniform(8.0, 10.0), G)
        ctrl = PredictiveController(params, spec=arm)
        t0 = 0.1
        q = np.asarray(arm.initial_q, float)
        for k in range(60):
            t = t0 + k * 1e-3
            z = _arc(THROW_START, v0, t - t0) + rng.normal(0.0, 0.002, 3)
            ctrl.update(
                t + 1e-3,
                [
                    (TOPIC_VISION_OBJECT, VisionObject(t, z.tolist())),
                    (
                        TOPIC_ARM_ENCODERS,
                        JointState(t, list(arm.joint_names), q.tolist(), [0.0] * 4, []),
                    ),
                ],
            )
        ic = ctrl.intercept
        assert ic is not None and ctrl.replans >= 1
        p_true = _arc(THROW_START, v0, ic.t_catch - t0)
        q_r, _, _ = ctrl.plan(ic.t_catch)
        hand = ctrl.model.fk(q_r)
        print(
            f"  prediction {1e3 * np.linalg.norm(ic.point - p_true):.1f} mm, rollout hand "
            f"{1e3 * np.linalg.norm(hand - ic.point):.1f} mm, palm {ic.angle_deg:.0f} deg"
        )
        if (
            np.linalg.norm(ic.point - p_true) < 0.025
            and np.linalg.norm(hand - ic.point) < 0.01
            and ic.angle_deg < 45.0
        ):
            ok += 1
    print(f"predictive plans landing the palm on the arc: {ok}/{trials}")
    assert ok / trials >= 0.9


def test_rollout_stays_within_the_torque_limits_and_obeys_the_model(spec):
    """The rollout's torques are at most the limits (by construction) and its accelerations are
    the model's forward dynamics of them: ID(q, qd, qdd) = tau on the active joints."""
    from replay.control.predictive.intercept import Rollout
    from replay.control.predictive.trajectory import InterceptPlan

    arm, params = spec
    ctrl = PredictiveController(params, spec=arm)
    m, act = ctrl.model, list(ctrl.active)
    rng = np.random.default_rng(3)
    for _ in range(3):
        q0 = np.asarray(arm.initial_q, float)
        goal = m.full(
            np.array([rng.uniform(-0.2, 0.2), rng.uniform(0.8, 1.3), rng.uniform(0.3, 1.5)])
        )
        plan = InterceptPlan(
            0.0, q0, np.zeros(4), np.zeros(4), goal, np.zeros(4), 0.15, 0.015, 0.05
        )
        ro = Rollout(m, plan, 0.0, 0.15, q0, np.zeros(4), ctrl.kp, ctrl.kd, ctrl.tau_limit)
        assert np.all(np.abs(ro.tau) <= ctrl.tau_limit + 1e-9)
        assert np.any(np.abs(ro.tau[:, act]) >= ctrl.tau_limit[act] - 1e-6)  # it saturates
        for k in (0, 40, 100):
            tau = m.inverse_dynamics_full(ro.q[k], ro.qd[k], ro.qdd[k])
            np.testing.assert_allclose(tau[act], ro.tau[k, act], atol=1e-6)


def test_ik_round_trip_and_palm_angle(spec):
    """solve_ik recovers seeded postures of the elbow-positive branch from their catch point
    (from the method's seed), and the palm angle is 0 for a ball coming down -z_tool, 180 for
    one leaving along it."""
    from replay.control.predictive.intercept import palm_angle, solve_ik

    arm, params = spec
    ctrl = PredictiveController(params, spec=arm)
    m = ctrl.model
    rng = np.random.default_rng(8)
    for _ in range(10):
        p = np.array([rng.uniform(-0.3, 0.3), rng.uniform(0.6, 1.2), rng.uniform(0.5, 2.0)])
        got, err = solve_ik(m, m.point(p), np.asarray(params.ik_seed, float))
        assert err < 1e-7
        np.testing.assert_allclose(got, p, atol=1e-5)
        z = m.tool_axis(p)
        assert palm_angle(m, p, -3.0 * z) == pytest.approx(0.0, abs=1e-6)
        assert palm_angle(m, p, 2.0 * z) == pytest.approx(180.0, abs=1e-6)
