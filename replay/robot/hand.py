"""Multi-fingered hands as parameter tables, with their kinematics and mass properties. Pure NumPy.

A hand is a palm plus fingers; every finger is a chain of revolute joints, one link per joint.
Frames:

- The **palm frame** is the arm's tool frame: z is the palm's normal (pointing away from the
  arm), the palm is a box or disc whose back face lies at z = 0 and whose front (contact) face
  at z = ``palm_thickness``.
- Each finger's **root frame** sits at ``root`` (palm frame, usually on the front face) turned
  by ``yaw`` about the palm normal, so that its x axis points to where the finger closes
  (towards the palm centre / the opposing finger) and its z axis along the palm normal.
- A ``flex`` joint rotates about the current y axis (positive = tip towards +x, i.e. closing);
  an ``abduct`` joint rotates about the current x axis (spreading sideways). Each joint's link
  extends ``length`` along its z axis; the next joint sits at its end.

The tables ``CATCH3`` and ``GRASP4`` carry assumed dimensions: neither paper gives them (see
each table's comment). Add a hand by adding a table.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.robot.serial_chain import RigidBody
from replay.spatial import rot_x, rot_y, rot_z, transform


@dataclass(frozen=True)
class HandJoint:
    name: str
    kind: str  # "flex" (about y) or "abduct" (about x)
    length: float  # m, link length along the link's z axis
    width: float  # m, square cross-section of the link's box
    mass: float  # kg, of the link (a uniform box)
    lower: float  # rad
    upper: float  # rad
    open: float = 0.0  # rad, the "open" posture
    closed: float = 0.0  # rad, the "closed" posture


@dataclass(frozen=True)
class Finger:
    name: str
    root: tuple[float, float, float]  # m, in the palm frame
    yaw: float  # rad, root frame about the palm normal
    joints: tuple[HandJoint, ...]


@dataclass(frozen=True)
class HandTable:
    name: str
    palm_shape: str  # "cylinder" (size = (radius, radius, thickness)) or "box"
    palm_size: tuple[float, float, float]  # m: box full extents x, y, z; cylinder (r, r, z)
    palm_mass: float  # kg, uniform solid
    fingers: tuple[Finger, ...]
    closing_speed: float  # rad/s, the joints' speed limit
    max_torque: float  # N*m, each joint's actuator limit
    note: str = ""

    @property
    def palm_thickness(self) -> float:
        return self.palm_size[2]

    @property
    def joints(self) -> tuple[HandJoint, ...]:
        return tuple(j for f in self.fingers for j in f.joints)

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.joints)

    @property
    def open_posture(self) -> np.ndarray:
        return np.array([j.open for j in self.joints])

    @property
    def closed_posture(self) -> np.ndarray:
        return np.array([j.closed for j in self.joints])


def joint_rotation(kind: str, angle: float) -> np.ndarray:
    if kind == "flex":
        return rot_y(angle)
    if kind == "abduct":
        return rot_x(angle)
    raise ValueError(f"unknown hand joint kind {kind!r} (flex or abduct)")


def joint_axis(kind: str) -> tuple[float, float, float]:
    return (0.0, 1.0, 0.0) if kind == "flex" else (1.0, 0.0, 0.0)


def root_transform(finger: Finger) -> np.ndarray:
    """Pose of a finger's root frame in the palm frame."""
    return transform(rot_z(finger.yaw), finger.root)


def box_inertia(mass: float, size) -> np.ndarray:
    x, y, z = size
    return mass / 12.0 * np.diag([y * y + z * z, x * x + z * z, x * x + y * y])


def cylinder_inertia(mass: float, radius: float, length: float) -> np.ndarray:
    """Solid cylinder along z."""
    ixx = mass * (3.0 * radius * radius + length * length) / 12.0
    return np.diag([ixx, ixx, 0.5 * mass * radius * radius])


def palm_body(hand: HandTable) -> RigidBody:
    """The palm's mass properties in the palm frame."""
    sx, sy, sz = hand.palm_size
    com = np.array([0.0, 0.0, sz / 2.0])
    if hand.palm_shape == "cylinder":
        return RigidBody(hand.palm_mass, com, cylinder_inertia(hand.palm_mass, sx, sz))
    return RigidBody(hand.palm_mass, com, box_inertia(hand.palm_mass, hand.palm_size))


def link_body(j: HandJoint) -> RigidBody:
    """A finger link's mass properties in its joint frame (a uniform box along z)."""
    if j.length <= 0.0:  # a knuckle without length: a small cube
        w = j.width
        return RigidBody(j.mass, np.zeros(3), box_inertia(j.mass, (w, w, w)))
    return RigidBody(
        j.mass,
        np.array([0.0, 0.0, j.length / 2.0]),
        box_inertia(j.mass, (j.width, j.width, j.length)),
    )


def finger_frames(finger: Finger, q) -> list[np.ndarray]:
    """Joint frames of a finger in the palm frame (after each joint's rotation), then the tip."""
    T = root_transform(finger)
    out = []
    for j, qi in zip(finger.joints, q):
        T = T @ transform(joint_rotation(j.kind, qi))
        out.append(T)
        T = T @ transform(translation=(0.0, 0.0, j.length))
    out.append(T)
    return out


def hand_body(hand: HandTable, q=None) -> RigidBody:
    """The whole hand's mass properties in the palm (= tool) frame at posture ``q`` (default
    open): what an arm model carries as its payload."""
    q = hand.open_posture if q is None else np.asarray(q, dtype=float)
    body = palm_body(hand)
    k = 0
    for f in hand.fingers:
        n = len(f.joints)
        frames = finger_frames(f, q[k : k + n])
        for j, T in zip(f.joints, frames[:-1]):
            body = body.combined(link_body(j).transformed(T))
        k += n
    return body


def hand_mass(hand: HandTable) -> float:
    return hand.palm_mass + sum(j.mass for j in hand.joints)


# ---------------------------------------------------------------------------------------------
# Namiki & Ishikawa (catching), Sec. IV-A: "a 3-fingered and 3-axis hand ... By reducing the weight
# of each finger and using high power actuators, fingers can close a 90-degree angle in 20ms."
# Only the 3 fingers, 3 axes and 90 deg / 20 ms are from the paper; the dimensions and masses are
# assumed (a light hand around a palm a bit wider than a ~4 cm ball): fingers at 120 deg on the
# rim of a 45 mm-radius disc palm, open along the palm normal, closing 90 deg towards its centre.
CATCH_CLOSING_SPEED = (math.pi / 2.0) / 0.020  # 90 deg in 20 ms = 78.54 rad/s


def _catch_finger(k: int) -> Finger:
    phi = math.radians(90.0 + 120.0 * k)  # root direction from the palm centre
    r = 0.040
    return Finger(
        name=f"f{k + 1}",
        root=(r * math.cos(phi), r * math.sin(phi), 0.012),
        yaw=phi + math.pi,  # root x axis towards the palm centre
        joints=(
            HandJoint(
                name=f"f{k + 1}_j1",
                kind="flex",
                length=0.070,
                width=0.014,
                mass=0.030,
                lower=-0.2,
                upper=math.pi / 2.0,
                open=0.0,
                closed=math.pi / 2.0,
            ),
        ),
    )


CATCH3 = HandTable(
    name="catch3",
    palm_shape="cylinder",
    palm_size=(0.045, 0.045, 0.012),
    palm_mass=0.25,
    fingers=tuple(_catch_finger(k) for k in range(3)),
    closing_speed=CATCH_CLOSING_SPEED,
    max_torque=2.0,  # assumed: ~28 N at a 70 mm finger's tip
    note="Namiki & Ishikawa Sec. IV-A: 3 fingers, 3 axes, 90 deg in 20 ms; sizes/masses assumed",
)


# ---------------------------------------------------------------------------------------------
# Namiki, Nakabo, Ishii & Ishikawa (grasping), Sec. 3.3: "4 fingers and 14 joints ... a thumb
# finger is installed opposite to the other three fingers". The split 4/3/4/3 and every size
# are assumed (human-like proportions): index, middle and ring side by side, each a sideways
# (abduct) knuckle then flexion joints; the thumb opposite them.
def _grasp_finger(
    name: str, y: float, x: float, yaw: float, kinds: tuple[str, ...], lengths: tuple[float, ...]
) -> Finger:
    joints = []
    for i, (kind, length) in enumerate(zip(kinds, lengths)):
        lo, hi = (-0.35, 0.35) if kind == "abduct" else (-0.2, math.pi / 2.0)
        joints.append(
            HandJoint(
                name=f"{name}_j{i + 1}",
                kind=kind,
                length=length,
                width=0.016,
                mass=0.010 if length == 0.0 else 0.025,
                lower=lo,
                upper=hi,
                open=0.0,
                closed=0.0 if kind == "abduct" else 1.2,
            )
        )
    return Finger(name=name, root=(x, y, 0.015), yaw=yaw, joints=tuple(joints))


GRASP4 = HandTable(
    name="grasp4",
    palm_shape="box",
    palm_size=(0.10, 0.09, 0.015),
    palm_mass=0.40,
    fingers=(
        _grasp_finger(
            "index",
            0.030,
            0.045,
            math.pi,
            ("abduct", "flex", "flex", "flex"),
            (0.0, 0.045, 0.030, 0.025),
        ),
        _grasp_finger(
            "middle", 0.0, 0.045, math.pi, ("flex", "flex", "flex"), (0.050, 0.032, 0.025)
        ),
        _grasp_finger(
            "ring",
            -0.030,
            0.045,
            math.pi,
            ("abduct", "flex", "flex", "flex"),
            (0.0, 0.045, 0.030, 0.025),
        ),
        _grasp_finger("thumb", 0.0, -0.045, 0.0, ("flex", "flex", "flex"), (0.045, 0.032, 0.025)),
    ),
    closing_speed=CATCH_CLOSING_SPEED,  # assumed same drive as the catching hand
    max_torque=2.0,
    note="Namiki et al. Sec. 3.3: 4 fingers, 14 joints, thumb opposite; split 4/3/4/3 and "
    "all sizes assumed",
)

HANDS: dict[str, HandTable] = {h.name: h for h in (CATCH3, GRASP4)}
