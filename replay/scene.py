"""What a camera can see: simulator-free geometric primitives with world poses (SI units).

A plant describes its visible bodies with these; a camera renders them. Orientation is a unit
quaternion [qx, qy, qz, qw] (scalar last, as in the log contract and PyBullet).
"""

from __future__ import annotations

from dataclasses import dataclass, field


# Box, Sphere, Cylinder and Frame store their fields straight into the instance's dict: a frozen
# dataclass's generated __init__ sets each through object.__setattr__ (~1 us a field on Python
# 3.11; the air table makes ~800 primitives a simulated second, the catching arm a Sphere a step
# and ~1000 link Frames); tests/replay/test_scene_inits.py holds them to the generated signature
# and result.
@dataclass(frozen=True, init=False)
class Box:
    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    size: tuple[float, float, float]  # full extents along the body x, y, z axes (m)
    albedo: float = 0.5  # 0 black .. 1 white, as a camera sees it

    def __init__(self, name: str, position, orientation, size, albedo: float = 0.5) -> None:
        d = self.__dict__
        d["name"], d["position"], d["orientation"] = name, position, orientation
        d["size"], d["albedo"] = size, albedo


@dataclass(frozen=True, init=False)
class Sphere:
    name: str
    position: tuple[float, float, float]
    radius: float
    albedo: float = 0.5

    def __init__(self, name: str, position, radius: float, albedo: float = 0.5) -> None:
        d = self.__dict__
        d["name"], d["position"], d["radius"], d["albedo"] = name, position, radius, albedo


@dataclass(frozen=True, init=False)
class Cylinder:
    name: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    radius: float
    length: float
    albedo: float = 0.5

    def __init__(
        self, name: str, position, orientation, radius: float, length: float, albedo: float = 0.5
    ) -> None:
        d = self.__dict__
        d["name"], d["position"], d["orientation"] = name, position, orientation
        d["radius"], d["length"], d["albedo"] = radius, length, albedo


Primitive = Box | Sphere | Cylinder


@dataclass(frozen=True, init=False)
class Frame:
    """A moving body's or robot link's frame ``child`` in frame ``parent`` (for 3-D viewers:
    ``/tf``): translation (m) and rotation [qx, qy, qz, qw] of ``child`` in ``parent``."""

    parent: str
    child: str
    position: tuple[float, float, float]
    orientation: tuple[float, float, float, float]

    def __init__(self, parent: str, child: str, position, orientation) -> None:
        d = self.__dict__
        d["parent"], d["child"], d["position"], d["orientation"] = (
            parent,
            child,
            position,
            orientation,
        )


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
