"""The prediction-free estimator of the direct mapping (``estimator: last``, issue #38)."""

from __future__ import annotations

import pytest

from replay.control.catching.controller import Params
from replay.control.catching.estimator import BallisticEstimator, LastFrameEstimator


def test_newest_frame_and_two_frame_difference_whatever_the_time():
    est = LastFrameEstimator()
    assert est.state_f(0.0) is None and est.time_to_radius(0.0, (0, 0, 0), 0.1) is None
    g = 9.81
    for k in range(5):  # a ballistic arc sampled every 10 ms
        t = 0.01 * k
        est.add(t, (2.0 - 9.0 * t, 0.5 * t, 1.0 - 0.5 * g * t * t))
    est.add(0.02, (99.0, 99.0, 99.0))  # out of order: ignored
    r, v, a = est.state_f(1.0)  # no extrapolation to t = 1 s
    t0, t1 = 0.03, 0.04
    assert r == pytest.approx((2.0 - 9.0 * t1, 0.5 * t1, 1.0 - 0.5 * g * t1 * t1))
    # the difference quotient: the mean velocity over the last frame interval, no gravity model
    vz = -0.5 * g * (t1 * t1 - t0 * t0) / (t1 - t0)
    assert v == pytest.approx((-9.0, 0.5, vz), rel=1e-9)
    assert a == (0.0, 0.0, 0.0)
    # the ballistic estimator of the same frames carries r over the latency with gravity
    ball = BallisticEstimator()
    for k in range(5):
        t = 0.01 * k
        ball.add(t, (2.0 - 9.0 * t, 0.5 * t, 1.0 - 0.5 * g * t * t))
    assert ball.state_f(0.05)[0][0] == pytest.approx(2.0 - 9.0 * 0.05, abs=1e-9)
    assert est.state_f(0.05)[0][0] == pytest.approx(2.0 - 9.0 * 0.04, abs=1e-12)


def test_first_order_time_to_contact():
    est = LastFrameEstimator()
    est.add(0.0, (1.2, 0.0, 0.0))
    assert est.time_to_radius(0.0, (0.0, 0.0, 0.0), 0.2) is None  # one frame: no velocity
    est.add(0.1, (1.0, 0.0, 0.0))  # 2 m/s towards the origin
    assert est.time_to_radius(0.1, (0.0, 0.0, 0.0), 0.2) == pytest.approx(0.1 + 0.4)
    assert est.time_to_radius(0.1, (0.0, 0.0, 0.0), 1.5) == 0.1  # already inside
    assert est.time_to_radius(0.1, (0.0, 5.0, 0.0), 0.2) is None  # passes the sphere by
    away = LastFrameEstimator()
    away.add(0.0, (1.0, 0.0, 0.0))
    away.add(0.1, (1.2, 0.0, 0.0))
    assert away.time_to_radius(0.1, (0.0, 0.0, 0.0), 0.2) is None  # moving away


def test_default_estimator_is_the_ballistic_fit():
    assert Params().estimator == "ballistic"
    assert Params(estimator="last").estimator == "last"


def test_prediction_free_scenario_differs_from_catch_optimised_only_in_the_estimator():
    from conftest import ROOT
    from replay.scenario import load_scenario
    from replay.scenario.loader import to_plain

    base = to_plain(load_scenario(ROOT / "scenarios" / "catch_optimised.yaml"))
    free = to_plain(load_scenario(ROOT / "scenarios" / "prediction_free_catch.yaml"))
    assert free["controller"]["params"].pop("estimator") == "last"
    assert base["controller"]["params"].pop("estimator") == "ballistic"
    for d in (base, free):
        for k in ("name", "description", "notes", "extends"):
            d.pop(k, None)
    assert free == base
