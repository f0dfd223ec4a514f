"""Force sensing of the grasping rig: the wrist's 6-axis F/T sensor and the hand's joint-torque
strain gauges (Namiki et al. 1999, Sec. 3.3), from the plant's readings, with Gaussian noise
from the scenario.

- ``wrist_ft`` -> ``/wrist/wrench``: force (N) and torque (N m) the hand side exerts on the
  flange, in the palm (= tool) frame (``Scene.readings["wrist"]["wrench"]``).
- ``hand_torque`` -> ``/hand/joint_torque``: each hand joint's actuator torque (N m, positive
  along +q), what a strain gauge on its drive reads (``Scene.readings["hand_torque"]``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from replay.messages import TOPIC_HAND_TORQUE, TOPIC_WRIST_WRENCH, Vec3
from replay.interfaces import Sensor
from replay.params import param
from replay.scene import Scene


@dataclass
class WristWrench:
    t: float
    force: Vec3  # N, palm frame
    torque: Vec3  # N m, palm frame, about the flange-palm joint's origin


@dataclass
class JointTorque:
    t: float
    name: list[str]
    torque: list[float]  # N m


@dataclass
class WristFTParams:
    force_noise: float = param(0.0, unit="N", ge=0.0, doc="standard deviation per force axis")
    torque_noise: float = param(0.0, unit="N*m", ge=0.0, doc="standard deviation per torque axis")


class WristFTSensor(Sensor):
    """The wrist's 6-axis force/torque sensor: ``/wrist/wrench``."""

    Params = WristFTParams
    topic = TOPIC_WRIST_WRENCH
    spec_type = None
    description = "6-axis force/torque sensor between flange and palm (palm frame)"

    def __init__(self, params: WristFTParams, *, rng: np.random.Generator, spec=None) -> None:
        super().__init__(params, rng=rng, spec=spec)
        self._sigma = np.repeat([params.force_noise, params.torque_noise], 3)
        self._noisy = params.force_noise > 0.0 or params.torque_noise > 0.0

    def measure(self, t: float, scene: Scene) -> WristWrench | None:
        r = scene.readings.get("wrist")
        if r is None:
            return None
        if self._noisy:
            v = (
                np.asarray(r["wrench"], dtype=float) + self._sigma * self.rng.standard_normal(6)
            ).tolist()
        else:  # exact: the reading's floats as they are (no array round trip)
            v = [float(x) for x in r["wrench"]]
        return WristWrench(t, v[:3], v[3:])


@dataclass
class HandTorqueParams:
    noise: float = param(0.0, unit="N*m", ge=0.0, doc="standard deviation per joint")


class HandTorqueSensor(Sensor):
    """The hand joints' strain gauges: ``/hand/joint_torque``."""

    Params = HandTorqueParams
    topic = TOPIC_HAND_TORQUE
    spec_type = None
    description = "strain gauge torque of every hand joint (F^h of eq. 4)"

    def measure(self, t: float, scene: Scene) -> JointTorque | None:
        r = scene.readings.get("hand_torque")
        if r is None:
            return None
        tau = np.array(r["torque"], dtype=float)
        if self.params.noise > 0.0:
            tau += self.params.noise * self.rng.standard_normal(tau.shape)
        return JointTorque(t, list(r["name"]), tau.tolist())
