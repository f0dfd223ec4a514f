"""The arm plants' per-step maths in plain floats (issue #10) against the array forms they
replaced: seeded random inputs, equal to the bit (the logs stay what they were)."""

from __future__ import annotations

import math

import numpy as np

from plants.bullet_arm.ft_sensor import WristFT
from plants.bullet_arm.human_hand import band_limited_path, numpy_row_sum
from plants.arm_rig.servo import VelocityServos
from replay.spatial import cross3


def test_velocity_servos_are_decoupled_and_limited_over_random_commands():
    """Seeded random mass matrices, commands within and far beyond the torque limits: below
    the limits the torque is M k (e + w_i integral) (servo.py); past them every torque is
    within its limit, at least one joint at it, and the proportional part keeps its direction
    (a scale in [0, 1] of M k e), the integral held."""
    rng = np.random.default_rng(11)
    n, steps = 7, 400
    A = rng.normal(0.0, 0.5, (n, n))
    M = A @ A.T + np.diag(rng.uniform(0.05, 1.0, n))  # a mass matrix: symmetric, positive
    lim = rng.uniform(5.0, 60.0, n)
    servos = VelocityServos(lim, 60.0, 1e-3)
    servos.preload(rng.normal(0.0, 2.0, n), M)
    linear = saturated = scaled = 0
    for k in range(steps):
        servos.set_command(rng.normal(0.0, 0.2 if k % 40 else 200.0, n))
        qd = rng.normal(0.0, 0.2, n)
        e = servos.command - qd
        acc = servos.integral + e * servos.dt
        tau_i, tau_p = M @ (servos.k * servos.wi * acc), M @ (servos.k * e)
        before = servos.integral
        tau = np.array(servos.torques(qd.tolist(), M))
        if not servos.saturated.any():
            linear += 1
            np.testing.assert_allclose(tau, tau_i + tau_p, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(servos.integral, acc, rtol=1e-12, atol=1e-15)
        else:
            saturated += 1
            assert np.all(np.abs(tau) <= lim * (1 + 1e-12))
            if np.all(np.abs(tau_i) <= lim):  # else the integral alone is past a limit
                s = np.dot(tau - tau_i, tau_p) / np.dot(tau_p, tau_p)
                assert -1e-9 <= s <= 1.0 + 1e-9
                np.testing.assert_allclose(tau, tau_i + s * tau_p, rtol=1e-9, atol=1e-9)
                scaled += 1
            np.testing.assert_array_equal(servos.integral, before)
    print(f"servo step: {linear} linear, {saturated} at a torque limit ({scaled} scaled)")
    assert linear > 0 and scaled > 0


def test_velocity_servos_preload_holds_the_torque_at_zero_error():
    M = np.diag([1.0, 0.3]) + 0.1
    servos = VelocityServos([50.0, 50.0], 500.0, 1e-3)
    tau = np.array([12.0, -3.0])
    servos.preload(tau, M)
    np.testing.assert_allclose(servos.torques([0.0, 0.0], M), tau, rtol=1e-9)


def test_velocity_servos_stop_on_a_non_finite_command():
    servos = VelocityServos([10.0, 10.0], 50.0, 1e-3)
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
        h.start, h.kicks = 0.05, None  # (no kicks: the band-limited path alone)
        h._W, h._A, h._PHI, h._S0 = w, a, phi, np.sin(phi)
        h._rows = [
            list(zip(*row)) for row in zip(w.tolist(), a.tolist(), phi.tolist(), h._S0.tolist())
        ]
        for t in rng.uniform(0.0, 3.0, 200):
            tt = max(t - h.start, 0.0)
            want = (h._A * (np.sin(h._W * tt + h._PHI) - h._S0)).sum(axis=1).tolist()
            np.testing.assert_allclose(h.offset(float(t)), want, rtol=0.0, atol=1e-15)
