"""The human path's kicks (plants/arm_rig/human_path.py, issue #38): a velocity step of the
path for a set time at Poisson times, off by default without touching the path."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plants.arm_rig.human_path import HumanPath

BASE = dict(
    origin=[0.75, 0.0, 0.55], rpy0=[0.0, 0.0, 0.0], u=[0.0, 1.0, 0.0], v=[0.0, 0.0, 1.0],
    n=[1.0, 0.0, 0.0], speed=0.1, roll_rate=0.2, f_min=0.1, f_max=1.0, components=6,
    max_force=30.0, start=0.0, mass=0.1, gravity=9.81, stiffness=500.0, damping=10.0,
    rot_stiffness=0.5, rot_damping=0.01, max_torque=1.0,
)  # fmt: skip


def path(**kw) -> HumanPath:
    return HumanPath(np.random.default_rng(7), **{**BASE, **kw})


def test_no_kicks_by_default_and_the_path_unchanged():
    plain, off = path(), path(kick_rate=0.0, kick_speed=1.0, kick_duration=0.1)
    assert plain.kicks is None and off.kicks is None
    for t in (0.0, 0.3, 1.7):
        assert plain.offset(t) == off.offset(t) and plain.rate(t) == off.rate(t)


def test_each_kick_steps_the_velocity_and_displaces_the_path_by_speed_times_duration():
    speed, duration = 0.4, 0.1
    plain, kicked = path(), path(kick_rate=2.0, kick_speed=speed, kick_duration=duration)
    t_end = 5.0
    kicked.offset(t_end)  # draws the kicks up to t_end
    times = kicked.kicks.times
    assert 3 <= len(times) <= 25  # ~10 at 2/s (Poisson)
    assert times == sorted(times) and times[0] > 0.0
    lone = [
        t0
        for i, t0 in enumerate(times)
        if all(abs(t0 - x) > duration for j, x in enumerate(times) if j != i)
    ]
    assert lone  # at 2/s, 0.1 s long, most kicks stand alone
    t = lone[0] + duration / 2  # a lone kick's rate is the step, in its direction
    dr = np.subtract(kicked.rate(t)[:2], plain.rate(t)[:2])
    assert math.hypot(*dr) == pytest.approx(speed, rel=1e-9)
    t = t_end
    du = np.subtract(kicked.offset(t)[:2], plain.offset(t)[:2])
    expect = sum(
        speed * min(t - t0, duration) * np.array(d) for t0, d in zip(times, kicked.kicks.dirs)
    )
    np.testing.assert_allclose(du, expect, atol=1e-12)
    assert np.linalg.norm(du) > 0.0
    assert kicked.offset(t)[2] == plain.offset(t)[2]  # roll untouched


def test_kicks_need_a_speed_and_a_duration():
    with pytest.raises(ValueError, match="kick"):
        path(kick_rate=1.0, kick_speed=0.0, kick_duration=0.1)


@pytest.mark.parametrize(
    "field,value",
    [("human_kick_rate", "1e9"), ("human_kick_speed", "1e6"), ("human_kick_duration", "1e6")],
)
def test_a_kick_beyond_its_bound_is_one_line_before_anything_runs(field, value):
    """A rate of 1e9 kicks a second would draw (and sum at every step) ~1e9 kicks: refused at
    its field by the loader, as every bounded parameter is."""
    from cli_checks import invoke

    r = invoke("validate", "grasp_hexahedron", "--set", f"plant.params.{field}={value}")
    assert r.exit_code == 2 and f"plant.params.{field}: expected a number" in r.output, r.output
