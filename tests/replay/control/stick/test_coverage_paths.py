"""The stick planners' sweep checks against their whole-array NumPy references: sweep
.first_covered (sweep.covered_fixed: only the samples near the point, looked at one by one with
the skips the stick's speed and spin allow) against sweep.covered for a fixed point (first /
last covered sample; Coverage.hits is that too, tests/.../test_stick_fast_paths.py), and
ContactPlanner.route_clear (the moving hand in arrays, each finger's tips only where its check
needs them, the standing hand as fixed points) against oracles.route_clear. The same
operations on the samples they look at, so the answers agree exactly on seeded random motions,
points and routes, and the random cases exercise both answers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from replay.control.stick import coverage as sweeps
from replay.control.stick.hand_model import Config, HandModel, travel
from replay.control.stick.plan import ContactPlanner
from replay.control.stick.estimator import StickEstimate
from replay.control.stick.strategy import ThreeStepParams
from replay.control.stick.coverage import (
    Motion,
    covered,
    first_covered,
    sample_times,
)

from tests.replay.control.stick import oracles
from tests.replay.control.stick.test_stick_method import air_spec


def random_motion(rng) -> Motion:
    e = StickEstimate(
        rng.uniform(0.0, 0.2),
        *rng.uniform(-0.1, 0.3, 2),
        rng.uniform(-3, 3),
        *rng.normal(size=2) * 0.8,
        rng.normal() * 10.0,
        30,
        0.0,
        0.0,
    )
    if rng.uniform() < 0.3:
        return Motion(e)  # no planned contact
    return Motion(e, rng.uniform(0.1, 0.6), tuple(rng.normal(size=3) * [0.3, 0.3, 4.0]))


def near_points(rng, motion: Motion, t0: float, t1: float, count: int) -> np.ndarray:
    """Points about the stick's pose at random times of [t0, t1]: covered or not, often."""
    out = np.empty((count, 2))
    for i in range(count):
        c, th = motion.pose(float(rng.uniform(t0, max(t0, t1))))
        xb, yb = rng.uniform(-0.08, 0.08), rng.uniform(-0.03, 0.03)
        out[i] = c + [xb * math.cos(th) - yb * math.sin(th), xb * math.sin(th) + yb * math.cos(th)]
    return out


def test_libm_cos_and_sin_are_numpys():
    """sweep.covered_fixed's premise: NumPy's float64 cos/sin give libm's (math's) bits here."""
    x = np.random.default_rng(20).uniform(-60.0, 60.0, 20000)
    assert all(np.cos(x) == [math.cos(v) for v in x])
    assert all(np.sin(x) == [math.sin(v) for v in x])


def test_first_and_last_covered_sample_are_numpys():
    rng = np.random.default_rng(21)
    hits = cases = 0
    for _ in range(300):
        motion = random_motion(rng)
        t0 = rng.uniform(0.0, 0.4)
        t1 = t0 + rng.choice([-0.01, 0.0, rng.uniform(0.0005, 0.9)])
        times = sample_times(t0, t1)
        for p in near_points(rng, motion, t0, t1, 5):
            grow = rng.uniform(-0.001, 0.01)
            ref = covered(motion, times, [p], 0.05, 0.005, grow)[:, 0]
            cases += 1
            first = first_covered(motion, t0, t1, p, 0.05, 0.005, grow)
            last = first_covered(motion, t0, t1, p, 0.05, 0.005, grow, last=True)
            if ref.any():
                hits += 1
                assert first == float(times[ref][0]) and last == float(times[ref][-1])
            else:
                assert first is None and last is None
    assert 0.1 * cases < hits < 0.9 * cases


def random_config(rng, hand) -> Config:
    (xlo, xhi), (ylo, yhi) = hand.base_limits
    (a0, a1), (b0, b1) = hand.joint_limits
    return Config(
        (float(rng.uniform(xlo, xhi)), float(rng.uniform(ylo, yhi))),
        tuple((float(rng.uniform(a0, a1)), float(rng.uniform(b0, b1))) for _ in range(2)),
    )


@pytest.mark.parametrize("width", [0.0, 0.01])
def test_route_clear_is_the_numpy_reference(width):
    spec = air_spec()
    stick = type(spec.stick)(**{**spec.stick.__dict__, "width": width})
    hand = spec.hand
    home = Config(tuple(hand.start_base), tuple(tuple(q) for q in hand.start_joints))
    planner = ContactPlanner(ThreeStepParams(), hand, stick, HandModel(hand, home))
    rng = np.random.default_rng(23 + int(width * 1000))
    cases = clear = hit = 0
    far = Motion(StickEstimate(0.0, 100.0, 100.0, 0.0, 0.0, 0.0, 0.0, 30, 0.0, 0.0))
    for _ in range(400):
        motion = random_motion(rng)
        t = float(rng.uniform(0.0, 0.3))
        t_c = t + float(rng.uniform(0.02, 0.9))
        now = random_config(rng, hand)
        # 1-3 waypoints, some the straight route, some late or overlapping (refused)
        route, before = [], now
        for _ in range(int(rng.integers(1, 4))):
            prev = route[-1][1] if route else now
            cfg = random_config(rng, hand)
            if rng.uniform() < 0.5:  # a small move: quick, so often clear in time
                cfg = Config(
                    tuple(b + rng.normal() * 0.02 for b in prev.base),
                    tuple(tuple(q + rng.normal() * 0.1 for q in qq) for qq in prev.joints),
                )
            # the previous segment done in time (mostly) before this one starts
            t_s = (
                t
                if not route
                else route[-1][0] + travel(hand, before, prev) * float(rng.uniform(0.8, 1.5))
            )
            route.append((t_s, cfg))
            before = prev
        for k in (0, 1):
            for check_idle in (True, False):
                ref = oracles.route_clear(planner, t, now, route, k, motion, t_c, check_idle)
                got = planner.route_clear(t, now, route, k, motion, t_c, check_idle)
                assert got == ref
                cases += 1
                clear += ref is not None
                # refused by the sweep, not by the timing: clear of a stick far away
                hit += (
                    ref is None
                    and oracles.route_clear(planner, t, now, route, k, far, t_c, check_idle)
                    is not None
                )
    assert 0.05 * cases < clear < 0.95 * cases and hit > 0.05 * cases


def test_samples_made_alone_are_sample_times():
    """sample_time, sample_times_at and count_before: the values and counts of sample_times."""
    rng = np.random.default_rng(24)
    spans = [(0.0, 0.0), (0.1, 0.05), (1e-310, 2e-310)]
    spans += [(float(a), float(a + b)) for a, b in rng.uniform(0.0, 0.9, (40, 2))]
    for t0, t1 in spans:
        times = sample_times(t0, t1)
        n = len(times)
        assert [sweeps.sample_time(t0, t1, i) for i in range(n)] == times.tolist()
        for lo, hi in ((0, n), (0, 1), (n // 3, n), (n // 2, n // 2 + 2)):
            assert sweeps.sample_times_at(t0, t1, lo, hi).tolist() == times[lo:hi].tolist()
        for t in [
            *times[[0, n // 2, -1]],
            t0 - 1.0,
            t1 + 1.0,
            float(rng.uniform(t0, max(t0, t1) + 0.01)),
        ]:
            assert sweeps.count_before(t0, t1, t, inclusive=True) == int(np.sum(times <= t))
            assert sweeps.count_before(t0, t1, t, inclusive=False) == int(np.sum(times < t))
