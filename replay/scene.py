"""What a camera can see: simulator-free geometric primitives with world poses (SI units).

A plant describes its visible bodies with these; a camera renders them. Orientation is a unit
quaternion [qx, qy, qz, qw] (scalar last, as in the log contract and PyBullet).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Box:
    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float, float]          # full extents along the body x, y, z axes (m)
    albedo: float = 0.5                        # 0 black .. 1 white, as a camera sees it


@dataclass(frozen=True)
class Sphere:
    name: str
    position: tuple[float, float, float]
    radius: float
    albedo: float = 0.5


@dataclass(frozen=True)
class Cylinder:
    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    radius: float
    length: float
    albedo: float = 0.5


Primitive = Box | Sphere | Cylinder


@dataclass
class Scene:
    """What sensors can measure at one instant: the visible primitives, by name, and the
    robot's own readings (e.g. joint encoders: reading name -> payload)."""
    primitives: list = field(default_factory=list)
    readings: dict = field(default_factory=dict)

    def get(self, name: str):
        for p in self.primitives:
            if p.name == name:
                return p
        raise KeyError(name)


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Rotation about +z by ``yaw`` rad as [qx, qy, qz, qw]."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def quaternion_yaw(q) -> float:
    """Yaw (rad) of a rotation that is about +z only."""
    qx, qy, qz, qw = q
    return math.atan2(2.0 * (qw * qz + qx * qy), 1.0 - 2.0 * (qy * qy + qz * qz))


def quaternion_matrix(q) -> np.ndarray:
    """Rotation matrix of a quaternion [qx, qy, qz, qw] (normalised here)."""
    x, y, z, w = (float(v) for v in q)
    n = x * x + y * y + z * z + w * w
    if n == 0.0:
        raise ValueError("zero quaternion")
    s = 2.0 / n
    return np.array([
        [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
        [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
        [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
    ])


def wrap_half_pi(angle: float) -> float:
    """An axis angle (known modulo pi, as a symmetric marker shows it) in (-pi/2, pi/2]."""
    a = math.fmod(angle, math.pi)
    if a <= -math.pi / 2.0:
        a += math.pi
    elif a > math.pi / 2.0:
        a -= math.pi
    return a
