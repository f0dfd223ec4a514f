"""The grasping rig's logged topics and scene readings, engine-free: plain functions of the
readings they need (the servos', head's and human's public state, the head camera's pose, the
wrist's wrench), for the truth topics the grasping rig (``grasp_rig.GraspRig``) adds to the arm
rig's (``/arm/servo``, ``/head/joint_state``, ``/head/state``, ``/human/state``,
``/human/wrench``, ``/wrist/wrench_truth``), the head's joints and camera frame and the scene's
hand, head and wrist readings. Every engine's grasp rig logs them from this one source.
"""

from __future__ import annotations

from typing import Sequence

from plants.arm_rig.head import HeadServo
from plants.arm_rig.human_path import HumanPath
from plants.arm_rig.payloads import HeadState, HumanState, HumanWrench, ServoState, Wrench
from plants.arm_rig.servo import VelocityServos
from replay.messages import JointState
from replay.scene import Frame

HEAD_JOINTS = ("pan", "tilt")


def full(values: list, active: Sequence[int], dof: int) -> list:
    """Per-active-joint ``values`` as a list over every one of ``dof`` arm joints (zero where
    locked)."""
    if len(active) == dof:
        return list(values)
    out = [0.0] * dof
    for i, x in zip(active, values):
        out[i] = x
    return out


def servo_topic(
    t: float, names: Sequence[str], active: Sequence[int], servos: VelocityServos, torque, clamped
) -> ServoState:
    """``/arm/servo``: the servos' command and integral (over every joint of ``names``, the
    ``active`` ones served) with the torques applied and their saturation (full joint list)."""
    n = len(names)
    return ServoState(
        t,
        list(names),
        full(servos.command_l, active, n),
        full(servos.integral_l, active, n),
        torque[:],
        clamped[:],
    )


def head_topics(t: float, hs: HeadServo, camera: tuple) -> dict:
    """``/head/joint_state`` and ``/head/state`` of the head servo ``hs``, its camera at
    ``camera`` (R, c, [qx, qy, qz, qw])."""
    _, c, quat = camera
    return {
        "/head/joint_state": JointState(
            t, list(HEAD_JOINTS), hs.q_l[:], hs.qd_l[:], hs.torque_l[:]
        ),
        "/head/state": HeadState(t, hs.q_l[0], hs.q_l[1], hs.qd_l[:], c.tolist(), quat[:]),
    }


def human_topics(t: float, human: HumanPath, pos) -> dict:
    """``/human/state`` and ``/human/wrench`` of the human hand, the object's centre at ``pos``."""
    return {
        "/human/state": HumanState(
            t, human.target_l[:], float(human.roll), human.force(), human.max_force
        ),
        "/human/wrench": HumanWrench(
            t,
            human.force(),
            human.torque_l[:],
            [a - b for a, b in zip(pos, human.target_l)],
            human.limited,
        ),
    }


def wrist_topic(t: float, wrench) -> Wrench:
    """``/wrist/wrench_truth``: the wrist's true wrench [Fx, Fy, Fz, Mx, My, Mz]."""
    return Wrench(t, wrench[:3], wrench[3:])


def head_frame(camera: tuple) -> Frame:
    """The head's camera (``head_camera``: x right, y down, z the optical axis) in ``world``."""
    _, c, quat = camera
    x, y, z = (float(v) for v in c)
    return Frame("world", "head_camera", (x, y, z), tuple(quat))


def grasp_readings(hand_names, hand: tuple, hs: HeadServo, camera: tuple, wrench) -> dict:
    """The scene's ``hand``, ``hand_torque``, ``head`` and ``wrist`` readings: the hand's joints
    ``hand`` (q, qd, torque), the head servo, its camera (R, c, ...) and the wrist's wrench."""
    R, c, _ = camera
    hq, hqd, htau = hand
    return {
        "hand": {"name": list(hand_names), "position": hq[:], "velocity": hqd[:]},
        "hand_torque": {"name": list(hand_names), "torque": htau},
        "head": {
            "name": list(HEAD_JOINTS),
            "position": hs.q_l[:],
            "velocity": hs.qd_l[:],
            "camera_rotation": R,
            "camera_position": c,
        },
        "wrist": {"wrench": wrench},
    }
