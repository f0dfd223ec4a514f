"""The gain rule of the grasping tasks (replay/control/grasping/gain_rule.py): at every loop period
of sweeps/grasp_loops.yaml a simulated step of each closed loop, with the rule's gain, the
velocity servo's lag and (the head) the chip's one-frame latency, is as well damped as at 1 ms;
with the 1 ms gains kept, the 33 ms loops are not."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from grasp_rig import rig  # noqa: E402

from replay.control.grasping import gain_rule  # noqa: E402
from replay.control.grasping.arm_control import ArmControlTask, ArmParams  # noqa: E402
from replay.control.grasping.hand_control import HandParams  # noqa: E402
from replay.control.grasping.head_tracking import HeadParams  # noqa: E402

PERIODS = (0.001, 0.002, 0.005, 0.010, 0.015, 0.020, 0.033)  # s: sweeps/grasp_loops.yaml
DT = 1e-4  # s: the simulation's step
ARM_SERVO, HEAD_SERVO = 500.0, 300.0  # rad/s: the plant's velocity loops (plants/bullet_arm)


def step(K: float, T: float, servo: float, late: int, t_end: float = 0.6) -> list[float]:
    """A unit step of x' = v, v' = servo (u - v), u = K (1 - x) sampled and held every T,
    from the sample ``late`` frames old."""
    per, a = round(T / DT), 1.0 - math.exp(-servo * DT)
    x = v = u = 0.0
    seen = [0.0] * (late + 1)
    out = []
    for i in range(round(t_end / DT)):
        if i % per == 0:
            seen.append(x)
            u = K * (1.0 - seen[-1 - late])
        v += (u - v) * a
        x += v * DT
        out.append(x)
    return out


def overshoot(xs: list[float]) -> float:
    return max(xs) - 1.0


def settling(xs: list[float], band: float = 0.05) -> float:
    """s: the last time the response was outside 1 +- band (inf if it still is at the end)."""
    last = max((i for i, x in enumerate(xs) if abs(x - 1.0) > band), default=-1)
    return math.inf if last == len(xs) - 1 else (last + 1) * DT


LOOPS = {  # name: (1 ms gain, rule, servo bandwidth, frames of latency)
    "arm K^a1 (eq. 2)": (60.0, gain_rule.direct_gain, ARM_SERVO, 0),
    "arm K^a1 roll (eq. 2)": (30.0, gain_rule.direct_gain, ARM_SERVO, 0),
    "hand K^hg (eq. 4)": (25.0, gain_rule.direct_gain, 1e4, 0),
    "head K^v (eq. 1)": (60.0, gain_rule.delayed_gain, HEAD_SERVO, 1),
}


@pytest.mark.parametrize("name", LOOPS)
def test_rule_keeps_every_loop_damped_at_every_period(name):
    k1, rule, servo, late = LOOPS[name]
    base = settling(step(k1, 0.001, servo, late))
    for T in PERIODS:
        xs = step(rule(k1, T), T, servo, late)
        assert overshoot(xs) < 0.05, (name, T, overshoot(xs))
        if late == 0 or T <= 0.005:  # the pole kept: settles as fast as at 1 ms
            assert settling(xs) <= 1.25 * base, (name, T, settling(xs), base)
        else:  # critically damped beyond 10.5 ms: slower, still settled
            assert settling(xs) < 0.25, (name, T, settling(xs))


def test_fixed_gains_lose_the_loops_at_33_ms():
    arm = step(60.0, 0.033, ARM_SERVO, 0)
    head = step(60.0, 0.033, HEAD_SERVO, 1)
    assert overshoot(arm) > 0.5  # the pole at 1 - K T = -0.98: a sign-flipping ring
    assert max(abs(x) for x in head) > 10.0  # K T = 1.98 > 1: diverges


def test_rule_at_the_design_period_is_the_identity():
    for k in (60.0, 30.0, 25.0, 20.0):
        assert gain_rule.direct_gain(k, 0.001) == pytest.approx(k, rel=1e-12)
    assert gain_rule.delayed_gain(60.0, 0.001) == pytest.approx(60.0, rel=1e-12)
    assert gain_rule.scale(54.0, 0.001) == pytest.approx(1.0, rel=1e-12)


def test_delayed_rule_is_critically_damped_beyond_its_reach():
    T = 0.033  # p = exp(-66.2 / s * T) < 1/2: K T = 1/4, the double root at 1/2
    assert gain_rule.delayed_gain(60.0, T) * T == pytest.approx(0.25, rel=1e-12)
    T = 0.005
    K = gain_rule.delayed_gain(60.0, T)
    p = (1.0 + math.sqrt(1.0 - 4.0 * K * T)) / 2.0  # the dominant root kept: exp(-lambda T)
    assert -math.log(p) / T == pytest.approx(gain_rule.delayed_rate(60.0), rel=1e-9)


def test_gain_period_zero_keeps_the_gains_and_a_mismatch_is_refused():
    for cls in (HeadParams, HandParams, ArmParams):
        assert cls().gain_period == 0.0
    spec = rig().spec()
    assert ArmControlTask(ArmParams(), spec=spec).K_a1[1] == 60.0
    task = ArmControlTask(ArmParams(gain_period=0.01), spec=spec)
    assert task.K_a1[1] == pytest.approx(gain_rule.direct_gain(60.0, 0.01), rel=1e-12)
    assert task.K_af == pytest.approx(0.3 * gain_rule.scale(54.0, 0.01), rel=1e-12)
    with pytest.raises(ValueError, match="gain_period"):
        gain_rule.check_period(0.01, 0.001, "arm")
    gain_rule.check_period(0.033, 0.033000000000001, "arm")
