"""The stick estimator: least-squares constant velocities from 300 fps vision (theta mod pi),
trajectory prediction, and collision detection as a break of the constant-velocity model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from replay.control.stick.estimator import StickEstimator, unwrap_to

FPS = 300.0


def mod_pi(th: float) -> float:
    """What the camera reports: theta modulo pi in (-pi/2, pi/2]."""
    r = (th + math.pi / 2) % math.pi - math.pi / 2
    return r + math.pi if r <= -math.pi / 2 else r


def samples(state, t0, n, noise=(0.0, 0.0), rng=None):
    """n frames of a stick with constant velocities: state = (x, y, theta, vx, vy, omega) at t0."""
    x, y, th, vx, vy, w = state
    out = []
    for i in range(n):
        t = t0 + i / FPS
        dt = t - t0
        px, py, pth = x + vx * dt, y + vy * dt, th + w * dt
        if rng is not None:
            px += rng.normal(0.0, noise[0])
            py += rng.normal(0.0, noise[0])
            pth += rng.normal(0.0, noise[1])
        out.append((t, px, py, mod_pi(pth)))
    return out


def test_noisy_constant_velocity_is_estimated():
    rng = np.random.default_rng(7)
    state = (-0.3, 0.05, 0.4, 1.1, -0.2, 9.9)
    est = StickEstimator(window=30, min_samples=6)
    breaks = [est.add(*s) for s in samples(state, 0.0, 60, noise=(0.0005, 0.01), rng=rng)]
    assert not any(breaks)
    e = est.estimate()
    assert e.n == 30 and est.ready()
    assert e.vx == pytest.approx(1.1, abs=0.03) and e.vy == pytest.approx(-0.2, abs=0.03)
    assert e.omega == pytest.approx(9.9, abs=0.5)
    t_last = 59 / FPS
    assert e.t_ref == pytest.approx(t_last)
    x, y, th = est.predict(t_last + 0.1)  # 0.1 s ahead
    assert x == pytest.approx(-0.3 + 1.1 * (t_last + 0.1), abs=0.004)
    assert y == pytest.approx(0.05 - 0.2 * (t_last + 0.1), abs=0.004)
    assert th == pytest.approx(0.4 + 9.9 * (t_last + 0.1), abs=0.06)
    assert 0.0002 < e.rms_xy < 0.001 and 0.004 < e.rms_theta < 0.02


def test_ready_after_min_samples():
    est = StickEstimator(min_samples=6)
    assert not est.ready() and est.estimate() is None
    with pytest.raises(RuntimeError):
        est.predict(0.0)
    for s in samples((0, 0, 0, 0.5, 0, 1.0), 0.0, 6):
        assert not est.ready()
        est.add(*s)
    assert est.ready()


def test_theta_is_unwrapped_through_many_half_turns():
    """30 rad/s spins past pi/2 every 52 ms; the camera folds theta into (-pi/2, pi/2]."""
    state = (0.0, 0.0, 1.4, 0.0, 0.3, -30.0)
    est = StickEstimator(window=30)
    data = samples(state, 0.0, 150)
    assert max(s[3] for s in data) <= math.pi / 2 and min(s[3] for s in data) > -math.pi / 2
    assert not any(est.add(*s) for s in data)
    e = est.estimate()
    assert e.omega == pytest.approx(-30.0, abs=1e-6)
    t_last = 149 / FPS
    assert e.theta == pytest.approx(1.4 - 30.0 * t_last, abs=1e-6)  # continuous, ~ -13.5 rad
    assert est.predict(t_last + 0.05)[2] == pytest.approx(1.4 - 30.0 * (t_last + 0.05), abs=1e-6)


def test_unwrap_to_picks_the_nearest_branch():
    assert unwrap_to(1.5, -1.5) == pytest.approx(1.5 - math.pi)
    assert unwrap_to(-1.5, 7.9) == pytest.approx(-1.5 + 3 * math.pi)
    assert unwrap_to(0.2, 0.1) == pytest.approx(0.2)


def test_collision_breaks_the_model_and_restarts_the_fit():
    rng = np.random.default_rng(3)
    t_c = 0.2005  # between frames 60 and 61
    x_c, th_c = -0.3 + 1.1 * t_c, 0.3 + 9.9 * t_c

    def pose(t):  # v_1 = 0, omega_1 = -10 (Fig. 7)
        if t < t_c:
            return -0.3 + 1.1 * t, 0.0, 0.3 + 9.9 * t
        return x_c, 0.0, th_c - 10.0 * (t - t_c)

    data = []
    for i in range(100):
        t = i / FPS
        x, y, th = pose(t)
        data.append(
            (t, x + rng.normal(0, 3e-4), y + rng.normal(0, 3e-4), mod_pi(th + rng.normal(0, 0.005)))
        )
    est = StickEstimator(window=30, min_samples=6, pos_tol=0.002, theta_tol=0.03, confirm=2)
    flags = [est.add(*s) for s in data]
    hits = [s[0] for s, f in zip(data, flags) if f]
    assert len(hits) == 1
    assert t_c < hits[0] < t_c + 4 / FPS  # found within a few frames
    assert t_c < est.breaks[0] <= hits[0]
    assert est.before_break.vx == pytest.approx(1.1, abs=0.05)
    e = est.estimate()
    assert e.n == 30  # refilled from the break on
    assert abs(e.vx) < 0.02 and abs(e.vy) < 0.02
    assert e.omega == pytest.approx(-10.0, abs=0.2)
    assert e.at(t_c)[2] == pytest.approx(th_c, abs=0.02)  # continuous through the collision


def test_a_single_outlier_is_not_a_collision():
    data = samples((0.0, 0.0, 0.0, 0.5, 0.5, 2.0), 0.0, 40)
    t, x, y, th = data[20]
    data[20] = (t, x + 0.01, y, th)  # one bad frame, 10 mm off
    est = StickEstimator(confirm=2)
    assert not any(est.add(*s) for s in data)
    assert est.estimate().vx == pytest.approx(0.5, abs=1e-9)  # the outlier was dropped
    est1 = StickEstimator(confirm=1)
    assert sum(est1.add(*s) for s in data) >= 1  # without confirmation it would break


def test_no_false_breaks_on_long_noisy_flight():
    rng = np.random.default_rng(11)
    est = StickEstimator()
    data = samples((0.1, -0.1, 2.0, -0.4, 0.8, -7.0), 0.0, 600, (0.0004, 0.006), rng)
    assert sum(est.add(*s) for s in data) == 0


def test_bad_configuration_is_refused():
    with pytest.raises(ValueError):
        StickEstimator(window=5, min_samples=6)
    with pytest.raises(ValueError):
        StickEstimator(confirm=0)
