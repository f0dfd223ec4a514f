"""The catching controller's per-step paths (one sample in Python floats) against the batched
NumPy formulas they replace: the mapping (eqs. 7, 16, 23), the ballistic fit and its
time-to-contact, the PD torque, over seeded random neighbourhoods of the throws the method
sees."""

from __future__ import annotations

import math

import numpy as np
import pytest

from replay.control.catching import ArmModel, BallisticEstimator, ProblemConfig, build_problem
from replay.control.catching.estimator import _roots
from replay.robot import wam_chain
from replay.robot.hand import CATCH3, hand_body

QA = math.pi / 2
G = np.array([0.0, 0.0, -9.81])


@pytest.fixture(scope="module")
def mapping():
    model = ArmModel.from_chain(
        wam_chain(4, payload=hand_body(CATCH3)),
        q_fixed=np.array([0, math.pi / 4, 0, 0]),
        point_in_tool=(0.0, 0.0, CATCH3.palm_size[2] + 0.0175),
    )
    problem = build_problem(
        model, ProblemConfig(tau_max=(60.0, 60.0, 30.0), omega_max=(3.0, 3.0, 3.0), max_iter=0)
    )
    m = problem.mapping
    rng = np.random.default_rng(3)
    m.A = rng.normal(scale=0.3, size=m.A.shape)  # a non-trivial b(q) of eq. 12
    return m


def _states(rng, geo, n):
    """Object states around the throws: r in the flight region and near the shoulder (inside
    d_min: clamped), velocities of 8-10 m/s towards the arm, gravity plus a little noise."""
    out = []
    for k in range(n):
        if k % 5 == 0:  # inside the domain's hole: clamped, flagged
            d = rng.normal(size=3)
            r = geo.origin + d / np.linalg.norm(d) * rng.uniform(0.2, 1.0) * geo.d_min
        else:
            r = np.array([rng.uniform(0.4, 3.4), rng.uniform(-0.4, 0.4), rng.uniform(0.2, 1.3)])
        v = np.array([-rng.uniform(8.0, 10.0), rng.normal(scale=0.3), rng.normal(scale=1.5)])
        out.append((r, v, G + rng.normal(scale=0.5, size=3)))
    return out


def test_evaluate_one_equals_the_batched_mapping(mapping):
    rng = np.random.default_rng(11)
    states = _states(rng, mapping.geo, 400)
    compared = clamped = 0
    for r, v, a in states:
        inv = mapping.geo.inverse(r)
        p_one, ok_one = mapping.geo.inverse_one(r)
        assert ok_one == bool(inv.in_domain[0])
        np.testing.assert_allclose(p_one, inv.p[0], rtol=1e-12, atol=1e-12)
        if not ok_one:  # clamped to |r - O| = d_min, where l_c's Jacobian is singular (rank 2)
            clamped += 1
            continue
        q, qd, qdd, f = mapping.evaluate(r, v, a)
        q1, qd1, qdd1, q_o, ok = mapping.evaluate_one(r, v, a)
        assert ok
        for ref, one in ((q[0], q1), (qd[0], qd1), (qdd[0], qdd1), (f.p[0], q_o)):
            np.testing.assert_allclose(one, ref, rtol=1e-9, atol=1e-9)
        compared += 1
    for h in (0.3, 1.0):  # on the J1 axis: q1 undetermined (the reference), flagged
        r_axis = mapping.geo.origin + np.array([0.0, 0.0, h])
        p_one, ok_one = mapping.geo.inverse_one(r_axis)
        assert not ok_one
        np.testing.assert_allclose(p_one, mapping.geo.inverse(r_axis).p[0], atol=1e-12)
    print(f"evaluate_one vs evaluate: {compared} states equal, {clamped} clamped (inverse equal)")
    assert compared >= 0.75 * len(states) and clamped >= 0.15 * len(states)


def test_coefficients_one_equals_the_monomials(mapping):
    poly = mapping.poly
    rng = np.random.default_rng(12)
    for _ in range(50):
        p = np.array([rng.uniform(-1, 1), rng.uniform(-0.5, 1.5), QA + rng.uniform(-3, 0.5)])
        pd, pdd = rng.normal(scale=5, size=3), rng.normal(scale=50, size=3)
        m, dm, d2m = poly.monomials(p, 2)
        ref = (m[0], dm[0] @ pd, dm[0] @ pdd + np.einsum("jkl,k,l->j", d2m[0], pd, pd))
        for one, r in zip(poly.coefficients_one(p, pd, pdd), ref):
            np.testing.assert_allclose(one, r, rtol=1e-12, atol=1e-12)


def _lstsq_fit(samples, g):
    """The fit of estimator.py written directly: least squares about t_last."""
    t = np.array([s[0] for s in samples])
    R = np.array([s[1] for s in samples])
    s = t - t[-1]
    Y = R - 0.5 * np.outer(s * s, g)
    sol, *_ = np.linalg.lstsq(np.column_stack([np.ones_like(s), s]), Y, rcond=None)
    return sol[0], sol[1]


@pytest.mark.parametrize("max_samples", [400, 30])
def test_running_sum_fit_equals_least_squares(max_samples):
    """A noisy 1 kHz stream with dropped frames, long enough for the window to slide, the sums
    to be re-centred many times and (max_samples = 30) the deque to drop samples itself."""
    rng = np.random.default_rng(13)
    est = BallisticEstimator(G, window=0.05, max_samples=max_samples)
    r0, v0 = np.array([3.0, 0.1, 1.0]), np.array([-9.0, -0.2, 0.5])
    worst_r = worst_v = 0.0
    for k in range(900):
        if rng.random() < 0.1:
            continue  # a lost frame
        t = k * 1e-3
        est.add(t, r0 + v0 * t + 0.5 * G * t * t + rng.normal(scale=1e-3, size=3))
        if est.n < 2:
            continue
        _, r_fit, v_fit = est.fit()
        r_ref, v_ref = _lstsq_fit(list(est.buf), G)
        worst_r = max(worst_r, float(np.abs(r_fit - r_ref).max()))
        worst_v = max(worst_v, float(np.abs(v_fit - v_ref).max()))
    print(f"running sums vs lstsq: |dr| <= {worst_r:.2e} m, |dv| <= {worst_v:.2e} m/s")
    assert est.n <= min(max_samples, 51)
    assert worst_r < 1e-9 and worst_v < 1e-7


def test_roots_equal_numpy_roots():
    rng = np.random.default_rng(14)
    for _ in range(200):
        c = rng.normal(size=5)
        np.testing.assert_allclose(np.sort_complex(_roots(c)), np.sort_complex(np.roots(c)))
    # an end coefficient of zero: np.roots's own handling
    np.testing.assert_allclose(np.sort_complex(_roots([0.0, 1.0, -3.0, 2.0, 0.0])), [0, 1, 2])


def _ttr_eigvals(est, t, origin, R):
    """time_to_radius by the companion matrix only (the path Newton's method stands in for)."""
    r, v, g = est.state(t, from_fit=True)
    d = r - origin
    c = [0.25 * (g @ g), v @ g, v @ v + d @ g, 2.0 * (d @ v), d @ d - R * R]
    roots = _roots(c)
    real = roots[np.abs(roots.imag) < 1e-9].real
    real = real[real >= 0.0]
    return t + float(real.min()) if real.size else None


def test_time_to_radius_newton_equals_the_eigenvalue_roots():
    """Seeded throws at, past, away from and over the catch sphere: the same first arrival (or
    none) as the companion matrix's roots; the share Newton's method settles itself is printed."""
    from replay.control.catching import estimator as E

    rng = np.random.default_rng(15)
    origin, R = np.array([0.0, 0.0, 0.346]), 0.48
    settled = n = 0
    for k in range(300):
        r0 = np.array([rng.uniform(1.0, 3.5), rng.uniform(-0.5, 0.5), rng.uniform(0.0, 1.5)])
        aim = origin + rng.normal(scale=0.4, size=3)
        speed = rng.uniform(3.0, 12.0) * (1 if k % 4 else -1)  # a quarter thrown away
        v0 = (aim - r0) / np.linalg.norm(aim - r0) * speed
        est = BallisticEstimator(G, window=0.05)
        for i in range(20):
            est.add(i * 1e-3, r0 + v0 * i * 1e-3 + 0.5 * G * (i * 1e-3) ** 2)
        t = 0.019
        got, ref = est.time_to_radius(t, origin, R), _ttr_eigvals(est, t, origin, R)
        st = est.state(t, from_fit=True)
        d = st[0] - origin
        if d @ d > R * R and ref is not None:  # outside, arriving: Newton's case
            n += 1
            c = [0.25 * G @ G, st[1] @ G, st[1] @ st[1] + d @ G, 2 * d @ st[1], d @ d - R * R]
            settled += E._first_root_newton([float(x) for x in c]) is not None
        assert (got is None) == (ref is None)
        if got is not None:
            assert got == pytest.approx(ref, abs=1e-9)
    print(f"time_to_radius: Newton settled {settled}/{n} arrivals, the rest by eigenvalues")
    assert n >= 60 and settled >= 0.9 * n


def test_torque_equals_the_numpy_formula():
    """pd_torque (the catch controllers' per-step torque, in floats) against the NumPy
    np.clip(ff + Kp (q_d - q) + Kd (qd_d - qd), -limit, limit) on seeded random states of 1-7
    joints, a third of them beyond the limits: the same floats to the bit."""
    from replay.control.catching.base import pd_torque

    rng = np.random.default_rng(17)
    saturated = 0
    for k in range(300):
        n = 1 + k % 7
        args = [rng.normal(scale=s, size=n) for s in (20, 900, 0.02, 0.02, 30, 0.5, 0.5)]
        limit = rng.uniform(1.0, 60.0 if k % 3 else 5.0, size=n)
        ff, kp, q_d, q, kd, qd_d, qd = args
        ref = np.clip(ff + kp * (q_d - q) + kd * (qd_d - qd), -limit, limit).tolist()
        got = pd_torque(*(a.tolist() for a in args), limit.tolist())
        assert got == ref and all(type(x) is float for x in got)
        saturated += sum(abs(x) == lim for x, lim in zip(got, limit))
    print(f"torque: 300 states equal, {saturated} joint torques at their limit")
    assert 100 < saturated < 0.8 * sum(1 + k % 7 for k in range(300))
