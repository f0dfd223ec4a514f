"""The arm plant's optional compiled once-a-step arithmetic (plants/bullet_arm/_arm_state.c) against its
Python references (arm_state.py, outcome.palm_frame_reference): seeded random inputs, equal
to the bit, NaN and inf included."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plants.bullet_arm import arm_state
from plants.bullet_arm.arm_state import joint_state_reference, limit_flags_reference
from plants.bullet_arm.outcome import palm_frame_reference

_arm_state = arm_state._ARM_STATE
if _arm_state is None:
    pytest.skip(
        "the arm state accelerator is not built (or REPLAY_NO_ACCEL)", allow_module_level=True
    )


def _bits(x):
    """Floats as their hex (NaN == NaN, -0.0 != 0.0), through tuples, lists and bools."""
    if isinstance(x, float):
        return ("f", x.hex())
    if isinstance(x, (list, tuple)):
        return (type(x).__name__, [_bits(a) for a in x])
    return (type(x).__name__, x)


def _odd(rng, x: np.ndarray, p: float = 0.05) -> list:
    """x as floats, a few of them NaN or +-inf."""
    out = x.tolist()
    for i in range(len(out)):
        if rng.random() < p:
            out[i] = [math.nan, math.inf, -math.inf][rng.integers(3)]
    return out


def test_joint_state_equals_the_reference():
    rng = np.random.default_rng(21)
    locked_runs = 0
    for _ in range(300):
        na, nh = int(rng.integers(1, 8)), int(rng.integers(0, 15))
        dof = na + int(rng.integers(0, 3))  # some arm joints locked
        states = tuple(
            (
                *_odd(rng, rng.normal(0.0, 2.0, 2)),
                tuple(rng.normal(0.0, 1.0, 6).tolist()),
                float(rng.normal(0.0, 5.0)),
            )
            for _ in range(na + nh)
        )
        slots = rng.permutation(dof)[:na]  # arm joint slots[k] is read joint k
        pick = [-1] * dof
        for k, i in enumerate(slots):
            pick[int(i)] = k
        locked = rng.normal(0.0, 1.0, dof).tolist()
        want = joint_state_reference(states, na, tuple(pick), locked)
        got = _arm_state.joint_state(states, na, tuple(pick), locked)
        assert _bits(got) == _bits(want)
        locked_runs += dof > na
    print(f"joint_state: 300 equal, {locked_runs} with locked joints")
    assert 0 < locked_runs < 300
    with pytest.raises(IndexError):
        _arm_state.joint_state(((0.0, 0.0, (), 0.0),), 1, (1,), [0.0])


def test_limit_flags_equal_the_reference():
    rng = np.random.default_rng(4)
    kinds = {"none": 0, "changed": 0, "not finite": 0}
    for k in range(600):
        n = int(rng.integers(1, 8))
        q, qd = rng.normal(0.0, 2.0, n), rng.normal(0.0, 3.0, n)
        lower, upper = -rng.uniform(0.5, 2.5, n), rng.uniform(0.5, 2.5, n)
        vlim = rng.uniform(1.0, 4.0, n)
        if k % 2:  # last step's flags: as now (the usual case) or random
            over0 = (np.abs(qd) > vlim).tolist()
            at0 = ((q <= lower) | (q >= upper)).tolist()
        else:
            over0 = (rng.random(n) < 0.3).tolist()
            at0 = (rng.random(n) < 0.3).tolist()
        obj = k % 3 != 0
        args = (
            _odd(rng, q, 0.01),
            _odd(rng, qd, 0.01),
            _odd(rng, rng.normal(0, 1, 3), 0.02) if obj else None,
            _odd(rng, rng.normal(0, 5, 3), 0.02) if obj else None,
            vlim.tolist(),
            lower.tolist(),
            upper.tolist(),
            over0,
            at0,
        )
        want = limit_flags_reference(*args)
        assert _bits(_arm_state.limit_flags(*args)) == _bits(want)
        kinds["none" if want is None else "not finite" if not want[0] else "changed"] += 1
    print(f"limit_flags over 600 states: {kinds}")
    assert all(kinds.values())


def test_palm_frame_equals_the_reference():
    rng = np.random.default_rng(9)
    still = 0
    for k in range(2000):
        quat = rng.normal(0.0, 1.0, 4)
        if k % 2:
            quat /= np.linalg.norm(quat)
        palm_vel, omega = rng.normal(0.0, 3.0, 3).tolist(), rng.normal(0.0, 10.0, 3).tolist()
        obj_vel = rng.normal(0.0, 6.0, 3).tolist()
        if k % 50 == 0:  # moving with the palm point: speed 0, angle 0
            omega, obj_vel = [0.0, 0.0, 0.0], list(palm_vel)
            still += 1
        args = (
            tuple(rng.normal(0.0, 1.0, 3).tolist()),
            tuple(obj_vel),
            tuple(rng.normal(0.0, 1.0, 3).tolist()),
            tuple(quat.tolist()),
            tuple(palm_vel),
            tuple(omega),
            float(rng.uniform(0.0, 0.05)),
        )
        want = palm_frame_reference(*args)
        got = _arm_state.palm_frame(*args)
        assert _bits(got) == _bits(want)
    assert still == 40
    nan = palm_frame_reference(
        (math.nan, 0.0, 0.0), (1.0, 0, 0), (0, 0, 0), (0, 0, 0, 1), (0, 0, 0), (0, 0, 0), 0.01
    )
    got = _arm_state.palm_frame(
        (math.nan, 0.0, 0.0), (1.0, 0, 0), (0, 0, 0), (0, 0, 0, 1), (0, 0, 0), (0, 0, 0), 0.01
    )
    assert _bits(got) == _bits(nan)
