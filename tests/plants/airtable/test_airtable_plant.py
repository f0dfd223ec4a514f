"""The Pymunk air-table plant: free flight, mass properties, hand limits, events, determinism."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from plants.airtable import AirTablePlant, Params
from replay.robot.hand2d import AirTableSpec, HandCommand, finger_ik, finger_tip, travel_time
from replay.interfaces import Plant
from replay.messages import FingersState, StickState, to_dict
from replay.scene import Box, Cylinder

DT = 1.0 / 3000.0


def quaternion_yaw(q) -> float:
    """Yaw (rad) of a rotation that is about +z only."""
    qx, qy, qz, qw = q
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def far_stick_params(**initial) -> Params:
    """Stick well away from the (default) fingertips, drifting away (no rest event)."""
    p = Params()
    p.initial.x, p.initial.y, p.initial.vy = -0.3, 0.4, 0.02
    for k, v in initial.items():
        setattr(p.initial, k, v)
    return p


def run(plant: AirTablePlant, n: int) -> list:
    events = []
    for _ in range(n):
        plant.step()
        events += plant.pop_events()
    return events


def head_on_params(r_x=0.02, finger=0, vy=-1.0) -> tuple[Params, np.ndarray]:
    """Horizontal stick falling (-y) onto the resting fingertip ``finger`` at ``r_x``; the
    contact is detected after 30 steps with half a step's overlap."""
    p = Params()
    tip = AirTablePlant(p, dt=DT).truth(0.0)["/fingers/state"].tips[finger]
    R = p.hand.tip_radius
    y_contact = tip[1] + R - 0.5 * abs(vy) * DT  # stick line at the contact step
    p.initial.x = tip[0] - r_x
    p.initial.y = y_contact - 30 * DT * vy
    p.initial.vy = vy
    return p, np.array(tip)


# -- the stick ---------------------------------------------------------------------------


def test_is_a_plant_with_params():
    assert issubclass(AirTablePlant, Plant)
    assert dataclasses.is_dataclass(AirTablePlant.Params)
    plant = AirTablePlant(Params(), dt=DT, rng=np.random.default_rng(0))
    assert plant.space.gravity == (0.0, 0.0) and plant.space.damping == 1.0


@pytest.mark.parametrize("width", [0.0, 0.010])
def test_mass_and_inertia_are_as_set(width):
    p = far_stick_params(vy=0.0)
    p.stick.collision_width = width
    plant = AirTablePlant(p, dt=DT)
    b = plant.stick_body
    assert b.mass == 0.0225 and b.moment == 3.2e-5  # paper: 22.5 g, 32.0e3 g mm^2
    # dynamically: an impulse P at r from the centre gives dv = P/m, domega = (r x P)/I
    P, r = np.array([0.001, -0.0005]), np.array([0.04, 0.0])
    b.apply_impulse_at_world_point(tuple(P), tuple(np.array(b.position) + r))
    assert np.array(b.velocity) == pytest.approx(P / 0.0225, rel=1e-12)
    assert b.angular_velocity == pytest.approx((r[0] * P[1] - r[1] * P[0]) / 3.2e-5, rel=1e-12)


def test_free_flight_keeps_momentum_and_spin_exactly():
    p = far_stick_params(vx=0.7, vy=-0.3, omega=12.5, theta=0.2)
    plant = AirTablePlant(p, dt=DT)
    events = run(plant, 3000)  # 1 s
    s = plant.truth(1.0)["/stick/state"]
    assert (s.vx, s.vy, s.omega) == (0.7, -0.3, 12.5)  # bit-exact: no friction, no damping
    assert s.x == pytest.approx(-0.3 + 0.7, abs=1e-12)
    assert s.y == pytest.approx(0.4 - 0.3, abs=1e-12)
    assert s.theta == pytest.approx(0.2 + 12.5, abs=1e-10)
    assert [e.kind for e in events] == []


# -- the hand ----------------------------------------------------------------------------


def test_base_moves_at_the_slider_speed_and_takes_the_right_time():
    plant = AirTablePlant(far_stick_params(), dt=DT)
    spec = plant.spec().hand
    q = plant.hand.joints.tolist()
    target = (0.2, -0.15)
    plant.apply(HandCommand(base=target, joints=(tuple(q[0]), tuple(q[1]))))
    expected = travel_time(spec, (0.0, 0.0), target, q, q)  # 0.2 s at 1.0 m/s
    prev = plant.hand.base.copy()
    reached_at = None
    for k in range(1, 1000):
        plant.step()
        base = plant.hand.base
        assert np.all(np.abs(base - prev) <= spec.base_speed * DT * (1 + 1e-9))
        prev = base.copy()
        if reached_at is None and np.allclose(base, target, atol=0.0):
            reached_at = k * DT
    assert expected == pytest.approx(0.2)
    assert reached_at is not None and abs(reached_at - expected) <= DT * 1.001
    assert plant.pop_events() == []


def test_joints_move_at_the_joint_speed_and_tips_follow_the_kinematics():
    plant = AirTablePlant(far_stick_params(), dt=DT)
    spec = plant.spec().hand
    q_from = plant.hand.joints.copy()
    q_to = q_from + np.array([[0.7, -1.4], [-0.35, 0.5]])  # slowest: 1.4 rad
    plant.apply(HandCommand(base=(0.0, 0.0), joints=tuple(map(tuple, q_to))))
    expected = travel_time(spec, (0, 0), (0, 0), q_from, q_to)  # 0.1 s at 14 rad/s
    prev, reached_at = q_from.copy(), None
    for k in range(1, 600):
        plant.step()
        q = plant.hand.joints
        assert np.all(np.abs(q - prev) <= spec.joint_speed * DT * (1 + 1e-9))
        prev = q.copy()
        # the kinematic tip bodies land on the forward kinematics (integrated, not teleported)
        tips = plant.truth(k * DT)["/fingers/state"].tips
        for f in (0, 1):
            assert tips[f] == pytest.approx(finger_tip(spec, plant.hand.base, f, q[f]), abs=1e-12)
        if reached_at is None and np.array_equal(q, q_to):
            reached_at = k * DT
    assert expected == pytest.approx(0.1)
    assert reached_at is not None and abs(reached_at - expected) <= DT * 1.001


def test_targets_outside_the_limits_are_clamped_and_reported_once():
    plant = AirTablePlant(far_stick_params(), dt=DT)
    q = tuple(map(tuple, plant.hand.joints.tolist()))
    far = HandCommand(base=(0.5, -0.1), joints=q)
    for _ in range(700):  # the controller repeats its command every step
        plant.apply(far)
        plant.step()
    ev = plant.pop_events()
    assert [e.kind for e in ev] == ["limit"]
    assert ev[0].data["base_requested"] == [0.5, -0.1]
    assert ev[0].data["base_target"] == [0.2, -0.1]
    assert ev[0].data["base_clamped"] and not ev[0].data["joints_clamped"]
    json.dumps(ev[0].data, allow_nan=False)
    assert plant.hand.base.tolist() == [0.2, -0.1]  # parked at the limit
    # a new out-of-range target (a joint) is a new occurrence; an in-range one is none
    plant.apply(HandCommand(base=(0.2, -0.1), joints=((q[0][0], 3.0), q[1])))
    plant.apply(HandCommand(base=(0.0, 0.0), joints=q))
    ev = plant.pop_events()
    assert [e.kind for e in ev] == ["limit"]
    assert ev[0].data["joints_clamped"] and ev[0].data["joint_targets"][0][1] == 2.6


# -- collisions --------------------------------------------------------------------------


def test_collision_event_fields_head_on():
    """Stick (theta = 0) moving -y at 1 m/s onto fingertip 0 at r_x = 20 mm. Impulse along +y:
    P = (1 + e) / (1/m + r_x^2/I) (1 m/s), v_y' = -1 + P/m, omega' = r_x P / I (eq. 22)."""
    p, tip = head_on_params(r_x=0.02)
    plant = AirTablePlant(p, dt=DT)
    events = run(plant, 30)
    assert [e.kind for e in events] == ["collision"]
    d = events[0].data
    m, I, e, r = 0.0225, 3.2e-5, 0.19, 0.02
    P = (1 + e) * 1.0 / (1 / m + r * r / I)
    assert d["finger"] == 0
    assert d["r_x"] == pytest.approx(0.02, abs=1e-12) and d["r_y"] == pytest.approx(0, abs=1e-12)
    assert d["theta"] == 0.0
    assert d["v_before"] == [0.0, -1.0] and d["omega_before"] == 0.0
    assert d["v_after"] == pytest.approx([0.0, -1.0 + P / m], abs=1e-12)
    assert d["omega_after"] == pytest.approx(r * P / I, rel=1e-12)
    assert d["normal"] == pytest.approx([0.0, 1.0], abs=1e-12)  # fingertip -> stick
    assert d["contact"] == pytest.approx([tip[0], tip[1] + 0.005 - 0.5 / 3000], abs=1e-12)
    assert d["penetration"] == pytest.approx(0.5 / 3000, rel=1e-9)
    assert d["tip_velocity"] == [0.0, 0.0]
    json.dumps(d, allow_nan=False)
    # the contact persists a few steps (it separates at e * 1 m/s < overlap / dt): no second
    # event and no second restitution impulse
    after = (plant.stick_body.velocity, plant.stick_body.angular_velocity)
    events = run(plant, 300)
    assert events == []
    assert np.array(plant.stick_body.velocity) == pytest.approx(np.array(after[0]), abs=1e-15)
    assert plant.stick_body.angular_velocity == pytest.approx(after[1], abs=1e-12)


def test_collision_event_names_finger_one_and_the_side():
    p, _ = head_on_params(r_x=-0.03, finger=1)
    plant = AirTablePlant(p, dt=DT)
    ev = [e for e in run(plant, 31) if e.kind == "collision"]
    assert len(ev) == 1 and ev[0].data["finger"] == 1
    assert ev[0].data["r_x"] == pytest.approx(-0.03, abs=1e-12)
    assert ev[0].data["omega_after"] < 0  # hit left of the centre from below


def test_a_moving_fingertip_hits_with_its_real_velocity():
    """The base moves +y at its 1.0 m/s limit into a resting stick, contact at the stick's
    centre: a central impact on a moving infinite mass gives the stick (1 + e) * 1.0 m/s."""
    p = Params()
    p.hand.joints1 = [-math.pi / 2, 0.0]  # finger 1 folded away below the palm
    tips = AirTablePlant(p, dt=DT).truth(0.0)["/fingers/state"].tips
    p.initial.x = tips[0][0]  # centre above fingertip 0
    p.initial.y = tips[0][1] + 0.005 + 0.01 - 0.3 / 3000
    plant = AirTablePlant(p, dt=DT)
    q = tuple(map(tuple, plant.hand.joints.tolist()))
    plant.apply(HandCommand(base=(0.0, 0.2), joints=q))
    ev = [e for e in run(plant, 40) if e.kind == "collision"]
    assert len(ev) == 1
    d = ev[0].data
    assert d["tip_velocity"] == pytest.approx([0.0, 1.0], abs=1e-9)
    assert d["v_before"] == [0.0, 0.0]
    assert d["v_after"] == pytest.approx([0.0, 1.19], abs=1e-9)
    assert d["omega_after"] == pytest.approx(0.0, abs=1e-9)


# -- rest and NaN ------------------------------------------------------------------------


def test_rest_event_once_after_50_ms_of_slow_motion():
    plant = AirTablePlant(far_stick_params(vx=0.003, vy=0.0, omega=0.05), dt=DT)
    events = []
    for k in range(1, 3001):
        plant.step()
        events += [(k, e) for e in plant.pop_events()]
    assert [e.kind for _, e in events] == ["rest"]
    k, e = events[0]
    assert 0.05 <= k * DT <= 0.05 + 2 * DT
    assert e.data["speed"] == pytest.approx(0.003)
    json.dumps(e.data, allow_nan=False)


@pytest.mark.parametrize("vx,omega", [(0.006, 0.0), (0.0, 0.12)])
def test_no_rest_event_while_moving(vx, omega):
    plant = AirTablePlant(far_stick_params(vx=vx, vy=0.0, omega=omega), dt=DT)
    assert [e.kind for e in run(plant, 600)] == []


def test_nan_state_is_an_event_once():
    plant = AirTablePlant(far_stick_params(), dt=DT)
    plant.step()
    plant.stick_body.angular_velocity = float("nan")
    events = run(plant, 10)
    assert [e.kind for e in events] == ["nan"]
    assert "omega" in events[0].data["fields"]
    json.dumps(events[0].data, allow_nan=False)


# -- truth, scene, spec ------------------------------------------------------------------


def test_truth_scene_and_spec():
    p = far_stick_params(theta=0.3)
    plant = AirTablePlant(p, dt=DT)
    truth = plant.truth(0.0)
    assert set(truth) == {"/stick/state", "/fingers/state", "/hand/state"}
    assert isinstance(truth["/stick/state"], StickState)
    assert isinstance(truth["/fingers/state"], FingersState)
    hand = truth["/hand/state"]
    assert set(hand) == {"t", "base", "joints", "base_target", "joint_targets"}
    json.dumps({k: to_dict(v) for k, v in truth.items()}, allow_nan=False)

    scene = plant.scene()
    stick, marker = scene.get("stick"), scene.get("marker")
    assert isinstance(stick, Box) and stick.size == (0.100, 0.010, 0.005)
    assert stick.position == pytest.approx((-0.3, 0.4, 0.0025))
    assert quaternion_yaw(stick.orientation) == pytest.approx(0.3)
    assert stick.albedo == 0.3 and marker.albedo == 1.0
    assert marker.position[2] > 0.005 and quaternion_yaw(marker.orientation) == pytest.approx(0.3)
    for k in (0, 1):
        tip = scene.get(f"tip{k}")
        assert isinstance(tip, Cylinder) and tip.orientation == (0.0, 0.0, 0.0, 1.0)
        assert tip.position[:2] == pytest.approx(truth["/fingers/state"].tips[k])
        assert tip.radius == 0.005 and tip.albedo == 0.1

    spec = plant.spec()
    assert isinstance(spec, AirTableSpec)
    assert not hasattr(spec.stick, "friction") and not hasattr(spec.stick, "mu")
    assert (spec.stick.mass, spec.stick.inertia, spec.stick.length, spec.stick.restitution) == (
        0.0225,
        3.2e-5,
        0.100,
        0.19,
    )
    assert spec.stick.width == p.stick.collision_width
    assert spec.hand.base_speed == 1.0 and spec.hand.joint_speed == 14.0
    assert spec.hand.base_limits == ((-0.2, 0.2), (-0.2, 0.2))
    # the spec's kinematics agree with the plant's fingertips (what a controller relies on)
    q0 = finger_ik(spec.hand, (0.0, 0.0), 0, truth["/fingers/state"].tips[0], q_near=(2.0, -1.0))
    assert q0 == pytest.approx(tuple(p.hand.joints0), abs=1e-9)


# -- determinism -------------------------------------------------------------------------


def _record(p: Params) -> list:
    plant = AirTablePlant(p, dt=DT)
    q = tuple(map(tuple, plant.hand.joints.tolist()))
    out = []
    for k in range(300):
        if k == 10:
            plant.apply(HandCommand(base=(0.01, 0.02), joints=((q[0][0] + 0.2, q[0][1]), q[1])))
        plant.step()
        t = (k + 1) * DT
        out.append(
            (
                {top: to_dict(v) for top, v in plant.truth(t).items()},
                [(e.kind, e.data) for e in plant.pop_events()],
            )
        )
    return out


def test_two_identical_runs_give_identical_truth():
    p, _ = head_on_params(r_x=0.015)
    p.initial.omega = 3.0
    a, b = _record(p), _record(p)
    assert a == b
    assert any(ev for _, ev in a)  # the run did contain a collision


# -- the outcome (the physical verdict of a run) ------------------------------------------


def held_params(vx=0.0, omega=0.0) -> Params:
    """A horizontal stick at (0, 0.1) with fingertip 0 just below and 1 just above it."""
    p = Params()
    hand = AirTablePlant(p, dt=DT).spec().hand
    gap = p.hand.tip_radius + 0.001
    for k, (name, y) in enumerate((("joints0", 0.1 - gap), ("joints1", 0.1 + gap))):
        q = finger_ik(hand, (0.0, 0.0), k, (0.0, y), q_near=hand.start_joints[k])
        assert q is not None
        setattr(p.hand, name, [float(q[0]), float(q[1])])
    p.initial.x, p.initial.y, p.initial.theta = 0.0, 0.1, 0.0
    p.initial.vx, p.initial.omega = vx, omega
    return p


def test_outcome_captured_when_held_between_the_tips():
    plant = AirTablePlant(held_params(), dt=DT)
    run(plant, 300)
    o = plant.outcome(plant.time)
    assert o["success"] is True and o["captured"] is True and o["reason"] == "captured"
    assert o["t_capture"] == pytest.approx(DT, abs=1e-12)
    assert o["speed"] == pytest.approx(0.0, abs=1e-9) and o["collisions"] == 0
    json.dumps(o, allow_nan=False)


def test_outcome_needs_the_hold_time():
    plant = AirTablePlant(held_params(), dt=DT)
    run(plant, 60)  # 20 ms < hold_time = 50 ms
    o = plant.outcome(plant.time)
    assert o["success"] is False and "only for the last" in o["reason"]


@pytest.mark.parametrize(
    "kw,words", [({"vx": 0.05}, "still moves"), ({"omega": 2.0}, "still moves")]
)
def test_outcome_not_captured_while_the_stick_moves(kw, words):
    plant = AirTablePlant(held_params(**kw), dt=DT)
    run(plant, 300)
    o = plant.outcome(plant.time)
    assert o["success"] is False and not o["captured"] and words in o["reason"]
    assert o["t_capture"] is None


def test_outcome_stopped_elsewhere_or_never_in_reach():
    p = far_stick_params(x=0.0, y=0.25, vy=0.0)  # at rest, within reach, not held
    plant = AirTablePlant(p, dt=DT)
    run(plant, 300)
    assert (
        plant.outcome(plant.time)["reason"]
        == "not captured: the stick stopped but not between the fingertips"
    )
    plant = AirTablePlant(far_stick_params(), dt=DT)  # 0.21 m beyond any finger root
    run(plant, 300)
    o = plant.outcome(plant.time)
    assert o["reason"] == "not captured: the stick never came within the hand's reach"


def test_state_reads_equal_pymunks_own_properties():
    """The logged state is the bodies' (Pymunk's properties) after each step, the hand
    moving."""
    plant = AirTablePlant(far_stick_params(vx=0.7, omega=3.0), dt=DT)
    plant.apply(HandCommand((0.05, 0.02), ((1.8, -0.8), (1.2, 0.9))))  # the hand moving
    for _ in range(30):
        plant.step()
        s, f = plant.truth(plant.time)["/stick/state"], plant.truth(plant.time)["/fingers/state"]
        sb = plant.stick_body
        assert (s.x, s.y, s.vx, s.vy) == (*sb.position, *sb.velocity)
        assert (s.theta, s.omega) == (sb.angle, sb.angular_velocity)
        assert f.tips == [list(tb.position) for tb in plant.tip_bodies]
