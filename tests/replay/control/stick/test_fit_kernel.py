"""The stick estimator's compiled running sums and fit (``_fit.add``, ``_fit.fit``) against their
Python references (StickEstimator._sum_reference, _refit_reference): seeded random throws with
noise, collisions (model breaks), gaps and hours-long streams (the sums re-anchored), the same
estimate after every sample, to the bit."""

import math

import numpy as np

from replay.control.stick.estimator import StickEstimator


def reference_estimator(**kw) -> StickEstimator:
    est = StickEstimator(**kw)
    est._sum = est._sum_reference  # type: ignore[method-assign]
    est._refit = est._refit_reference  # type: ignore[method-assign]
    est._rebuild()
    return est


def test_compiled_fit_equals_the_reference_over_random_streams():
    rng = np.random.default_rng(23)
    samples = breaks = 0
    for k in range(40):
        kw = {
            "window": int(rng.integers(2, 40)),
            "min_samples": 2,
            "confirm": int(rng.integers(1, 3)),
        }
        fast, ref = StickEstimator(**kw), reference_estimator(**kw)
        t, x, y, th = float(rng.uniform(0, 100)), *rng.uniform(-0.3, 0.3, 2), rng.uniform(-3, 3)
        vx, vy, w = rng.normal(0.0, 1.0), rng.normal(0.0, 1.0), rng.normal(0.0, 10.0)
        for i in range(int(rng.integers(20, 400))):
            dt = 1.0 / 300.0 * (1 + int(rng.uniform() < 0.05) * int(rng.integers(1, 200)))
            t += dt
            x, y, th = x + vx * dt, y + vy * dt, th + w * dt
            if rng.uniform() < 0.02:  # a collision: new velocities
                vx, vy, w = rng.normal(0.0, 1.0), rng.normal(0.0, 1.0), rng.normal(0.0, 10.0)
            noise = rng.normal(0.0, 1e-4, 3) * (k % 3)
            mx, my = float(x + noise[0]), float(y + noise[1])
            mth = math.remainder(float(th + noise[2]), math.pi)
            b1, b2 = fast.add(t, mx, my, mth), ref.add(t, mx, my, mth)
            assert b1 == b2
            breaks += b1
            assert fast.estimate() == ref.estimate()
            assert list(fast._sums) == list(ref._sums)
            samples += 1
    print(f"compiled fit = reference after {samples} samples ({breaks} breaks)")
    assert breaks > 10
