"""Log payloads of the grasping method's tasks (docs/DESIGN.md, "Grasping runs")."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class GraspObject:
    """``/grasping/object``: what the vision task recognised in the chip image captured at ``t``."""

    t: float
    found: bool
    xi: list  # px [u, v]
    phi: float  # rad
    area: int  # px in the target
    window: int  # px in the Self Window
    position: list  # m, on the constraint plane
    roll: float | None  # rad, long axis in the plane (None: no axis, e.g. a circle)
    x_o: list  # [x, y, z, roll, pitch, yaw]
    size: list  # m, [length, width] in the plane
    shape: str  # rectangle | circle | unknown
    fill: float | None  # None once the shape is decided (not computed any more)
    elongation: float
    jacobian: list  # 2x2 image Jacobian d xi / d (pan, tilt) (px/rad) at capture
    head: list  # rad, (pan, tilt) at capture


@dataclass
class GraspState:
    """``/grasping/state``: the schedule (Fig. 9) and the reaching target x_d^a of eq. 2."""

    t: float
    phase: str  # track | reach | hold | release
    cycle: int
    x_d: list  # [x, y, z, roll, pitch, yaw]; only (I - S) components are used
    reach_progress: float  # 0 (far) .. 1 (at the grasp position) along x_d
    grasp: bool  # grasping phase (reach, hold); else releasing (track, release)
    phase_time: float  # s into the phase


@dataclass
class HeadLoop:
    """``/grasping/head``: eq. 1."""

    t: float
    xi_error: list  # px
    command: list  # rad/s


@dataclass
class ArmLoop:
    """``/grasping/arm``: eq. 2 with the task partition of eq. 3."""

    t: float
    x_a: list
    x_o: list
    x_d: list
    tracking_error: list  # (y, z, roll) of x_o - x_a (m, m, rad)
    wrench: list  # external wrench on the hand, world (N, N m)
    terms: dict  # track, reach, damp, force: joint velocity terms (rad/s)
    command: list  # rad/s


@dataclass
class HandLoop:
    """``/grasping/hand``: eq. 4 and the preshape."""

    t: float
    preshape: str
    closure: float  # 0 preshape .. 1 grip posture (theta_d^h)
    theta_d: list
    load: list  # F^h (N m): the joint torques' load
    command: list  # rad/s
