"""What a camera can see: simulator-free geometric primitives with world poses (SI units).

A plant describes its visible bodies with these; a camera renders them. Orientation is a unit
quaternion [qx, qy, qz, qw] (scalar last, as in the log contract and PyBullet).
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Box:
    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float, float]  # full extents along the body x, y, z axes (m)
    albedo: float = 0.5  # 0 black .. 1 white, as a camera sees it


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


@dataclass(frozen=True)
class Frame:
    """A moving body's or robot link's frame ``child`` in frame ``parent`` (for 3-D viewers:
    ``/tf``): translation (m) and rotation [qx, qy, qz, qw] of ``child`` in ``parent``."""

    parent: str
    child: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]


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
