"""The grasping rig's physics (plants/bullet_arm/grasp_plant.py): what the wrist F/T sensor reads
for known static loads, the velocity servos' torque limits, the pan/tilt head's servo, the human
hand's path, the F^h the strain gauges read, and the rig's events."""

from __future__ import annotations

import math

import numpy as np
import pybullet as p
import pytest

from plants.arm_rig.grasp_rig import GraspRig
from plants.arm_rig.head import HeadServo
from plants.bullet_arm.human_hand import band_limited_path
from plants.arm_rig.params import GraspParams
from replay.robot.arm_types import ServoCommand
from replay.robot.hand import GRASP4, hand_body, hand_mass
from replay.robot.head import HeadSpec, camera_pose, look_angles

from grasp_rig import DT, Q0, rig


def settle(plant, n=300):
    for _ in range(n):
        plant.apply(ServoCommand(arm=[0.0] * 7, hand=[0.0] * 14, head=[0.0, 0.0]))
        plant.step()


def palm_rotation(plant) -> np.ndarray:
    orn = plant.engine.bc.getLinkState(plant.engine.robot, plant.engine.tool_link)[5]
    return np.array(p.getMatrixFromQuaternion(orn)).reshape(3, 3)


def test_wrist_sensor_reads_the_hands_weight_when_still():
    """Known static load 1: the open hand (0.72 kg) hanging still from the flange. Recorded:
    F = (7.0632, 0, 0) N in the palm frame (palm x points down here), i.e. m g along gravity,
    and M = r_com x m g about the flange-palm joint (0.2478 N m about palm y)."""
    plant = rig()
    try:
        settle(plant)
        w = np.array(plant.engine.wrench)
        R = palm_rotation(plant)
        m = hand_mass(GRASP4)
        g = np.array([0.0, 0.0, -9.81])
        np.testing.assert_allclose(R @ w[:3], m * g, atol=2e-3)
        com = hand_body(GRASP4, plant.hand_state()[0]).com
        np.testing.assert_allclose(R @ w[3:], np.cross(R @ com, m * g), atol=2e-3)
        assert w[0] == pytest.approx(7.0632, abs=2e-3)  # the recorded reading
        assert w[4] == pytest.approx(0.2478, abs=2e-3)
    finally:
        plant.close()


def test_wrist_sensor_reads_an_added_static_force():
    """Known static load 2: 5 N along world +y pushed on the palm's centre (0.0075 m ahead of
    the joint) while the servos hold the arm: the reading grows by the force, the torque by
    r x F."""
    plant = rig()
    try:
        settle(plant)
        base = np.array(plant.engine.wrench)
        F = np.array([0.0, 5.0, 0.0])
        for _ in range(400):
            pos = plant.engine.bc.getLinkState(plant.engine.robot, plant.engine.palm_link)[
                0
            ]  # the palm's CoM
            plant.engine.bc.applyExternalForce(
                plant.engine.robot, plant.engine.palm_link, F.tolist(), pos, p.WORLD_FRAME
            )
            plant.apply(ServoCommand(arm=[0.0] * 7, hand=[0.0] * 14))
            plant.step()
        R = palm_rotation(plant)
        extra = np.array(plant.engine.wrench) - base
        # the hand pushed +y; it loads the flange with the same force (palm frame)
        np.testing.assert_allclose(R @ extra[:3], F, atol=0.05)
        r = R @ np.array([0.0, 0.0, GRASP4.palm_size[2] / 2.0])
        np.testing.assert_allclose(R @ extra[3:], np.cross(r, F), atol=0.01)
    finally:
        plant.close()


def test_arm_servo_torque_is_limited_and_the_joint_lags():
    plant = rig()
    try:
        lim = plant.torque_limits
        for _ in range(30):
            plant.apply(ServoCommand(arm=[3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]))
            plant.step()
            assert np.all(np.abs(plant._tau_applied) <= lim + 1e-9)
        assert plant._clamped[0]  # J1 at its 60 N m
        assert abs(plant._tau_applied[0]) == pytest.approx(lim[0])
        assert 0.0 < plant.arm_state()[1][0] < 3.0  # not an ideal joint: it lags
        kinds = [e.kind for e in plant.pop_events()]
        assert "torque_limit" in kinds
    finally:
        plant.close()


def test_arm_servo_follows_a_feasible_velocity_command():
    plant = rig()
    try:
        cmd = np.array([0.2, 0.0, -0.1, 0.0, 0.3, 0.0, -0.2])
        err = []
        for k in range(400):
            plant.apply(ServoCommand(arm=cmd))
            plant.step()
            if k >= 200:
                err.append(plant.arm_state()[1] - cmd)
        err = np.abs(np.array(err))
        # the mean follows; the redundant axes (J1, J3, J5, J7 nearly coupled at this posture)
        # keep a ~10 Hz wobble of a few 0.01 rad/s with the fingers
        assert err.mean() < 0.01 and err.max() < 0.06
        assert not any(plant._clamped)
    finally:
        plant.close()


def test_head_servo_reaches_its_rate_within_its_torque_limit():
    head = HeadSpec(
        (0.0, 0.0, 1.0), 0.0, 0.03, (-1.5, -1.0), (1.5, 1.0), (2e-3, 1e-3), (0.5, 0.5), (10.0, 10.0)
    )
    servo = HeadServo(head, 300.0, DT, [0.0, 0.0])
    servo.set_command([2.0, -1.0])
    peak = 0.0
    for _ in range(100):
        servo.step()
        peak = max(peak, float(np.abs(servo.torque).max()))
    np.testing.assert_allclose(servo.qd, [2.0, -1.0], atol=1e-6)
    assert peak <= 0.5 + 1e-12
    servo.set_command([500.0, 0.0])  # beyond what 0.5 N m gives in 1 ms
    servo.step()
    assert servo.qd[0] == pytest.approx(2.0 + DT * 0.5 / 2e-3, rel=1e-9)


def _head_step_reference(servo, q, qd, cmd):
    """The head servo's step on 2-vectors (module docstring of plants/arm_rig/head.py)."""
    dt, J, K = servo.dt, servo.J, servo.K
    qd_new = (J * qd + dt * K * cmd) / (J + dt * K)
    tau = K * (cmd - qd_new)
    over = np.abs(tau) > servo.tau_max
    if over.any():
        tau = np.clip(K * (cmd - qd), -servo.tau_max, servo.tau_max)
        qd_new = np.where(over, qd + dt * tau / J, qd_new)
    q_new = q + dt * qd_new
    stop = (q_new < servo.lower) | (q_new > servo.upper)
    return np.clip(q_new, servo.lower, servo.upper), np.where(stop, 0.0, qd_new), tau


def test_head_servo_step_equals_the_vector_form_over_random_commands():
    """Seeded random commands within and beyond the torque limit, into the hard stops: the
    per-axis float step gives exactly the 2-vector form's angles, rates and torques."""
    head = HeadSpec(
        (0.0, 0.0, 1.0), 0.0, 0.03, (-0.2, -0.1), (0.2, 0.1), (2e-3, 1e-3), (0.5, 0.5), (10.0, 10.0)
    )
    servo = HeadServo(head, 300.0, DT, [0.0, 0.0])
    rng = np.random.default_rng(7)
    n, same, saturated, stopped = 400, 0, 0, 0
    for k in range(n):
        servo.set_command(rng.normal(0.0, 3.0 if k % 50 else 400.0, 2))
        want = _head_step_reference(servo, servo.q, servo.qd, servo.command)
        servo.step()
        same += all(np.array_equal(a, b) for a, b in zip((servo.q, servo.qd, servo.torque), want))
        saturated += bool(np.any(np.abs(want[2]) >= servo.tau_max - 1e-12))
        stopped += bool(np.any((want[0] == servo.lower) | (want[0] == servo.upper)))
    print(f"head step: {same}/{n} equal; {saturated} at the torque limit, {stopped} at a stop")
    assert same == n and saturated > 0 and stopped > 0


def test_camera_pose_looks_where_look_angles_says():
    head = HeadSpec((0.0, 0.15, 0.7), 0.2, 0.0, (-2, -2), (2, 2), (1, 1), (1, 1), (1, 1))
    target = np.array([0.75, -0.05, 0.5])
    R, c = camera_pose(head, *look_angles(head, target))
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    d = R.T @ (target - c)
    assert d[2] > 0 and abs(d[0]) < 1e-12 and abs(d[1]) < 1e-12
    assert R[2, 1] < 0.0  # image down has a -z component


def test_human_path_has_the_scenarios_rms_speed():
    w, a, phi = band_limited_path(
        np.random.default_rng(5), components=6, f_min=0.1, f_max=1.0, rms_rate=0.1, axes=2
    )
    assert np.sum((a * w) ** 2) / 2.0 == pytest.approx(0.01, rel=1e-12)
    t = np.arange(0.0, 400.0, 0.01)  # long enough to average
    v = (a[..., None] * w[..., None] * np.cos(w[..., None] * t + phi[..., None])).sum(axis=1)
    assert math.sqrt(np.mean(np.sum(v**2, axis=0))) == pytest.approx(0.1, rel=0.15)
    assert np.all(w <= 2 * math.pi * 1.0 + 1e-12) and np.all(w >= 2 * math.pi * 0.1 - 1e-12)


def test_human_moves_the_object_and_seeds_give_other_paths():
    paths = []
    for seed in (0, 1):
        plant = GraspRig(
            GraspParams(
                arm="wam7",
                hand="grasp4",
                object="box",
                object_size=[0.05, 0.10, 0.05],
                object_mass=0.1,
                object_position=[0.75, 0.0, 0.55],
                initial_q=Q0,
                human_speed=0.1,
            ),
            dt=DT,
            rng=np.random.default_rng(seed),
        )
        try:
            pos = []
            for _ in range(500):
                plant.step()
                pos.append(plant.object_state()[0])
            pos = np.array(pos)
            target = plant.human.target
            np.testing.assert_allclose(pos[-1], target, atol=2e-3)  # follows its hand
            assert np.ptp(pos[:, 0]) < 1e-3  # stays on the plane x
            paths.append(pos)
        finally:
            plant.close()
    assert np.abs(paths[0] - paths[1]).max() > 5e-3


def test_strain_gauges_read_the_servo_torque_and_the_scene_has_the_readings():
    plant = rig()
    try:
        settle(plant, 50)
        sc = plant.scene()
        assert set(sc.readings) >= {"arm", "hand", "hand_torque", "head", "wrist"}
        np.testing.assert_allclose(
            sc.readings["hand_torque"]["torque"], plant.engine.hand_servos.torque
        )
        assert len(sc.readings["hand"]["position"]) == 14
        truth = plant.truth(0.05)
        assert {
            "/head/state",
            "/human/state",
            "/wrist/wrench_truth",
            "/arm/servo",
            "/head/joint_state",
        } <= set(truth)
        assert "/arm/applied_torque" not in truth
    finally:
        plant.close()


def test_the_rig_refuses_a_torque_command():
    from replay.robot.arm_types import ArmCommand

    plant = rig()
    try:
        with pytest.raises(TypeError):
            plant.apply(ArmCommand(torque=[0.0] * 7))
    finally:
        plant.close()


def test_frames_read_once_a_step_equal_pybullets_own_reads_while_moving():
    """The tool/palm link states read once a step (effector motion, grasp point, the palm's point
    velocity) are what PyBullet's getLinkState gives at that moment, at seeded random commands."""
    plant = rig(human_speed=0.1)
    rng = np.random.default_rng(3)
    try:
        bc = plant.engine.bc
        for k in range(60):
            plant.apply(
                ServoCommand(
                    arm=rng.uniform(-0.5, 0.5, 7).tolist(),
                    hand=rng.uniform(-1.0, 1.0, 14).tolist(),
                    head=[0.0, 0.0],
                )
            )
            plant.step()
            if k % 10:
                continue
            tool = bc.getLinkState(
                plant.engine.robot,
                plant.engine.tool_link,
                computeLinkVelocity=1,
                computeForwardKinematics=1,
            )
            pe, oe, ve, we = plant.effector_state()
            for got, want in zip((pe, oe, ve, we), (tool[4], tool[5], tool[6], tool[7])):
                np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12)
            assert np.linalg.norm(ve) > 1e-3  # it moves: a stale cache would differ
            palm = bc.getLinkState(
                plant.engine.robot,
                plant.engine.palm_link,
                computeLinkVelocity=1,
                computeForwardKinematics=1,
            )
            point = plant.object_state()[0]
            want = np.array(palm[6]) + np.cross(np.array(palm[7]), point - np.array(palm[0]))
            got = plant.engine.point_velocity(plant.engine.palm_link, point)
            np.testing.assert_allclose(got, want, rtol=0.0, atol=1e-12)
            np.testing.assert_allclose(
                plant.engine.frames_now()[0][0], tool[4], rtol=0.0, atol=1e-12
            )
    finally:
        plant.close()


def test_the_robot_never_collides_with_itself():
    """Self-collision is off (the URDF is loaded without URDF_USE_SELF_COLLISION): the closing
    fingers, the palm and the arm links never make contact points with each other, so filtering
    their pairs cannot change (or speed up) the physics."""
    plant = rig()
    try:
        closed = np.asarray(GRASP4.closed_posture)
        for _ in range(300):
            hq = plant.hand_state()[0]
            plant.apply(
                ServoCommand(arm=[0.0, 0.5, 0.0, 0.5, 0.0, 0.5, 0.0], hand=(closed - hq) * 20)
            )
            plant.step()
            assert (
                plant.engine.bc.getContactPoints(bodyA=plant.engine.robot, bodyB=plant.engine.robot)
                == ()
            )
        # the fingers did close onto each other's space: the hand moved towards its grip
        assert (
            np.abs(plant.hand_state()[0] - closed).max()
            < 0.5 * np.abs(np.asarray(GRASP4.open_posture) - closed).max()
        )
    finally:
        plant.close()


def test_kept_pybullet_calls_stay_bound_to_each_rigs_own_client():
    """Two rigs at once: the per-step calls kept on each client carry that client's id, so
    stepping one moves only its own world."""
    from plants.bullet_arm.plant import PER_STEP_CALLS

    a, b = rig(human_speed=0.1), rig(human_speed=0.1)
    try:
        assert a.engine.bc._client != b.engine.bc._client
        for plant in (a, b):
            for name in PER_STEP_CALLS:
                assert (
                    getattr(plant.engine.bc, name).keywords["physicsClientId"]
                    == plant.engine.bc._client
                )
        before = b.object_state()[0].copy()
        for _ in range(200):
            a.step()
        assert np.linalg.norm(a.object_state()[0] - before) > 1e-3  # a's human moved its box
        b.invalidate_state()
        np.testing.assert_array_equal(b.object_state()[0], before)
    finally:
        a.close()
        b.close()


class _Recorder:
    """A stand-in PyBullet client that keeps the forces and torques applied to the object."""

    def __init__(self):
        self.force = self.torque = None

    def applyExternalForce(self, obj, link, force, pos, frame):  # noqa: N802
        self.force = np.array(force)

    def applyExternalTorque(self, obj, link, torque, frame):  # noqa: N802
        self.torque = np.array(torque)


def _still_human(bc, **kw):
    from plants.bullet_arm.human_hand import HumanHand

    base = dict(
        origin=[0.75, 0.0, 0.55],
        rpy0=[0.0, 0.0, 0.0],
        u=[0.0, 1.0, 0.0],
        v=[0.0, 0.0, 1.0],
        n=[1.0, 0.0, 0.0],
        speed=0.0,
        roll_rate=0.0,
        f_min=0.1,
        f_max=1.0,
        components=6,
        max_force=30.0,
        start=0.0,
        mass=0.1,
        gravity=9.81,
        stiffness=500.0,
        damping=10.0,
        rot_stiffness=0.5,
        rot_damping=0.01,
        max_torque=1.0,
    )
    base.update(kw)
    return HumanHand(bc, 0, np.random.default_rng(0), **base)


def test_human_hand_is_a_spring_damper_with_a_total_force_limit():
    """Issue #20: the human holds the object compliantly: at its path's pose it carries the
    weight; 10 mm off it pulls back with k x 10 mm; far off, the force's magnitude (not each
    axis) stops at its limit, pointing the same way; a moving object is damped."""
    bc = _Recorder()
    h = _still_human(bc)
    q = [0.0, 0.0, 0.0, 1.0]
    h.drive(0.0, [0.75, 0.0, 0.55], q, [0.0] * 3, [0.0] * 3)
    np.testing.assert_allclose(bc.force, [0.0, 0.0, 0.981], atol=1e-12)
    np.testing.assert_allclose(bc.torque, 0.0, atol=1e-12)
    h.drive(0.0, [0.75, 0.01, 0.55], q, [0.0] * 3, [0.0] * 3)
    np.testing.assert_allclose(bc.force, [0.0, -5.0, 0.981], atol=1e-9)
    h.drive(0.0, [0.75, 0.01, 0.55], q, [0.0, 0.2, 0.0], [0.0] * 3)
    np.testing.assert_allclose(bc.force, [0.0, -7.0, 0.981], atol=1e-9)
    h.drive(0.0, [0.80, 0.10, 0.55], q, [0.0] * 3, [0.0] * 3)  # 25 N and 50 N per axis
    assert np.linalg.norm(bc.force) == pytest.approx(30.0, rel=1e-12) and h.limited
    want = np.array([-25.0, -50.0, 0.981])
    np.testing.assert_allclose(bc.force / 30.0, want / np.linalg.norm(want), atol=1e-12)
    # turned 0.1 rad about the plane normal: turned back with k_r x 0.1 rad
    s = math.sin(0.05)
    h.drive(0.0, [0.75, 0.0, 0.55], [s, 0.0, 0.0, math.cos(0.05)], [0.0] * 3, [0.0] * 3)
    np.testing.assert_allclose(bc.torque, [-0.05, 0.0, 0.0], atol=1e-9)


def test_human_force_is_logged_and_follows_a_pull():
    """On the rig: with nothing touching, the object hangs on the human's spring at its path
    (within 1 mm; the logged force carries its weight); /human/wrench is in the truth."""
    plant = rig(human_speed=0.05)
    try:
        for _ in range(300):
            plant.step()
        truth = plant.truth(plant._t)
        hw = truth["/human/wrench"]
        assert np.linalg.norm(hw.offset) < 1e-3
        assert hw.force[2] == pytest.approx(0.1 * 9.81, abs=0.6)
        assert not hw.limited
    finally:
        plant.close()
