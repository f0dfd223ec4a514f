"""Extra log payloads of the arm plant (topics beyond the contract, none renamed)."""

from __future__ import annotations

from dataclasses import dataclass

from replay.messages import Quat, Vec2, Vec3


@dataclass
class AppliedTorque:
    """``/arm/applied_torque``: what the controller asked and what the motors gave (N*m)."""

    t: float
    name: list[str]
    commanded: list[float | None]  # None: a non-finite command (no torque applied)
    applied: list[float]
    clamped: list[bool]  # bool per joint: the command was cut to the torque/velocity limit


@dataclass
class EffectorMotion:
    """``/effector/motion``: the tool frame's pose and twist (world, m, m/s, rad/s)."""

    t: float
    position: Vec3
    orientation: Quat
    velocity: Vec3
    angular_velocity: Vec3
    speed: float


@dataclass
class ObjectContacts:
    """``/object/contacts``: which robot parts touch the free object now."""

    t: float
    parts: list[str]  # "palm", finger names, "arm"
    links: list[str]
    normal_force: float  # N, sum over contact points


@dataclass
class ServoState:
    """``/arm/servo``: the velocity servos' command (rad/s), integral of the velocity error (rad)
    and torque (N*m)."""

    t: float
    name: list[str]
    command: list[float]
    integral: list[float]
    torque: list[float]
    saturated: list[bool]  # bool per joint: the motor gave its torque limit


@dataclass
class HeadState:
    """``/head/state``: pan/tilt (rad), their rates, and the camera's pose (world)."""

    t: float
    pan: float
    tilt: float
    velocity: Vec2  # (pan, tilt) rates
    camera_position: Vec3
    camera_orientation: Quat  # [qx, qy, qz, qw], camera-to-world (x right, y down, z forward)


@dataclass
class HumanState:
    """``/human/state``: where the human's hand pulls the object, and with what force."""

    t: float
    target: Vec3  # m, world
    roll: float  # rad, about the plane normal, from the start pose
    force: Vec3  # N, world: the hand's force on the object (its spring-damper and weight)
    max_force: float  # N


@dataclass
class HumanWrench:
    """``/human/wrench``: the human hand's coupling to the object (world): the force and torque
    it applies, the offset of the object from the hand's path, and whether a limit cut it."""

    t: float
    force: Vec3  # N
    torque: Vec3  # N*m
    offset: Vec3  # m: object centre - the path's point
    limited: bool


@dataclass
class Wrench:
    """``/wrist/wrench`` and ``/wrist/wrench_truth``: force (N) and torque (N*m), palm frame."""

    t: float
    force: Vec3
    torque: Vec3
