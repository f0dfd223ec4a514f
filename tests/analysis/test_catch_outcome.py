"""The arm rig's catch verdict (plants/arm_rig/outcome.py): every outcome says why."""

from __future__ import annotations

import numpy as np
import pytest

from plants.arm_rig.outcome import CatchWatch

IDENT = [0.0, 0.0, 0.0, 1.0]  # palm frame = world: the palm normal is +z
THICK, RADIUS = 0.012, 0.045


def _fly(offset, parts_when=None, caught_from=None, t_end=0.2, z0=0.3, vz=-3.0, dz_end=None):
    """A ball falling along -z at lateral ``offset`` onto a palm at rest at the origin."""
    w = CatchWatch(kind="ball", palm_radius=RADIUS, palm_thickness=THICK)
    for k in range(int(t_end / 1e-3)):
        t = k * 1e-3
        z = z0 + vz * t
        pos = np.array([offset, 0.0, max(z, THICK + 0.0175)])
        parts = parts_when(pos, t) if parts_when else []
        caught = caught_from is not None and t >= caught_from
        w.observe(t, pos, [0.0, 0.0, vz], [0, 0, 0], IDENT, [0, 0, 0], [0, 0, 0], parts, caught)
    return w


def test_rim_and_face_bounces_are_told_apart():
    hit = lambda pos, t: ["palm"] if pos[2] <= THICK + 0.0175 + 1e-9 else []  # noqa: E731
    rim = _fly(0.06, hit).verdict(caught=False, ever_caught=False)
    assert rim["success"] is False and rim["reason"] == "ball bounced off the palm rim"
    assert rim["contact_offset"] == pytest.approx(0.06)
    assert rim["approach_angle"] == pytest.approx(0.0, abs=1e-6)  # straight down the axis
    assert rim["contact_speed"] == pytest.approx(3.0)
    face = _fly(0.01, hit).verdict(caught=False, ever_caught=False)
    assert face["reason"] == "ball bounced off the palm face"


def test_finger_arm_caught_and_dropped():
    finger = lambda pos, t: ["f2"] if pos[2] < 0.05 else []  # noqa: E731
    assert (
        _fly(0.0, finger).verdict(caught=False, ever_caught=False)["reason"]
        == "ball bounced off finger f2"
    )
    w = _fly(0.0, finger, caught_from=0.12)
    ok = w.verdict(caught=True, ever_caught=True)
    assert ok["success"] is True and ok["reason"] == "caught"
    assert ok["catch_time"] == pytest.approx(0.12) and ok["first_contact_time"] < 0.12
    assert w.verdict(caught=False, ever_caught=True)["reason"] == "ball dropped after the catch"


def test_no_touch_says_where_the_ball_went():
    # passes 0.2 m below the palm face centre, moving along +x (the palm faces +z)
    w = CatchWatch(kind="ball", palm_radius=RADIUS, palm_thickness=THICK)
    for k in range(200):
        t = k * 1e-3
        w.observe(
            t,
            [-0.5 + 5.0 * t, 0.0, -0.2],
            [5.0, 0.0, 0.0],
            [0, 0, 0],
            IDENT,
            [0, 0, 0],
            [0, 0, 0],
            [],
            False,
        )
    v = w.verdict(caught=False, ever_caught=False)
    assert v["success"] is False and v["reason"] == "ball passed below the hand"
    assert v["closest_distance"] == pytest.approx(0.2 + THICK, abs=1e-3)
    # still closing in when the run ends
    w = CatchWatch(kind="ball", palm_radius=RADIUS, palm_thickness=THICK)
    for k in range(10):
        w.observe(
            k * 1e-3,
            [1.0 - 0.01 * k, 0.0, 0.0],
            [-10.0, 0, 0],
            [0, 0, 0],
            IDENT,
            [0, 0, 0],
            [0, 0, 0],
            [],
            False,
        )
    assert (
        w.verdict(caught=False, ever_caught=False)["reason"]
        == "the run ended before the ball reached the hand"
    )
