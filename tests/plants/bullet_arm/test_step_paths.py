"""The arm plant's shortcuts in its per-step path (issue #10) against the long way they replace:
commands read without an array, the torque limits' one-pass usual case, the hand's velocity
motors set only when their targets change, contacts not asked for while the object is beyond
the robot's reach. Each one leaves the physics and the events what they were."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from plants.arm_rig.params import Params
from plants.arm_rig.rig import ArmRig
from plants.arm_rig.arm_state import limit_torque, limit_torque_loop
from plants.arm_rig.rig import floats
from replay.robot.arm_types import ArmCommand
from replay.runner import Runner
from replay.scenario import load_scenario

DT = 1e-3
CATCHING = dict(initial_q=[0.0, math.pi / 4, 0.0, 0.0], locked_joints=["J3"])


def make(**kw) -> ArmRig:
    return ArmRig(Params(**kw), dt=DT, rng=np.random.default_rng(0))


def test_commands_read_as_numpy_reads_them():
    rng = np.random.default_rng(3)
    forms = 0
    for _ in range(300):
        x = rng.normal(0.0, 50.0, 4)
        kind = rng.integers(6)
        if kind == 0:
            v = x.tolist()
        elif kind == 1:
            v = tuple(x.tolist())
        elif kind == 2:
            v = x  # an array
        elif kind == 3:
            v = [int(a) for a in x]
        elif kind == 4:
            v = [[a] for a in x.tolist()]  # nested: NumPy flattens it
        else:
            v = list(x.astype(np.float32))
        want = np.asarray(v, dtype=float).reshape(-1).tolist()
        got = floats(v, 4, "torque")
        assert [type(a) for a in got] == [float] * 4
        assert [a.hex() for a in got] == [a.hex() for a in want]
        forms += 1
    assert forms == 300
    with pytest.raises(ValueError, match="torque needs 4 values, got 3"):
        floats([1.0, 2.0, 3.0], 4, "torque")
    with pytest.raises(ValueError):
        floats(["a", 1.0, 2.0, 3.0], 4, "torque")


def test_torque_limits_one_pass_equals_the_joint_loop():
    """Seeded random commands (within and beyond the limits, NaN, inf, signed zeros): the one
    pass over finite commands (arm_state.limit_torque) gives the loop's applied torques and
    clamps; the plant's step gives them and their events (both plants share the rig's _limit_torque)."""
    plant = make(**CATCHING)
    rng = np.random.default_rng(17)
    tlim, vlim, locked = plant._tlim_l, plant._vlim_l, plant._locked_l
    lim = np.asarray(tlim)
    quick = clipped = 0
    for k in range(400):
        tau = rng.uniform(-1.3, 1.3, 4) * lim
        if k % 3 == 0:
            tau = rng.uniform(-0.9, 0.9, 4) * lim
        if k % 7 == 0:
            tau[rng.integers(4)] = [math.nan, math.inf, -math.inf, -0.0][k % 4]
        qd = rng.normal(0.0, 2.0, 4).tolist()
        cmd = tau.tolist()
        for enforce in (False, True):
            fast = limit_torque(cmd, tlim, locked, enforce, vlim, qd)
            slow = limit_torque_loop(cmd, tlim, locked, enforce, vlim, qd)
            assert [a.hex() for a in fast[0]] == [a.hex() for a in slow[0]]
            assert fast[1] == slow[1]
        plant._tau_cmd = cmd
        plant._torque_episode = [False] * 4
        plant.pop_events()
        plant._limit_torque(qd)
        applied, clamped = limit_torque_loop(cmd, tlim, locked, False, vlim, qd)
        assert [a.hex() for a in plant._tau_applied] == [a.hex() for a in applied]
        assert plant._clamped == clamped
        assert [(e.kind, e.data) for e in plant.pop_events()] == [
            (
                "torque_limit",
                {
                    "joint": plant.joint_names[i],
                    "commanded": cmd[i] if math.isfinite(cmd[i]) else None,
                    "applied": applied[i],
                    "limit": tlim[i],
                },
            )
            for i in range(4)
            if clamped[i]
        ]
        quick += math.isfinite(sum(tau))
        clipped += any(clamped)
    print(f"torque limits: {quick}/400 commands finite (the one pass), {clipped} clamped")
    assert 0 < quick < 400 and 0 < clipped < 400
    plant.close()


def test_hand_motors_set_only_on_new_targets_move_the_hand_the_same():
    """Closing and holding the hand: skipping the call when the targets repeat (PyBullet keeps
    a velocity motor's target) gives the same hand joint states as setting them every step."""
    lazy, eager = make(**CATCHING, object="none"), make(**CATCHING, object="none")
    table = lazy.hand_table
    calls = []
    set_motors = lazy.engine.set_motors
    lazy.engine.set_motors = lambda *a, **kw: (calls.append(a[2]), set_motors(*a, **kw))[1]
    for k in range(120):
        hand = table.closed_posture if 20 <= k < 80 else table.open_posture
        for plant in (lazy, eager):
            plant.apply(ArmCommand([0.0] * 4, hand))
        eager.engine._hand_v = None  # forget the last targets: the call every step
        lazy.step()
        eager.step()
        assert lazy._state()[1] == eager._state()[1]
        assert lazy._state()[0] == eager._state()[0]
    skipped = 120 - sum(1 for c in calls if c == 0)  # VELOCITY_CONTROL == 0
    print(f"hand motors: {skipped}/120 steps without a call")
    assert 0 < skipped < 120
    lazy.close()
    eager.close()


def test_nothing_of_the_robot_is_near_a_ball_beyond_its_reach():
    """At seeded random joint angles, a ball placed anywhere at the plant's no-contact distance
    from the base is farther than 4 cm from every link (PyBullet's closest points), while a
    ball at the tool frame does touch (the check can fail)."""
    plant = make(**CATCHING)
    bc, rng = plant.engine.bc, np.random.default_rng(8)
    base = np.asarray(plant.engine._base_pose[0])
    lo, hi = np.asarray(plant.lower), np.asarray(plant.upper)
    near = 0
    for _ in range(60):
        q = rng.uniform(lo, hi)
        for j, i in zip(plant.engine.arm_j, plant.active):
            bc.resetJointState(plant.engine.robot, j, q[i])
        d = rng.normal(size=3)
        pos = base + plant.engine._contact_radius * d / np.linalg.norm(d)
        bc.resetBasePositionAndOrientation(plant.engine.obj, pos.tolist(), [0, 0, 0, 1])
        assert (
            bc.getClosestPoints(bodyA=plant.engine.obj, bodyB=plant.engine.robot, distance=0.04)
            == ()
        )
        tool = bc.getLinkState(
            plant.engine.robot, plant.engine.tool_link, computeForwardKinematics=1
        )[4]
        bc.resetBasePositionAndOrientation(plant.engine.obj, list(tool), [0, 0, 0, 1])
        near += bool(
            bc.getClosestPoints(bodyA=plant.engine.obj, bodyB=plant.engine.robot, distance=0.04)
        )
    assert near == 60
    plant.close()


@pytest.mark.parametrize("name", ["catch_optimised", "catch_10ms"])
def test_contacts_skipped_only_where_pybullet_has_none(project_root, name, tmp_path: Path):
    """A whole catch run: each step where the plant does not ask for contacts, PyBullet has
    none; the skip happens (most of the flight) and the ball is caught."""
    runner = Runner(load_scenario(project_root / "scenarios" / f"{name}.yaml"))
    plant = runner.plant
    ask = plant.engine._get_contact_points
    asked = [0]

    def counted(**kw):
        asked[0] += 1
        return ask(**kw)

    plant.engine._get_contact_points = counted
    check = plant.engine.object_contacts
    steps = [0]

    def both(pos, v):
        got = check(pos, v)
        want = [
            c
            for c in ask(bodyA=plant.engine.obj, bodyB=plant.engine.robot)
            if c[9] > 0.0 or c[8] <= 1e-4
        ]
        assert got == want
        steps[0] += 1
        return got

    plant.engine.object_contacts = both
    result = runner.run(tmp_path / "run.mcap")
    print(f"{name}: contacts asked for at {asked[0]} of {steps[0]} steps")
    assert result.outcome["success"]
    assert 0 < asked[0] < 0.8 * steps[0]
