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
    clamped: list        # bool per joint: the command was cut to the torque/velocity limit


@dataclass
class EffectorMotion:
    """``/effector/motion``: the tool frame's pose and twist (world, m, m/s, rad/s)."""
    t: float
    position: list
    orientation: list    # [qx, qy, qz, qw]
    velocity: list
    angular_velocity: list
    speed: float


@dataclass
class ObjectContacts:
    """``/object/contacts``: which robot parts touch the free object now."""
    t: float
    parts: list          # "palm", finger names, "arm"
    links: list
    normal_force: float  # N, sum over contact points
