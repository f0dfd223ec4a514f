"""The air table's compiled body input/output (plants/airtable/_bodies.c, body_state.TableIO)
against its Python reference, the Chipmunk readers and setter of body_state: on seeded random
bodies and tip targets the same state after every engine step (exactly: the same Chipmunk
calls on the same numbers), and LeanSpace's step is Pymunk's (the same trajectory, contacts
included)."""

from __future__ import annotations

import numpy as np
import pymunk
import pytest

from plants.airtable import body_state
from plants.airtable.lean_space import LeanSpace


def table(space_cls, rng):
    """A stick (dynamic, spinning) and two kinematic tips near it in a fresh space."""
    space = space_cls()
    space.gravity = (0.0, 0.0)
    stick = pymunk.Body(0.0225, 3.2e-5)
    stick.position = tuple(rng.uniform(-0.05, 0.05, 2))
    stick.velocity = tuple(rng.normal(size=2) * 0.5)
    stick.angle, stick.angular_velocity = rng.uniform(-3, 3), rng.normal() * 10.0
    seg = pymunk.Segment(stick, (-0.05, 0.0), (0.05, 0.0), 0.0)
    seg.elasticity, seg.friction = 0.19, 0.3
    space.add(stick, seg)
    tips = []
    for _ in range(2):
        tb = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
        tb.position = tuple(rng.uniform(-0.06, 0.06, 2))
        c = pymunk.Circle(tb, 0.005)
        c.filter = pymunk.ShapeFilter(group=1)
        space.add(tb, c)
        tips.append(tb)
    return space, stick, tips


def python_state(stick, tips):
    """The reference: body_state's Chipmunk readers."""
    return body_state.pose_reader(stick)() + sum(
        (body_state.position_reader(tb)() for tb in tips), ()
    )


@pytest.mark.parametrize("direct", [False, True])
def test_table_io_steps_as_the_python_readers_and_setter(direct):
    """direct: the engine's cpSpaceStep called from C (space_step None), else LeanSpace.step."""
    dt = 1.0 / 3000.0
    hit = 0
    for seed in range(6):
        rng = np.random.default_rng(40 + seed)
        space_a, stick_a, tips_a = table(pymunk.Space, np.random.default_rng(seed))
        space_b, stick_b, tips_b = table(LeanSpace, np.random.default_rng(seed))
        io = body_state.TableIO(stick_b, tips_b, space_b if direct else None)
        assert io.direct == direct
        if direct:  # (a space's first step checks the bodies added: Pymunk's own)
            space_a.step(dt), space_b.step(dt)
            io.read()
        assert tuple(io.state) == python_state(stick_a, tips_a)
        v0 = tuple(stick_a.velocity)
        for _ in range(600):
            targets = [tuple(t.position + rng.normal(size=2) * 1e-4) for t in tips_a]
            pos = [body_state.position_reader(tb)() for tb in tips_a]
            for tb, (tx, ty), (x, y) in zip(tips_a, targets, pos):
                body_state.velocity_setter(tb)((tx - x) / dt, (ty - y) / dt)
            space_a.step(dt)
            io.step(targets, dt, None if direct else space_b.step, (0.01, 0.1, 0.02, 0.5))
            assert tuple(io.state) == python_state(stick_a, tips_a)
            assert tuple(io.state) == python_state(stick_b, tips_b)
        hit += tuple(stick_a.velocity) != v0  # only a contact changes it (no gravity)
    assert hit >= 2  # contacts were compared too


def test_table_io_cannot_be_copied():
    """Its addresses are the bodies'; a copy would read the originals."""
    import copy

    _, stick, tips = table(pymunk.Space, np.random.default_rng(0))
    with pytest.raises(TypeError, match="cannot be copied"):
        copy.deepcopy(body_state.TableIO(stick, tips))


def test_lean_space_refuses_changes_made_during_a_step():
    space = LeanSpace()
    a = pymunk.Body(1.0, 1.0)
    sa = pymunk.Circle(a, 0.1)
    b = pymunk.Body(1.0, 1.0)
    b.position = (0.15, 0.0)
    sb = pymunk.Circle(b, 0.1)
    space.add(a, sa, b, sb)
    space.step(0.01)  # a plain step: fine
    b.position = (0.5, 0.0)
    space.step(0.01)  # apart again
    space.on_collision(begin=lambda arb, sp, data: sp.add_post_step_callback(print, "x"))
    b.position = (0.15, 0.0)
    with pytest.raises(RuntimeError, match="during a step"):
        space.step(0.01)


def test_the_usual_case_flag_is_never_wrong():
    """TableIO.step's True (finite, too fast to rest or be held) agrees with the plant's own
    checks (math.hypot) wherever it is given, on speeds and spins about the thresholds."""
    import math

    rng = np.random.default_rng(41)
    limits = (0.01, 0.1, 0.02, 0.5)  # rest_speed, rest_omega, hold_speed, hold_omega
    space, stick, tips = table(pymunk.Space, rng)
    for tb in tips:
        tb.position = (5.0, 5.0)  # far away: no contact, the velocity stays as set
    io = body_state.TableIO(stick, tips)
    flagged = usual = 0
    for _ in range(3000):
        v = rng.choice(limits[::2]) * (1.0 + rng.choice([0.0, 1e-16, -1e-16, rng.normal() * 0.5]))
        a = rng.uniform(0.0, 2.0 * math.pi)
        stick.velocity = (v * math.cos(a), v * math.sin(a))
        stick.angular_velocity = rng.choice(limits[1::2]) * rng.choice([0.5, 1.0, 2.0, -2.0])
        io.read()
        flag = io.step([(5.0, 5.0), (5.0, 5.0)], 1.0 / 3000.0, space.step, limits)
        x, y, vx, vy, th, w, *tp = io.state
        speed, spin = math.hypot(vx, vy), abs(w)
        finite = math.isfinite(x + y + th + vx + vy + w + sum(tp))
        ok = (
            finite
            and not (speed < limits[0] and spin < limits[1])
            and (speed >= limits[2] or spin >= limits[3])
        )
        assert not flag or ok
        flagged += flag
        usual += ok
    assert 0.3 * usual < flagged <= usual  # mostly decided by the kernel


def test_step_hand_advances_the_servo_as_its_python_reference():
    """_bodies.step_hand (the servo's step and the tips' kinematics, then step, the engine's
    cpSpaceStep called from C) against HandServo.advance and tip_list, then TableIO.step through
    LeanSpace.step: the same hand state and bodies, exactly, with targets set now and then (the
    servo moving, landing and resting)."""
    from plants.airtable.hand import HandServo
    from plants.airtable.params import Params
    from plants.airtable.settings import hand_spec

    dt = 1.0 / 3000.0
    spec = hand_spec(Params())
    moved = settled = 0
    for seed in range(4):
        rng = np.random.default_rng(70 + seed)
        space_a, stick_a, tips_a = table(LeanSpace, np.random.default_rng(seed))
        space_b, stick_b, tips_b = table(LeanSpace, np.random.default_rng(seed))
        io_a = body_state.TableIO(stick_a, tips_a)
        io_b = body_state.TableIO(stick_b, tips_b, space_b)  # b: the engine called from C
        assert io_b.direct and not io_a.direct
        space_b.step(dt)  # (a space's first step checks the bodies added: Pymunk's own)
        space_a.step(dt)
        io_a.read(), io_b.read()
        q0 = [[0.3, 1.2], [-0.4, -1.0]]
        hand_a, hand_b = HandServo(spec, [0.0, 0.0], q0), HandServo(spec, [0.0, 0.0], q0)
        limits = (0.01, 0.1, 0.02, 0.5)
        lean = io_b.lean_stepper(hand_b, dt, limits)  # the same call, its arguments bound
        assert lean is not None and io_a.lean_stepper(hand_a, dt, limits) is None
        for i in range(900):
            if rng.uniform() < 0.02:  # a new target: far (now and then beyond the limits) or near
                if rng.uniform() < 0.3:
                    base, joints = rng.uniform(-0.25, 0.25, 2), rng.uniform(-3.5, 3.5, (2, 2))
                else:
                    base = hand_a.base + rng.normal(size=2) * 0.002
                    joints = hand_a.joints + rng.normal(size=(2, 2)) * 0.02
                assert hand_a.set_targets(base, joints) == hand_b.set_targets(base, joints)
            hand_a.advance(dt)
            usual_a = io_a.step(hand_a.tip_list(), dt, space_a.step, (0.01, 0.1, 0.02, 0.5))
            usual_b = lean() if i % 2 else io_b.step_hand(hand_b, dt, None, limits)
            assert usual_a == usual_b
            assert tuple(hand_a.state) == tuple(hand_b.state)
            assert tuple(io_a.state) == tuple(io_b.state)
            moved += not hand_a.state[12]
            settled += bool(hand_a.state[12])
    print(f"servo compared moving {moved} and settled {settled} steps")
    assert moved > 100 and settled > 100


def test_set_targets_clamps_as_np_clip():
    """HandServo.set_targets' scalar clamping against np.clip (its reference): the same targets
    to the bit (NaN, -0.0 at a limit 0.0 and values beyond the limits included) and the same
    clamping report."""
    import math

    from plants.airtable.hand import BASE_TARGET, JOINT_TARGETS, HandServo
    from plants.airtable.params import Params
    from plants.airtable.settings import hand_spec

    spec = hand_spec(Params())
    hand = HandServo(spec, [0.0, 0.0], [[0.0, 0.0], [0.0, 0.0]])
    lims = [
        *spec.base_limits[0],
        *spec.base_limits[1],
        *spec.joint_limits[0],
        *spec.joint_limits[1],
    ]
    rng = np.random.default_rng(8)
    specials = [math.nan, -0.0, 0.0, *lims, *(-v for v in lims)]
    clamped = 0
    for _ in range(500):
        v = rng.uniform(-4.0, 4.0, 6)
        for i in np.flatnonzero(rng.uniform(size=6) < 0.2):
            v[i] = specials[rng.integers(len(specials))]
        base, joints = v[:2], v[2:].reshape(2, 2)
        report = hand.set_targets(tuple(base), tuple(map(tuple, joints)))
        ref_b, b_clamped = hand.clamp_base(base)
        ref_q, q_clamped = hand.clamp_joints(joints)
        got = np.array(hand.state[BASE_TARGET]), np.array(hand.state[JOINT_TARGETS])
        for a, ref in zip(got, (ref_b.ravel(), ref_q.ravel())):
            assert a.tobytes() == np.ascontiguousarray(ref, dtype=float).tobytes()
        assert (report is not None) == (b_clamped or q_clamped)
        if report is not None:
            clamped += 1
            assert report["base_clamped"] == b_clamped and report["joints_clamped"] == q_clamped
            np.testing.assert_array_equal(report["joint_targets"], ref_q)
    assert clamped > 100
