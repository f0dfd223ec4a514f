"""The serial chain's one-configuration path in Python floats (SerialChain.point, rnea) against
the 4x4 matrix products (frames) and the NumPy batch recursion (rnea_batch), on seeded random
states, lists and arrays alike."""

from __future__ import annotations

import numpy as np
import pytest

from replay.robot.hand import CATCH3, hand_body
from replay.robot.wam import wam_chain
from tests.replay.robot.oracles import rnea_batch


def _chains():
    c4 = wam_chain(4)
    return [c4, wam_chain(7), c4.with_payload(hand_body(CATCH3))]


@pytest.mark.parametrize("k", range(3))
def test_point_and_rnea_equal_the_matrix_forms_and_the_batch(k):
    chain = _chains()[k]
    rng = np.random.default_rng(10 + k)
    n = chain.n
    for _ in range(100):
        q, qd, qdd = rng.uniform(-3, 3, n), rng.uniform(-10, 10, n), rng.uniform(-100, 100, n)
        pt = tuple(rng.uniform(-0.2, 0.2, 3))
        ref = (chain.frames(q)[-1] @ np.array([*pt, 1.0]))[:3]
        np.testing.assert_allclose(chain.point(q, pt), ref, atol=1e-12)
        assert chain.point_tuple(q.tolist(), pt) == tuple(chain.point(q, pt))
        g = rng.uniform(-10, 10, 3)
        batch = rnea_batch(chain, q[None], qd[None], qdd[None], gravity=g)[0]
        tau = chain.rnea(q.tolist(), qd, qdd, gravity=g)
        np.testing.assert_allclose(tau, batch, rtol=1e-9, atol=1e-9)
        assert chain.rnea_tuple(q, qd, qdd, g) == tuple(tau)


def test_a_wrong_joint_count_is_refused():
    chain = wam_chain(4)
    with pytest.raises(ValueError, match="expected 4 joint values, got 3"):
        chain.rnea([0.0] * 3, [0.0] * 4, [0.0] * 4)
    with pytest.raises(ValueError, match="expected 4 joint values, got 5"):
        chain.point([0.0] * 5)
    with pytest.raises(ValueError, match="expected 4 joint values"):
        chain.point(np.zeros((2, 4)))
