"""Simulator-free descriptions of an arm plant: what a controller may know, and what it commands.

A plant hands an :class:`ArmSpec` to controllers (its nominal model, never simulator state); a
controller returns :class:`ArmCommand` values. SI units throughout (rad, rad/s, N*m, m, kg).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from replay.robot.hand import HandTable
from replay.robot.head import HeadSpec
from replay.robot.serial_chain import SerialChain


@dataclass(frozen=True, eq=False)
class HandSpec:
    name: str
    joint_names: tuple[str, ...]
    lower: np.ndarray  # rad
    upper: np.ndarray  # rad
    open_posture: np.ndarray  # rad
    closed_posture: np.ndarray  # rad
    closing_speed: float  # rad/s, each joint
    max_torque: float  # N*m, each joint
    mass: float  # kg, whole hand
    table: HandTable  # the geometry (palm, fingers)

    @property
    def n(self) -> int:
        return len(self.joint_names)


@dataclass(frozen=True)
class ObjectSpec:
    """The free object's nominal description (a method may know its shape and mass)."""

    kind: str  # "ball", "box" or "none"
    mass: float  # kg
    radius: float = 0.0  # m (ball)
    size: tuple[float, float, float] = (0.0, 0.0, 0.0)  # m, full extents (box)


@dataclass(frozen=True, eq=False)
class ArmSpec:
    name: str  # "wam4", "wam7"
    joint_names: tuple[str, ...]  # every arm joint, locked ones included
    lower: np.ndarray  # rad, joint limits
    upper: np.ndarray
    torque_limits: np.ndarray  # N*m, symmetric |tau_i| <= limit_i
    velocity_limits: np.ndarray  # rad/s, symmetric |qd_i| <= limit_i
    locked_joints: tuple[str, ...]  # held fixed by the plant at ``initial_q``
    initial_q: np.ndarray  # rad
    model: SerialChain  # nominal dynamics, hand (open) as payload
    tool: np.ndarray  # 4x4, tool frame in the last DH frame
    hand: HandSpec | None = None
    object: ObjectSpec | None = None
    gravity: float = 9.81  # m/s^2 along world -z
    dt: float = 0.001  # s, the plant's physics step
    notes: dict = field(default_factory=dict)  # why the limits are what they are

    @property
    def n(self) -> int:
        return len(self.joint_names)

    @property
    def active(self) -> tuple[int, ...]:
        """Indices of the joints that move (not locked)."""
        return tuple(i for i, n in enumerate(self.joint_names) if n not in self.locked_joints)

    def index(self, name: str) -> int:
        return self.joint_names.index(name)


@dataclass
class ArmCommand:
    """Joint torques for every arm joint (entries of locked joints are ignored) and, optionally,
    position targets for the hand joints (None keeps the previous targets). The plant moves the
    hand joints towards their targets no faster than the hand's closing speed."""

    torque: Sequence[float]
    hand: Sequence[float] | None = None


@dataclass(frozen=True)
class PlaneSpec:
    """A constraint plane given beforehand (Namiki et al. 1999, Sec. 4.1.1): a point and a unit
    normal (world). The object moves on it."""

    point: tuple[float, float, float]
    normal: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class GraspSpec(ArmSpec):
    """An :class:`ArmSpec` with the active-vision head and the constraint plane (grasping)."""

    head: HeadSpec | None = None
    plane: PlaneSpec | None = None


@dataclass
class ServoCommand:
    """Velocity commands to velocity-controlled servos (rad/s): the arm's (eq. 2's theta_d^a,
    every arm joint), the hand's (eq. 4's theta_d^h) and the head's (eq. 1's theta_d^v). A field
    left None keeps that servo's previous command, so several tasks can each command their own
    actuators."""

    arm: Sequence[float] | np.ndarray | None = None
    hand: Sequence[float] | np.ndarray | None = None
    head: Sequence[float] | np.ndarray | None = None
