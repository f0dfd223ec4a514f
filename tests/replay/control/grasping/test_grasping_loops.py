"""The grasping method's arm and hand loops in isolation (eqs. 2-4): the task partition S keeps
tracking and reaching orthogonal, and the hand's compliance balances at F^h = -(K^hg/K^hf) e."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from grasp_rig import rig  # noqa: E402

from replay.control.grasping.arm_control import ArmControlTask, ArmParams  # noqa: E402
from replay.control.grasping.hand_control import HandControlTask, HandParams  # noqa: E402
from replay.control.grasping.payloads import GraspObject, GraspState  # noqa: E402
from replay.messages import (
    TOPIC_ARM_ENCODERS,
    TOPIC_GRASP_OBJECT,
    TOPIC_GRASP_STATE,  # noqa: E402
    TOPIC_HAND_ENCODERS,
    TOPIC_HAND_TORQUE,
    TOPIC_WRIST_WRENCH,
    JointState,
)
from replay.sensors.force import JointTorque, WristWrench  # noqa: E402

from tests.replay.control.grasping.oracles import eq2_reference, kinematics


@pytest.fixture(scope="module")
def spec():
    plant = rig()
    s = plant.spec()
    plant.close()
    return s


def obj(position, roll=None, shape="rectangle"):
    return GraspObject(
        0.0,
        True,
        [7.5, 7.5],
        0.0,
        40,
        40,
        list(position),
        roll,
        [*position, roll or 0.0, 0.0, 0.0],
        [0.1, 0.05],
        shape,
        1.0,
        2.0,
        [[1.0, 0.0], [0.0, 1.0]],
        [0.0, 0.0],
    )


def state(x_d, phase="track", s=0.0):
    return GraspState(0.0, phase, 0, [*x_d, 0.0, 0.0, 0.0], s, phase in ("reach", "hold"), 0.0)


def arm_velocity(spec, task, measurements):
    cmd = task.update(0.0, measurements)
    _, J = kinematics(task, np.asarray(spec.initial_q))
    T, _ = kinematics(task, np.asarray(spec.initial_q))
    r = task.params.grasp_point * T[:3, 2]
    v = J[:3] @ cmd.arm + np.cross(J[3:] @ cmd.arm, r)  # the grasp point's velocity
    return v, J[3:] @ cmd.arm


def test_task_partition_tracks_in_the_plane_and_reaches_along_its_normal(spec):
    q0 = list(spec.initial_q)
    enc = JointState(0.0, list(spec.joint_names), q0, [0.0] * 7, [0.0] * 7)
    task = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    T, _ = kinematics(task, np.asarray(q0))
    gp = T[:3, 3] + task.params.grasp_point * T[:3, 2]
    # the object 2 cm to +y and 5 cm beyond the hand along x; x_d^a at the hand: only y moves
    v, w = arm_velocity(
        spec,
        task,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp + [0.05, 0.02, 0.0])),
            (TOPIC_GRASP_STATE, state(gp)),
        ],
    )
    assert v[1] == pytest.approx(task.K_a1[1] * 0.02, rel=0.02)
    assert abs(v[0]) < 0.02 * abs(v[1]) and abs(v[2]) < 0.02 * abs(v[1])
    # x_d^a 1 cm ahead and 1 cm up; the object where the hand is: only x moves (z is tracked)
    task = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    v, w = arm_velocity(
        spec,
        task,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp)),
            (TOPIC_GRASP_STATE, state(gp + [0.01, 0.0, 0.01])),
        ],
    )
    assert v[0] == pytest.approx(task.K_a2[0] * 0.01, rel=0.02)
    assert abs(v[1]) < 0.02 * v[0] and abs(v[2]) < 0.02 * v[0]
    # the box rolled by 0.05 rad: the hand turns about the plane normal (x) only (within the
    # joints' 3 rad/s)
    task = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    v, w = arm_velocity(
        spec,
        task,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp, roll=0.05)),
            (TOPIC_GRASP_STATE, state(gp)),
        ],
    )
    assert w[0] == pytest.approx(task.K_a1[3] * 0.05, rel=0.05)
    assert np.linalg.norm(v) < 0.01 and abs(w[1]) < 0.05 * w[0] and abs(w[2]) < 0.05 * w[0]
    # a circle has no axis: no roll
    task = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    v, w = arm_velocity(
        spec,
        task,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp, roll=0.2, shape="circle")),
            (TOPIC_GRASP_STATE, state(gp)),
        ],
    )
    assert abs(w[0]) < 1e-6 and np.linalg.norm(w) < 2e-3  # (pitch/yaw: the start's residue)


def test_hand_compliance_balances_the_load_against_the_overclosure(spec):
    """Eq. 4 at rest: the command vanishes where K^hg (theta_d - theta) = -K^hf F^h."""
    P = HandParams(load_filter=0.0)
    task = HandControlTask(P, spec=spec)
    theta = np.full(14, 0.3)
    hold = state([0.0, 0.0, 0.0], phase="hold", s=1.0)
    shape = obj([0.75, 0.0, 0.55])
    theta_d = np.asarray(P.rectangle_grip)
    tau = P.K_hg / P.K_hf * (theta_d - theta)  # the drives' torque at equilibrium
    enc = JointState(0.0, list(spec.hand.joint_names), theta.tolist(), [0.0] * 14, [0.0] * 14)
    # the first reading is the tare (the unloaded hand): an offset the later ones lose
    tare = np.linspace(-0.1, 0.1, 14)
    task.update(
        0.0,
        [
            (TOPIC_GRASP_OBJECT, shape),
            (TOPIC_GRASP_STATE, hold),
            (TOPIC_HAND_ENCODERS, enc),
            (TOPIC_HAND_TORQUE, JointTorque(0.0, [], tare.tolist())),
        ],
    )
    cmd = task.update(0.001, [(TOPIC_HAND_TORQUE, JointTorque(0.001, [], (tare + tau).tolist()))])
    np.testing.assert_allclose(cmd.hand, 0.0, atol=1e-12)
    # less load than that: it closes further; before the shape is known the hand stays open
    cmd = task.update(
        0.002, [(TOPIC_HAND_TORQUE, JointTorque(0.002, [], (tare + 0.5 * tau).tolist()))]
    )
    assert np.all(np.asarray(cmd.hand)[theta_d > theta] > 0)
    fresh = HandControlTask(P, spec=spec)
    cmd = fresh.update(0.0, [(TOPIC_GRASP_STATE, hold), (TOPIC_HAND_ENCODERS, enc)])
    assert fresh.preshape == "none" and np.all(np.asarray(cmd.hand) <= 0)


def test_arm_task_kinematics_match_the_chains_fk_and_jacobian_over_random_postures(spec):
    """Eq. 2's J^a and tool pose (the task's array-filled DH chain) against the nominal chain's
    own fk/jacobian, at seeded random postures within the joint limits."""
    task = ArmControlTask(ArmParams(), spec=spec)
    rng = np.random.default_rng(10)
    lo, hi = np.asarray(spec.lower), np.asarray(spec.upper)
    ok = 0
    n = 50
    for _ in range(n):
        q = rng.uniform(lo, hi)
        T, J = kinematics(task, q)
        T_ref = spec.model.fk(q)
        J_ref = spec.model.jacobian(q)
        ok += bool(
            np.allclose(T, T_ref, atol=1e-12, rtol=0.0) and np.allclose(J, J_ref, atol=1e-12)
        )
    print(f"arm kinematics: {ok}/{n} random postures match the chain")
    assert ok == n


def test_arm_task_eq2_matches_its_numpy_reference_over_random_inputs(spec):
    """The task's chain, grasp-point Jacobian, damped pseudo-inverse, J^T F and F^a against
    eq. 2 written out in NumPy (``oracles.eq2_reference``), at seeded
    random postures, rates, objects, targets and wrenches: agreement within 1e-9 (rad/s, N)."""
    rng = np.random.default_rng(11)
    lo, hi = np.asarray(spec.lower), np.asarray(spec.upper)
    ok, n = 0, 60
    for i in range(n):
        task = ArmControlTask(ArmParams(force_deadband=0.0, force_filter=0.0), spec=spec)
        q, qd = rng.uniform(lo, hi), rng.normal(0.0, 1.0, 7)
        T, _ = kinematics(task, q)
        gp = T[:3, 3] + task.params.grasp_point * T[:3, 2]
        roll = float(rng.uniform(-1.0, 1.0)) if i % 3 else None
        o = obj(gp + rng.normal(0.0, 0.05, 3), roll=roll, shape=("rectangle", "circle")[i % 2])
        st = state(gp + rng.normal(0.0, 0.05, 3), phase="reach")
        enc = JointState(0.0, list(spec.joint_names), q.tolist(), qd.tolist(), [0.0] * 7)
        f0, m0, f1, m1 = (rng.normal(0.0, 5.0, 3).tolist() for _ in range(4))
        # the arm still between the two readings (same q, qd): no inertial load, F^a is the
        # second reading in the world minus the hand's weight at its centre of mass (no filter)
        task.update(
            0.0,
            [
                (TOPIC_ARM_ENCODERS, enc),
                (TOPIC_GRASP_STATE, st),
                (TOPIC_WRIST_WRENCH, WristWrench(0.0, f0, m0)),
            ],
        )
        cmd = task.update(
            0.001,
            [
                (TOPIC_GRASP_OBJECT, o),
                (TOPIC_WRIST_WRENCH, WristWrench(0.001, f1, m1)),
            ],
        )
        out = task._out
        R = T[:3, :3]
        w_hand, r = task.hand.mass * task.g, R @ np.asarray(task.hand.com, float)
        F_ref = np.concatenate([R @ f1 - w_hand, R @ m1 - np.cross(r, w_hand)])
        good = np.allclose(out.wrench, F_ref, atol=1e-9, rtol=0.0)
        ref = eq2_reference(task, q, qd, o, st, out.wrench)
        good &= np.allclose(cmd.arm, ref["command"], atol=1e-9, rtol=0.0)
        good &= np.allclose(out.x_a[:3], ref["x_a"], atol=1e-12, rtol=0.0)
        for name, term in out.terms.items():
            good &= np.allclose(term, ref[name], atol=1e-9, rtol=0.0)
        ok += bool(good)
    print(f"arm eq. 2 task vs NumPy: {ok}/{n} random inputs agree within 1e-9")
    assert ok == n


def test_hand_task_eq4_and_lowpass_equal_the_numpy_formulas():
    """``eq4_step`` and ``lowpass_step`` (the hand task's per-step path, in floats)
    against eq. 4 and the low-pass written in NumPy, over seeded random postures, rates, loads,
    closures and gains (some commands beyond the limit): equal within 1e-12."""
    from replay.control.grasping.hand_control import eq4_step, lowpass_step

    rng = np.random.default_rng(14)
    ok = clipped = 0
    n = 200
    for i in range(n):
        pre, grip, q = (rng.uniform(-0.3, 1.3, 14) for _ in range(3))
        qd, load, tau = (rng.normal(0.0, 2.0, 14) for _ in range(3))
        c, a = float(rng.uniform(0.0, 1.0)), float(rng.uniform(0.0, 1.0))
        K_hg, K_hv, K_hf = rng.uniform(0, 50), rng.uniform(0, 0.1), rng.uniform(0, 80)
        vmax = float(rng.uniform(0.5, 20.0))
        g = None if i % 5 == 0 else grip
        td_ref = pre if g is None else pre + c * (grip - pre)
        cmd_ref = np.clip(K_hg * (td_ref - q) - K_hv * qd + K_hf * load, -vmax, vmax)
        args = (pre.tolist(), None if g is None else g.tolist(), c, q.tolist(), qd.tolist())
        td, cmd, deficit = eq4_step(*args, load.tolist(), K_hg, K_hv, K_hf, vmax)
        low = lowpass_step(load.tolist(), tau.tolist(), a)
        ok += bool(
            np.allclose(td, td_ref, rtol=0.0, atol=1e-12)
            and np.allclose(cmd, cmd_ref, rtol=0.0, atol=1e-12)
            and abs(deficit - np.abs(td_ref - q).max()) < 1e-12
            and np.allclose(low, load + a * (-tau - load), rtol=0.0, atol=1e-12)
        )
        clipped += int(np.sum(np.abs(cmd_ref) == vmax))
    print(f"hand eq. 4 floats vs NumPy: {ok}/{n} random inputs agree, {clipped} clipped")
    assert ok == n and clipped > 0


def test_arm_wrench_below_the_deadband_is_zero_and_the_filter_lags(spec):
    """F^a: a step of the wrist force passes the first-order low-pass (gain dt / (tau + dt) a
    step) and is zero while its force is below the deadband."""
    enc = JointState(0.0, list(spec.joint_names), list(spec.initial_q), [0.0] * 7, [0.0] * 7)
    st = state([0.6, 0.0, 0.55])
    for deadband, expect_zero in ((0.0, False), (50.0, True)):
        task = ArmControlTask(ArmParams(force_deadband=deadband, force_filter=0.009), spec=spec)
        # the hand hanging still reads its weight (palm frame): F^a = 0; then 10 N more
        T, _ = kinematics(task, np.asarray(spec.initial_q))
        R = T[:3, :3]
        w = task.hand.mass * task.g
        f_w = R.T @ w
        m_w = R.T @ np.cross(R @ np.asarray(task.hand.com, float), w)
        task.update(
            0.0,
            [
                (TOPIC_ARM_ENCODERS, enc),
                (TOPIC_GRASP_STATE, st),
                (TOPIC_WRIST_WRENCH, WristWrench(0.0, f_w.tolist(), m_w.tolist())),
            ],
        )
        assert np.allclose(task._out.wrench, 0.0, atol=1e-12)
        f = (f_w + [10.0, 0.0, 0.0]).tolist()
        task.update(0.001, [(TOPIC_WRIST_WRENCH, WristWrench(0.001, f, m_w.tolist()))])
        F = np.asarray(task._out.wrench)
        if expect_zero:
            assert np.all(F == 0.0)
        else:  # a = 0.001 / (0.009 + 0.001) = 0.1 of the 10 N step
            assert np.linalg.norm(F[:3]) == pytest.approx(1.0, rel=1e-9)


def test_arm_wrench_removes_the_hands_inertial_load(spec):
    """F^a (issue #20): the wrist reads m g - m a_com + F_ext; with the arm accelerating
    between two readings (a_com from the arm's kinematics) a reading of exactly m (g - a_com)
    and its moment gives F^a = 0, and 5 N more gives those 5 N."""
    rng = np.random.default_rng(21)
    q = np.asarray(spec.initial_q, float)
    st = state([0.6, 0.0, 0.55])
    for k in range(5):
        qd0, qd1 = rng.normal(0.0, 0.5, 7), rng.normal(0.0, 0.5, 7)
        extra = 5.0 if k % 2 else 0.0
        task = ArmControlTask(ArmParams(force_deadband=0.0, force_filter=0.0), spec=spec)
        T, J = kinematics(task, q)
        R = T[:3, :3]
        r = R @ np.asarray(task.hand.com, float)

        v0, v1 = (J[:3] @ qd + np.cross(J[3:] @ qd, r) for qd in (qd0, qd1))
        a = (v1 - v0) / 0.001
        load = task.hand.mass * (task.g - a)
        f = R.T @ (load + [0.0, extra, 0.0])
        m = R.T @ np.cross(r, load)
        for t, qd in ((0.0, qd0), (0.001, qd1)):
            enc = JointState(t, list(spec.joint_names), q.tolist(), qd.tolist(), [0.0] * 7)
            task.update(
                t,
                [
                    (TOPIC_ARM_ENCODERS, enc),
                    (TOPIC_GRASP_STATE, st),
                    (TOPIC_WRIST_WRENCH, WristWrench(t, f.tolist(), m.tolist())),
                ],
            )
        assert np.linalg.norm(a) > 10.0  # a load worth removing (0.72 kg: > 7 N)
        np.testing.assert_allclose(task._out.wrench[:3], [0.0, extra, 0.0], atol=1e-9)


def test_hold_keeps_the_grasp_time_offset_instead_of_chasing(spec):
    """In the hold phase eq. 2's errors count from where the object sat in the hand when the
    hold began: a ball 15 mm off the grasp point commands nothing; its moving 5 mm more in
    the hand commands K^a1 x 5 mm, as in tracking."""
    q0 = list(spec.initial_q)
    enc = JointState(0.0, list(spec.joint_names), q0, [0.0] * 7, [0.0] * 7)
    task = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    T, _ = kinematics(task, np.asarray(q0))
    gp = T[:3, 3] + task.params.grasp_point * T[:3, 2]
    hold = state(gp, phase="hold", s=1.0)
    v, _ = arm_velocity(
        spec,
        task,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp + [0.0, 0.015, 0.0])),
            (TOPIC_GRASP_STATE, hold),
        ],
    )
    assert np.linalg.norm(v) < 1e-5  # (vs 0.6 m/s if it chased: K^a1 x 15 mm)
    v, _ = arm_velocity(spec, task, [(TOPIC_GRASP_OBJECT, obj(gp + [0.0, 0.020, 0.0]))])
    assert v[1] == pytest.approx(task.K_a1[1] * 0.005, rel=0.02)
    # the same offset while tracking is chased
    track = ArmControlTask(ArmParams(K_af=0.0, K_av=0.0), spec=spec)
    v, _ = arm_velocity(
        spec,
        track,
        [
            (TOPIC_ARM_ENCODERS, enc),
            (TOPIC_GRASP_OBJECT, obj(gp + [0.0, 0.015, 0.0])),
            (TOPIC_GRASP_STATE, state(gp)),
        ],
    )
    assert v[1] == pytest.approx(track.K_a1[1] * 0.015, rel=0.02)


def test_preshape_aperture_opens_for_the_measured_width(spec):
    """The preshape's first flex joints open (never past their limits) so that the tips clear
    a wider object by the margin; a narrow one keeps the posture's own flex."""
    task = HandControlTask(HandParams(), spec=spec)
    pre = list(task.params.circle_preshape)
    wide, narrow = task.aperture(pre, 0.07), task.aperture(pre, 0.01)
    for j1, rest, half, length in task._flex:
        assert task.lo[j1] - 1e-12 <= wide[j1] <= narrow[j1] <= pre[j1] + 1e-12
        tip = half + length * math.sin(-wide[j1])
        if wide[j1] > task.lo[j1] + 1e-9:
            assert tip == pytest.approx(0.035 + task.params.aperture_margin, abs=1e-9)
        assert all(wide[i] == 0.0 for i in rest)


def test_touch_posture_clears_the_measured_width_and_closes_less_on_a_wider_object(spec):
    """touch_closure: at its closure the first finger's joints or tips reach the width (a
    little more closure crosses it), a wider object is met sooner, and the preshape opened for
    that width by aperture() is clear of it; an object too narrow to meet gives 1."""
    task = HandControlTask(HandParams(), spec=spec)
    for shape in ("rectangle", "circle"):
        pre0, grip = (list(x) for x in task.postures[shape])
        closures = []
        for width in (0.05, 0.07):
            pre = task.aperture(pre0, width)
            c = task.touch_closure(pre, grip, width, shape)
            assert 0.0 < c < 1.0, (shape, width, c)
            # the bisection's bound: just past it the posture is inside the object
            assert task.touch_closure(pre, grip, width + 0.002, shape) <= c
            closures.append(c)
        assert closures[1] < closures[0], (shape, closures)  # wider: met sooner
    pre = task.aperture(list(task.postures["rectangle"][0]), 0.05)
    assert task.touch_closure(pre, list(task.postures["rectangle"][0]), 0.001, "rectangle") == 1.0


def test_the_hold_closes_the_hand_no_faster_than_touch_speed(spec):
    """In the hold eq. 4's command is clipped to touch_speed (the gentle last gap); in the
    reach it may use the drive's full speed."""
    P = HandParams(touch_speed=3.0)
    task = HandControlTask(P, spec=spec)
    # every joint 0.2 rad more open than any posture: eq. 4 asks > 5 rad/s of each
    enc = JointState(0.0, list(spec.hand.joint_names), [-0.2] * 14, [0.0] * 14, [0.0] * 14)
    task.shape = "rectangle"
    task.width = 0.05
    hold = GraspState(0.0, "hold", 0, [0.0] * 6, 1.0, True, 0.01)
    cmd = task.update(0.0, [(TOPIC_HAND_ENCODERS, enc), (TOPIC_GRASP_STATE, hold)])
    assert cmd is not None and max(abs(v) for v in cmd.hand) == pytest.approx(3.0)
    reach = GraspState(0.001, "reach", 0, [0.0] * 6, 0.95, True, 0.29)
    fresh = HandControlTask(P, spec=spec)
    fresh.shape, fresh.width = "rectangle", 0.05
    cmd = fresh.update(0.001, [(TOPIC_HAND_ENCODERS, enc), (TOPIC_GRASP_STATE, reach)])
    assert cmd is not None and max(abs(v) for v in cmd.hand) > 3.0
