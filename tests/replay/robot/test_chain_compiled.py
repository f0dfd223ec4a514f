"""The serial chain's compiled one-configuration path (replay/robot/_chain.c) against its Python
float reference (SerialChain.point_floats, rnea_floats) and the NumPy batch (rnea_batch)."""

from __future__ import annotations

import numpy as np
import pytest

from replay.robot.hand import CATCH3, hand_body
from replay.robot.wam import wam_chain


def _chains():
    c4 = wam_chain(4)
    return [c4, wam_chain(7), c4.with_payload(hand_body(CATCH3))]


@pytest.mark.parametrize("k", range(3))
def test_compiled_point_and_rnea_equal_the_float_reference(k):
    """Seeded random states: the same operations in the same order, so equal to a few ulps
    (1e-12 relative), and the NumPy batch recursion agrees too."""
    chain = _chains()[k]
    rng = np.random.default_rng(10 + k)
    n = chain.n
    worst_p = worst_t = 0.0
    for _ in range(200):
        q, qd, qdd = rng.uniform(-3, 3, n), rng.uniform(-10, 10, n), rng.uniform(-100, 100, n)
        pt = tuple(rng.uniform(-0.2, 0.2, 3))
        worst_p = max(worst_p, np.abs(chain.point(q, pt) - chain.point_floats(q, pt)).max())
        tau, ref = chain.rnea(q, qd, qdd), chain.rnea_floats(q, qd, qdd)
        worst_t = max(worst_t, np.abs(tau - ref).max() / max(1.0, np.abs(ref).max()))
        g = rng.uniform(-10, 10, 3)
        np.testing.assert_allclose(
            chain.rnea(q.tolist(), qd, qdd, gravity=g), chain.rnea_floats(q, qd, qdd, g), atol=1e-9
        )
    assert worst_p <= 1e-12
    assert worst_t <= 1e-12
    Q, QD, QDD = rng.uniform(-3, 3, (5, n)), rng.uniform(-5, 5, (5, n)), rng.uniform(-9, 9, (5, n))
    batch = chain.rnea_batch(Q, QD, QDD)
    for i in range(5):
        np.testing.assert_allclose(chain.rnea(Q[i], QD[i], QDD[i]), batch[i], atol=1e-9)


def test_compiled_path_rejects_a_wrong_joint_count():
    chain = wam_chain(4)
    with pytest.raises(ValueError, match="expected 4 joint values, got 3"):
        chain.rnea([0.0] * 3, [0.0] * 4, [0.0] * 4)
    with pytest.raises(ValueError, match="expected 4 joint values, got 5"):
        chain.point([0.0] * 5)
