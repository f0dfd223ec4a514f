"""The arm plants' per-step maths in plain floats (issue #10) against the array forms they
replaced: seeded random inputs, equal to the bit (the logs stay what they were)."""

from __future__ import annotations

import math

import numpy as np

from plants.bullet_arm.ft_sensor import WristFT
from plants.bullet_arm.human_hand import band_limited_path, numpy_row_sum
from plants.bullet_arm.servo import VelocityServos
from replay.spatial import cross3


def _servo_reference(command, integral, qd, K, wi, lim, dt):
    """The PI velocity servos on arrays (plants/bullet_arm/servo.py's docstring)."""
    e = command - qd
    acc = integral + e * dt
    raw = K * (e + wi * acc)
    sat = np.abs(raw) > lim
    return np.where(sat, integral, acc), np.clip(raw, -lim, lim), sat


def test_velocity_servos_equal_the_vector_form_over_random_commands():
    rng = np.random.default_rng(11)
    n, steps = 7, 400
    inertia = rng.uniform(0.05, 2.0, n)
    lim = rng.uniform(5.0, 60.0, n)
    servos = VelocityServos(inertia, lim, 60.0, 1e-3)
    servos.preload(rng.normal(0.0, 2.0, n))
    same = saturated = 0
    for k in range(steps):
        servos.set_command(rng.normal(0.0, 0.2 if k % 40 else 200.0, n))
        qd = rng.normal(0.0, 0.2, n)
        want = _servo_reference(
            servos.command, servos.integral, qd, servos.K, servos.wi, servos.limits, servos.dt
        )
        got_tau = servos.torques(qd.tolist())
        got = (servos.integral, np.array(got_tau), servos.saturated)
        same += all(np.array_equal(a, b) for a, b in zip(got, want))
        saturated += bool(want[2].any())
    print(f"servo step: {same}/{steps} equal, {saturated} with a joint at its torque limit")
    assert same == steps and 0 < saturated < steps


def test_velocity_servos_stop_on_a_non_finite_command():
    servos = VelocityServos([1.0, 1.0], [10.0, 10.0], 50.0, 1e-3)
    servos.set_command([math.nan, 1.0])
    assert servos.command.tolist() == [0.0, 1.0]


def test_wrist_conversion_equals_the_vector_form():
    rng = np.random.default_rng(5)
    ft = WristFT.__new__(WristFT)  # the conversion only (no PyBullet client)
    ft.r_c = rng.normal(0.0, 0.05, 3)
    ft._rc = ft.r_c.tolist()
    same = 0
    for _ in range(500):
        raw = rng.normal(0.0, 10.0, 6)
        f, m = raw[:3], raw[3:]
        want = np.concatenate([-f, -(m + cross3(ft.r_c, f))])
        same += np.array_equal(ft.convert(tuple(raw.tolist())), want)
    assert same == 500


def test_row_sum_is_numpys_over_random_rows():
    rng = np.random.default_rng(3)
    lengths = list(range(1, 40)) + [64, 127, 128, 129, 200]
    bad = []
    for n in lengths:
        M = rng.normal(size=(20, n)) * rng.uniform(1e-3, 1e3, size=(20, n))
        got = [numpy_row_sum(row) for row in M.tolist()]
        if got != M.sum(axis=1).tolist():
            bad.append(n)
    print(f"row sums: {len(lengths) - len(bad)}/{len(lengths)} lengths equal to NumPy's")
    assert not bad


def test_human_offset_equals_the_array_form():
    """HumanHand.offset in floats = sum(A (sin(W t + PHI) - sin(PHI)), axis=1) on arrays: equal
    here (math.sin and NumPy's sin agree on this machine); within 1e-15 m where NumPy's SIMD sin
    may round differently."""
    from plants.bullet_arm.human_hand import HumanHand

    rng = np.random.default_rng(9)
    for components in (1, 6, 9):
        h = HumanHand.__new__(HumanHand)  # the path only (no PyBullet client)
        w, a, phi = band_limited_path(
            rng, components=components, f_min=0.1, f_max=1.0, rms_rate=0.1, axes=3
        )
        h.start = 0.05
        h._W, h._A, h._PHI, h._S0 = w, a, phi, np.sin(phi)
        h._rows = [
            list(zip(*row)) for row in zip(w.tolist(), a.tolist(), phi.tolist(), h._S0.tolist())
        ]
        for t in rng.uniform(0.0, 3.0, 200):
            tt = max(t - h.start, 0.0)
            want = (h._A * (np.sin(h._W * tt + h._PHI) - h._S0)).sum(axis=1).tolist()
            np.testing.assert_allclose(h.offset(float(t)), want, rtol=0.0, atol=1e-15)
