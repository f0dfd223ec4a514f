"""Joint encoders: the robot's own reading of its joint angles, as a sensor.

The plant puts its joint readings in ``Scene.readings`` (reading name -> name/position/velocity);
this sensor publishes them, quantised to the encoder's resolution, on its topic (default
``/arm/encoders``), so a controller sees joint angles only through a sensor, like any other
measurement.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replay.interfaces import Sensor
from replay.messages import TOPIC_ARM_ENCODERS, JointState
from replay.params import param
from replay.scene import Scene


@dataclass
class EncoderParams:
    reading: str = param(
        "arm", max_length=100, doc="which of the plant's readings (Scene.readings) to publish"
    )
    topic: str = param(
        TOPIC_ARM_ENCODERS, pattern=r"/[A-Za-z0-9_/]{1,99}", doc="log topic of the measurement"
    )
    resolution: float = param(
        0.0, unit="rad", ge=0, le=10, doc="angle per encoder count; 0 = exact"
    )


class JointEncoders(Sensor):
    """Joint encoders: the plant's joint readings, quantised, on ``/arm/encoders``."""

    Params = EncoderParams
    topic = TOPIC_ARM_ENCODERS

    def __init__(self, params: EncoderParams, *, rng: np.random.Generator, spec=None) -> None:
        super().__init__(params, rng=rng, spec=spec)
        self.topic = params.topic

    def measure(self, t: float, scene: Scene) -> JointState | None:
        r = scene.readings.get(self.params.reading)
        if r is None:
            return None
        res = self.params.resolution
        if res > 0.0:
            q = (np.round(np.asarray(r["position"], dtype=float) / res) * res).tolist()
        else:  # exact: the reading's floats as they are (no array round trip)
            q = [float(x) for x in r["position"]]
        return JointState(t, list(r["name"]), q, list(r["velocity"]), [0.0] * len(q))
