"""The grasping rig's engine-free set-up from its ``GraspParams``: the pan/tilt head's spec and
initial angles, the constraint plane and its axes, the human hand's path arguments: the grasping
rig (grasp_rig.py ``GraspRig``) builds the same head, plane and human from a scenario in every
engine."""

from __future__ import annotations

import numpy as np

from replay.robot.arm_types import PlaneSpec
from replay.robot.head import HeadSpec, look_angles


def head_setup(P) -> tuple[HeadSpec, list[float]]:
    """The head's spec and its initial (pan, tilt): ``head_initial``, else looking at the
    object's centre."""
    head = HeadSpec(
        position=tuple(P.head_position),
        yaw=float(P.head_yaw),
        camera_offset=float(P.head_camera_offset),
        lower=tuple(P.head_lower),
        upper=tuple(P.head_upper),
        inertia=tuple(P.head_inertia),
        torque_limit=tuple(P.head_torque_limit),
        velocity_limit=tuple(P.head_velocity_limit),
    )
    h0 = list(P.head_initial) if P.head_initial else list(look_angles(head, P.object_position))
    if len(h0) != 2:
        raise ValueError("head_initial needs 2 values (pan, tilt)")
    return head, h0


def plane_setup(P) -> tuple[PlaneSpec, np.ndarray, np.ndarray, np.ndarray]:
    """The constraint plane through the object's initial centre, and its axes (u, v in it, n its
    unit normal; u horizontal unless the plane is)."""
    n = np.asarray(P.plane_normal, float)
    if np.linalg.norm(n) == 0.0:
        raise ValueError("plane_normal must not be zero")
    n = n / np.linalg.norm(n)
    u = np.cross([0.0, 0.0, 1.0], n)
    if np.linalg.norm(u) < 1e-9:
        u = np.array([0.0, 1.0, 0.0])
    u = u / np.linalg.norm(u)
    v = np.cross(n, u)
    op = [float(x) for x in P.object_position]
    plane = PlaneSpec(point=(op[0], op[1], op[2]), normal=(float(n[0]), float(n[1]), float(n[2])))
    return plane, u, v, n


def human_args(P, u, v, n) -> dict:
    """``human_path.HumanPath``'s keyword arguments (after its rng) from the scenario."""
    return dict(
        origin=P.object_position,
        rpy0=P.object_rpy,
        u=u,
        v=v,
        n=n,
        speed=P.human_speed,
        roll_rate=P.human_roll_rate,
        f_min=P.human_f_min,
        f_max=P.human_f_max,
        components=P.human_components,
        max_force=P.human_max_force,
        start=P.human_start,
        mass=P.object_mass,
        gravity=P.gravity,
        stiffness=P.human_stiffness,
        damping=P.human_damping,
        rot_stiffness=P.human_rot_stiffness,
        rot_damping=P.human_rot_damping,
        max_torque=P.human_max_torque,
        kick_rate=P.human_kick_rate,
        kick_speed=P.human_kick_speed,
        kick_duration=P.human_kick_duration,
    )
