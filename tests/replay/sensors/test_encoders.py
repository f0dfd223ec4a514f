"""Joint encoders publish the plant's readings, quantised to their resolution."""

import numpy as np

from replay.sensors.encoders import EncoderParams, JointEncoders
from replay.scene import Scene


def test_encoders_quantise_and_name():
    scene = Scene(
        [],
        readings={
            "arm": {"name": ["J1", "J2"], "position": [0.1234, -1.0], "velocity": [0.5, 0.0]}
        },
    )
    exact = JointEncoders(EncoderParams(), rng=np.random.default_rng(0)).measure(0.25, scene)
    assert exact.t == 0.25 and exact.name == ["J1", "J2"] and exact.position == [0.1234, -1.0]
    res = 2 * np.pi / 4096
    coarse = JointEncoders(EncoderParams(resolution=res), rng=np.random.default_rng(0))
    m = coarse.measure(0.25, scene)
    assert m.position[0] != 0.1234 and abs(m.position[0] - 0.1234) <= res / 2
    assert abs(m.position[0] / res - round(m.position[0] / res)) < 1e-9


def test_missing_reading_is_none():
    assert JointEncoders(EncoderParams(), rng=np.random.default_rng(0)).measure(0, Scene()) is None
