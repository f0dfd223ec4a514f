"""The grasping rig's verdict (plants/arm_rig/grasp_verdict.py) as a component of its own, on
synthetic readings: a hand carrying the object along its plane with the human, the same with the
object slipping in the hand, and an object pushed off its plane before the grasp."""

from __future__ import annotations

import math

import pytest

from plants.arm_rig.grasp_verdict import GraspReading, GraspVerdict, in_hand_position
from plants.arm_rig.params import GraspParams
from replay.interfaces import Occurrence
from replay.robot.arm_types import PlaneSpec

DT = 1e-3
PLANE = PlaneSpec(point=(0.5, 0.0, 1.0), normal=(1.0, 0.0, 0.0))
U, V = (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)  # the plane's in-plane axes
IN_HAND = (-0.05, 0.0, 0.0)  # m: the object's centre in the tool frame (identity orientation)
AHEAD = (0.0, 0.003, 0.004)  # m: the object from IN_HAND before the grasp (u 3 mm, v 4 mm)
GRASP_STEP, STEPS = 100, 500


def run(slip=(0, 0), off_plane_step=None) -> tuple[GraspVerdict, list, list]:
    """Feed the verdict STEPS readings: the tool moves 0.1 mm a step along the plane's u, the
    object AHEAD of IN_HAND before the grasp (at GRASP_STEP) and at IN_HAND after; the object
    slips 0.2 mm a step along the tool's y (in the plane) over the steps ``slip``;
    at ``off_plane_step`` it is 30 mm off the plane. Returns the verdict, the step's events fed
    and the slips it gave."""
    verdict = GraspVerdict(GraspParams(), PLANE, U, V, DT)
    fed, slips = [], []
    in_hand = list(IN_HAND)
    for k in range(STEPS):
        t = k * DT
        tool = (0.55, 1e-4 * k, 0.9)
        if slip[0] <= k < slip[1]:
            in_hand[1] += 2e-4
        pos = [a + b for a, b in zip(tool, in_hand)]
        if k < GRASP_STEP:
            pos = [a + b for a, b in zip(pos, AHEAD)]
        if k == off_plane_step:
            pos[0] += 0.030
        events = []
        if k == GRASP_STEP:
            events = [Occurrence("grasp", {"hold_time": 0.02})]
        reading = GraspReading(
            t,
            pos,
            (tool, (0.0, 0.0, 0.0, 1.0), (0.0,) * 3, (0.0,) * 3),
            ["index", "palm", "thumb"] if k >= GRASP_STEP else [],
            12.5,
            k >= GRASP_STEP,
            pos[:],  # the human's path: the object itself
            [3.0, 4.0, 0.0],
        )
        fed += events
        slips += verdict.observe(reading, events)
    return verdict, fed, slips


def test_in_hand_position_is_the_tool_frames_coordinates():
    # the tool turned 90 degrees about z: the world's +y is the tool's +x
    s = math.sqrt(0.5)
    x = in_hand_position([1.0, 2.5, 3.0], ((1.0, 2.0, 3.0), (0.0, 0.0, s, s)))
    assert x == pytest.approx([0.5, 0.0, 0.0], abs=1e-12)


def test_a_grasp_carried_with_the_human_succeeds():
    verdict, fed, slips = run()
    out = verdict.outcome(STEPS * DT)
    assert out["success"], out["reason"]
    assert slips == [] and out["slips"] == 0
    assert fed[0].data["normal_force"] == 12.5  # the grasp event gets the contacts' force
    assert out["first_grasp_t"] == pytest.approx((GRASP_STEP - 20) * DT)
    assert out["hold_drift_max"] == pytest.approx(0.0, abs=1e-12)
    # the object's path from the step before the grasp: AHEAD closed, then carried
    jump = math.dist(AHEAD, (0.0, 1e-4, 0.0))
    assert out["held_path"] == pytest.approx(jump + (STEPS - GRASP_STEP - 1) * 1e-4, rel=1e-9)
    assert out["off_plane_max"] == pytest.approx(0.0, abs=1e-12)
    assert out["hold_human_force_rms"] == pytest.approx(5.0)
    assert out["tracking_error_rms"] == pytest.approx(0.005, rel=1e-9)
    assert out["hand_parts_touched"] == ["index", "palm", "thumb"]


def test_an_object_slipping_in_the_hand_is_a_slip_and_not_held():
    verdict, _, slips = run(slip=(200, 260))  # 12 mm in 60 steps
    out = verdict.outcome(STEPS * DT)
    assert len(slips) == 1 and slips[0].kind == "slip"
    # the first window (slip_time) over slip_distance: 1 mm after 5 steps of 0.2 mm
    assert slips[0].data["distance"] == pytest.approx(1e-3, rel=1e-6)
    assert out["slips"] == 1
    assert out["hold_drift_max"] == pytest.approx(0.012, rel=1e-6)
    assert not out["success"]
    assert out["reason"] == "not held: the object moved 12.0 mm in the hand (> 10 mm)"


def test_a_slower_creep_is_no_slip():
    verdict, _, slips = run(slip=(200, 260))
    creep, _, creep_slips = run(slip=(200, 203))  # 0.6 mm in all: under slip_distance
    assert slips and not creep_slips
    assert creep.outcome(STEPS * DT)["success"]


def test_an_object_off_its_plane_fails_the_run():
    verdict, _, _ = run(off_plane_step=50)  # before the grasp: the reach shoved it
    out = verdict.outcome(STEPS * DT)
    assert out["off_plane_max"] == pytest.approx(0.030, rel=1e-9)
    assert not out["success"]
    assert out["reason"] == "off its plane: 30.0 mm at 0.050 s (> 20 mm)"


def test_a_release_records_how_long_the_grasp_was_held():
    verdict = GraspVerdict(GraspParams(), PLANE, U, V, DT)
    tool = ((0.5, 0.0, 0.9), (0.0, 0.0, 0.0, 1.0))
    pos = [0.5, 0.0, 0.95]
    grasp, release = Occurrence("grasp", {"hold_time": 0.0}), Occurrence("release", {})
    verdict.observe(GraspReading(0.1, pos, tool, ["palm"], 1.0, True, pos, [0.0] * 3), [grasp])
    verdict.observe(GraspReading(0.35, pos, tool, [], 0.0, False, pos, [0.0] * 3), [release])
    assert release.data["held_for"] == pytest.approx(0.25)
    out = verdict.outcome(1.0)
    assert out["longest_hold"] == pytest.approx(0.25)
    assert "grasp not held: longest hold 0.250 s < 0.3 s" in out["reason"]
    assert "held, but the object did not move while grasped" in out["reason"]
