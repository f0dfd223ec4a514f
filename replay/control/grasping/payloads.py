"""Log payloads of the grasping method's tasks (docs/DESIGN.md, "Grasping runs")."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated

from replay.messages import Length, OneOf, Pose6, Vec2, Vec3


@dataclass
class GraspObject:
    """``/grasping/object``: what the vision task recognised in the chip image captured at ``t``."""

    t: float
    found: bool
    xi: Annotated[list[float], Length(2, empty=True)]  # px [u, v]; [] when not found
    phi: float  # rad
    area: int  # px in the target
    window: int  # px in the Self Window
    position: Annotated[list[float], Length(3, empty=True)]  # m, on the constraint plane
    roll: float | None  # rad, long axis in the plane (None: no axis, e.g. a circle)
    x_o: Annotated[list[float], Length(6, empty=True)]  # [x, y, z, roll, pitch, yaw]
    size: Annotated[list[float], Length(2, empty=True)]  # m, [length, width] in the plane
    shape: Annotated[str, OneOf("rectangle", "circle", "unknown")]
    fill: float | None  # None once the shape is decided (not computed any more)
    elongation: float
    # 2x2 image Jacobian d xi / d (pan, tilt) (px/rad) at capture
    jacobian: Annotated[list[Vec2], Length(2, empty=True)]
    head: Vec2  # rad, (pan, tilt) at capture


@dataclass
class GraspState:
    """``/grasping/state``: the schedule (Fig. 9) and the reaching target x_d^a of eq. 2."""

    t: float
    phase: Annotated[str, OneOf("track", "reach", "hold", "release")]
    cycle: int
    x_d: Pose6  # [x, y, z, roll, pitch, yaw]; only (I - S) components are used
    reach_progress: float  # 0 (far) .. 1 (at the grasp position) along x_d
    grasp: bool  # grasping phase (reach, hold); else releasing (track, release)
    phase_time: float  # s into the phase


@dataclass
class HeadLoop:
    """``/grasping/head``: eq. 1."""

    t: float
    xi_error: Vec2  # px
    command: Vec2  # rad/s (pan, tilt)


@dataclass
class ArmLoop:
    """``/grasping/arm``: eq. 2 with the task partition of eq. 3."""

    t: float
    x_a: Pose6
    x_o: Annotated[list[float], Length(6, empty=True)]  # [] before the object is seen
    x_d: Pose6
    tracking_error: Vec3  # (y, z, roll) of x_o - x_a (m, m, rad)
    wrench: Annotated[list[float], Length(6)]  # external wrench on the hand, world (N, N m)
    terms: dict[str, list[float]]  # track, reach, damp, force: joint velocity terms (rad/s)
    command: list[float]  # rad/s


@dataclass
class HandLoop:
    """``/grasping/hand``: eq. 4 and the preshape."""

    t: float
    preshape: str
    closure: float  # 0 preshape .. 1 grip posture (theta_d^h)
    theta_d: list[float]
    load: list[float]  # F^h (N m): the joint torques' load
    command: list[float]  # rad/s
