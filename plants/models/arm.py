"""URDF of a WAM (4 or 7 axes) with an optional hand, built from the parameter tables.

Our own model from ``data/robots/wam.yaml`` (DH, masses, centres of mass, inertias) and a
:class:`replay.robot.hand.HandTable`; no vendor meshes: links are drawn as cylinders/spheres,
the palm and finger links as cylinders/boxes (these are also the collision shapes).

Frames. URDF link i (child of joint Ji) is DH frame i-1 turned by q_i about its z axis; DH frame
i is then ``C_i = Tz(d_i) Tx(a_i) Rx(alpha_i)`` in link i, so joint J(i+1)'s origin is C_i and
link i's inertia (given in DH frame i, about the centre of mass) is rotated into link i by C_i.
The tool frame is a zero-mass link ``wam_tool`` (README: a dummy mass biases gravity torques);
the palm is a link rigidly on it (palm frame = tool frame). A locked arm joint becomes a fixed
joint at its locked angle, so it cannot drift.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from plants.models.urdf import Geometry, Joint, Link, robot_xml, segment_cylinder, write_cached
from replay.robot.hand import HandTable, joint_axis, link_body, palm_body, root_transform
from replay.spatial import rot_x, rot_z, transform
from replay.robot.wam import (
    DEFAULT_VELOCITY_LIMIT,
    default_tool_d,
    load_wam_table,
    wam_dh,
    wam_joint_limits,
    wam_joint_names,
    wam_links,
    wam_torque_limits,
)

# cosmetic/collision radii of the arm links (m), assumed from the WAM's look (no table source)
_LINK_RADIUS = {1: 0.085, 2: 0.075, 3: 0.045, 4: 0.038, 5: 0.035, 6: 0.035, 7: 0.035}
_ARM_RGBA = (0.82, 0.82, 0.85, 1.0)
_HAND_RGBA = (0.25, 0.25, 0.28, 1.0)


@dataclass(frozen=True)
class ArmModel:
    """A generated URDF and the names a plant needs to find things in it."""

    urdf: str
    robot_name: str
    arm_joints: tuple[str, ...]  # every arm joint (locked ones are fixed joints)
    locked: dict = field(default_factory=dict)  # joint name -> locked angle (rad)
    arm_links: tuple[str, ...] = ()  # link moved by each arm joint
    tool_link: str = "wam_tool"
    palm_link: str | None = None
    hand_joints: tuple[str, ...] = ()
    hand_links: tuple[str, ...] = ()
    part_of_link: dict = field(default_factory=dict)  # link -> "palm" / finger name / "arm"

    def write(self, directory=None):
        """Write the URDF to the model cache (deterministic path) and return the path."""
        return write_cached(self.urdf, self.robot_name, directory)


def _dh_const(row) -> np.ndarray:
    return transform(rot_x(row.alpha), (row.a, 0.0, row.d))


def build_arm(
    dof: int = 4,
    *,
    tool_d: float | None = None,
    hand: HandTable | None = None,
    locked: Mapping[str, float] | None = None,
    torque_limits: Sequence[float] | np.ndarray | None = None,
    velocity_limits: Sequence[float] | np.ndarray | None = None,
    table: dict | None = None,
) -> ArmModel:
    """Build the URDF text of a ``dof``-axis WAM (+ ``hand``), see the module docstring."""
    t = table or load_wam_table()
    dh = wam_dh(dof, t)
    bodies = wam_links(dof, t)
    names = wam_joint_names(dof, t)
    lower, upper = wam_joint_limits(dof, t)
    tau = np.asarray(torque_limits if torque_limits is not None else wam_torque_limits(dof), float)
    vel = np.asarray(
        velocity_limits if velocity_limits is not None else [DEFAULT_VELOCITY_LIMIT] * dof, float
    )
    locked = dict(locked or {})
    for n in locked:
        if n not in names:
            raise ValueError(f"cannot lock {n!r}: joints are {names}")
    d_tool = default_tool_d(dof, t) if tool_d is None else float(tool_d)
    tool = transform(translation=(0.0, 0.0, d_tool))
    suffix = "".join(f"-lock{n}" for n in sorted(locked))
    robot = f"wam{dof}" + (f"-{hand.name}" if hand else "") + suffix

    links: list[Link] = []
    joints: list[Joint] = []
    # the base plate and the column up to the shoulder (frame 0 at base_height)
    h = float(t["base_height"])
    base_geo = [
        Geometry(
            "box",
            (0.20, 0.20, 0.02),
            transform(translation=(0.0, 0.0, 0.01)),
            _ARM_RGBA,
            "wam_grey",
        )
    ]
    col = segment_cylinder(
        (0.0, 0.0, 0.02), (0.0, 0.0, h - 0.1), 0.06, rgba=_ARM_RGBA, material="wam_grey"
    )
    if col is not None:  # None only if the column has no length
        base_geo.append(col)
    links.append(Link("wam_base", None, base_geo))
    arm_links = []
    parent, origin = "wam_base", transform(translation=(0.0, 0.0, h))
    for i, (row, body, name) in enumerate(zip(dh, bodies, names)):
        C = _dh_const(row)
        link_name = f"wam_link{i + 1}"
        r = _LINK_RADIUS.get(i + 1, 0.035)
        geo = []
        pts = [np.zeros(3), np.array([0.0, 0.0, row.d]), np.array([row.a, 0.0, row.d])]
        if i == dof - 1:
            pts.append((C @ tool)[:3, 3])
        for p0, p1 in zip(pts[:-1], pts[1:]):
            g = segment_cylinder(p0, p1, r, rgba=_ARM_RGBA, material="wam_grey")
            if g is not None:
                geo.append(g)
        if not geo or i in (0, 1):  # the shoulder housings and the wrist: a ball at the joint
            geo.append(Geometry("sphere", (r,), transform(), _ARM_RGBA, "wam_grey"))
        links.append(Link(link_name, body.transformed(C), geo))
        if name in locked:
            joints.append(
                Joint(
                    name, "fixed", parent, link_name, origin @ transform(rot_z(float(locked[name])))
                )
            )
        else:
            joints.append(
                Joint(
                    name,
                    "revolute",
                    parent,
                    link_name,
                    origin,
                    (0.0, 0.0, 1.0),
                    float(lower[i]),
                    float(upper[i]),
                    float(tau[i]),
                    float(vel[i]),
                )
            )
        arm_links.append(link_name)
        parent, origin = link_name, C
    links.append(Link("wam_tool", None, []))
    joints.append(Joint("wam_tool_joint", "fixed", parent, "wam_tool", origin @ tool))
    part = {n: "arm" for n in arm_links}
    hand_joints: list[str] = []
    hand_links: list[str] = []
    palm = None
    if hand is not None:
        palm = "palm"
        sx, sy, sz = hand.palm_size
        if hand.palm_shape == "cylinder":
            pg = Geometry(
                "cylinder",
                (sx, sz),
                transform(translation=(0.0, 0.0, sz / 2.0)),
                _HAND_RGBA,
                "hand_dark",
            )
        else:
            pg = Geometry(
                "box",
                (sx, sy, sz),
                transform(translation=(0.0, 0.0, sz / 2.0)),
                _HAND_RGBA,
                "hand_dark",
            )
        links.append(Link(palm, palm_body(hand), [pg]))
        joints.append(Joint("palm_joint", "fixed", "wam_tool", palm, transform()))
        part[palm] = "palm"
        for f in hand.fingers:
            fparent, forigin = palm, root_transform(f)
            for j in f.joints:
                lname = f"{j.name}_link"
                geo = []
                if j.length > 0.0:
                    geo.append(
                        Geometry(
                            "box",
                            (j.width, j.width, j.length),
                            transform(translation=(0.0, 0.0, j.length / 2.0)),
                            _HAND_RGBA,
                            "hand_dark",
                        )
                    )
                links.append(Link(lname, link_body(j), geo))
                joints.append(
                    Joint(
                        j.name,
                        "revolute",
                        fparent,
                        lname,
                        forigin,
                        joint_axis(j.kind),
                        j.lower,
                        j.upper,
                        hand.max_torque,
                        hand.closing_speed,
                    )
                )
                hand_joints.append(j.name)
                hand_links.append(lname)
                part[lname] = f.name
                fparent, forigin = lname, transform(translation=(0.0, 0.0, j.length))
    comment = (
        f"{robot}: generated by paper-replay plants.models.arm from data/robots/wam.yaml "
        f"(WAM manual D1001 DH; libbarrett inertial specifications Sept 2008)"
        + (f" and hand table {hand.name}" if hand else "")
    )
    return ArmModel(
        urdf=robot_xml(robot, links, joints, comment),
        robot_name=robot,
        arm_joints=tuple(names),
        locked=locked,
        arm_links=tuple(arm_links),
        palm_link=palm,
        hand_joints=tuple(hand_joints),
        hand_links=tuple(hand_links),
        part_of_link=part,
    )
