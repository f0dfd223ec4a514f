"""Extra log payloads of the arm plant (topics beyond the contract, none renamed)."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class AppliedTorque:
    """``/arm/applied_torque``: what the controller asked and what the motors gave (N*m)."""

    t: float
    name: list
    commanded: list
    applied: list
    clamped: list  # bool per joint: the command was cut to the torque/velocity limit


@dataclass
class EffectorMotion:
    """``/effector/motion``: the tool frame's pose and twist (world, m, m/s, rad/s)."""

    t: float
    position: list
    orientation: list  # [qx, qy, qz, qw]
    velocity: list
    angular_velocity: list
    speed: float


@dataclass
class ObjectContacts:
    """``/object/contacts``: which robot parts touch the free object now."""

    t: float
    parts: list  # "palm", finger names, "arm"
    links: list
    normal_force: float  # N, sum over contact points


@dataclass
class ServoState:
    """``/arm/servo``: the velocity servos' command (rad/s), integral of the velocity error (rad)
    and torque (N*m)."""

    t: float
    name: list
    command: list
    integral: list
    torque: list
    saturated: list  # bool per joint: the motor gave its torque limit


@dataclass
class HeadState:
    """``/head/state``: pan/tilt (rad), their rates, and the camera's pose (world)."""

    t: float
    pan: float
    tilt: float
    velocity: list
    camera_position: list
    camera_orientation: list  # [qx, qy, qz, qw], camera-to-world (x right, y down, z forward)


@dataclass
class HumanState:
    """``/human/state``: where the human's hand pulls the object, and with what force."""

    t: float
    target: list  # m, world
    roll: float  # rad, about the plane normal, from the start pose
    force: list  # N, the constraint's force on the object
    max_force: float  # N


@dataclass
class Wrench:
    """``/wrist/wrench`` and ``/wrist/wrench_truth``: force (N) and torque (N*m), palm frame."""

    t: float
    force: list
    torque: list
