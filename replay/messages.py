"""Message payloads of the log contract (docs/DESIGN.md): one dataclass per topic.

Every message carries ``t``, simulated seconds. Fields are SI (m, kg, s, rad). A payload's JSON
schema is derived from its fields, so the MCAP file is self-describing for the ``mcap`` CLI and
Foxglove. Topic names and field names are a contract: add topics and fields, rename none.
"""

from __future__ import annotations

import dataclasses
import typing
from dataclasses import dataclass, field
from typing import Any

import numpy as np

# ---- topic names (the contract: add freely, rename none). Use these, not string literals.
TOPIC_SCENARIO = "/scenario"  # ScenarioInfo, once at t = 0
TOPIC_EVENTS = "/events"  # Event
# air table (Higashimori et al. 2007)
TOPIC_STICK_STATE = "/stick/state"  # StickState
TOPIC_FINGERS_STATE = "/fingers/state"  # FingersState
TOPIC_HAND_STATE = "/hand/state"  # the airtable plant's hand
TOPIC_VISION_STICK = "/vision/stick"  # VisionStick
TOPIC_STICK_ESTIMATE = "/control/stick_estimate"  # the stick controllers' estimator
# arm plant (Namiki & Ishikawa 2003, Namiki et al. 1999)
TOPIC_ARM_JOINT_STATE = "/arm/joint_state"  # JointState
TOPIC_HAND_JOINT_STATE = "/hand/joint_state"  # JointState
TOPIC_ARM_JOINT_COMMAND = "/arm/joint_command"  # JointCommand
TOPIC_ARM_ENCODERS = "/arm/encoders"  # JointState, measured
TOPIC_ARM_APPLIED_TORQUE = "/arm/applied_torque"
TOPIC_OBJECT_STATE = "/object/state"  # ObjectState
TOPIC_OBJECT_CONTACTS = "/object/contacts"
TOPIC_EFFECTOR_STATE = "/effector/state"  # EffectorState
TOPIC_EFFECTOR_MOTION = "/effector/motion"
TOPIC_VISION_OBJECT = "/vision/object"  # VisionObject
TOPIC_OPTIMIZATION_COST = "/optimization/cost"  # OptimizationCost
TOPIC_CATCHING_STATE = "/catching/state"  # the catching controller's state
# grasping rig (Namiki et al. 1999; docs/DESIGN.md, "Grasping runs")
TOPIC_HAND_ENCODERS = "/hand/encoders"
TOPIC_HEAD_ENCODERS = "/head/encoders"
TOPIC_VISION_CHIP = "/vision/chip"
TOPIC_WRIST_WRENCH = "/wrist/wrench"
TOPIC_HAND_TORQUE = "/hand/joint_torque"
TOPIC_GRASP_OBJECT = "/grasping/object"
TOPIC_GRASP_STATE = "/grasping/state"
TOPIC_GRASP_HEAD = "/grasping/head"
TOPIC_GRASP_ARM = "/grasping/arm"
TOPIC_GRASP_HAND = "/grasping/hand"
TOPIC_TASK_LOOPS = "/tasks/loops"
# Foxglove / Rerun well-known topics (replay/foxglove; docs/foxglove.md), Protobuf-encoded except
# /robot_description (std_msgs/String as JSON); camera images on /camera/SENSOR/VIEW
TOPIC_TF = "/tf"  # foxglove.FrameTransforms
TOPIC_SCENE = "/scene"  # foxglove.SceneUpdate
TOPIC_JOINT_STATES = "/joint_states"  # foxglove.JointStates
TOPIC_ROBOT_DESCRIPTION = "/robot_description"  # the URDF, once at t = 0
TOPIC_LOG = "/log"  # foxglove.Log: the /events as log lines


@dataclass
class ScenarioInfo:
    t: float
    name: str
    paper: str
    yaml: str  # the resolved scenario, every default filled in
    seed: int
    version: str


@dataclass
class Event:
    t: float
    kind: str  # collision, catch, grasp, release, infeasible, rest, ...
    data: dict = field(default_factory=dict)


@dataclass
class StickState:
    t: float
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float


@dataclass
class FingersState:
    t: float
    tips: list  # [[x, y], [x, y]] fingertip centres (m)


@dataclass
class VisionStick:
    t: float  # capture time of the image
    x: float
    y: float
    theta: float


@dataclass
class JointState:
    t: float
    name: list
    position: list
    velocity: list
    effort: list


@dataclass
class JointCommand:
    t: float
    position: list  # q_d (rad)
    torque: list  # (N*m)


@dataclass
class ObjectState:
    t: float
    position: list
    orientation: list  # [qx, qy, qz, qw]
    velocity: list
    angular_velocity: list


@dataclass
class EffectorState:
    t: float
    position: list
    desired_position: list


@dataclass
class VisionObject:
    t: float
    position: list  # measured [x, y, z] (m)
    features: dict = field(default_factory=dict)


@dataclass
class OptimizationCost:
    t: float
    iteration: int
    torque_cost: float
    velocity_cost: float


# topic -> payload type, for the contract topics
TOPICS: dict[str, type] = {
    TOPIC_SCENARIO: ScenarioInfo,
    TOPIC_EVENTS: Event,
    TOPIC_STICK_STATE: StickState,
    TOPIC_FINGERS_STATE: FingersState,
    TOPIC_VISION_STICK: VisionStick,
    TOPIC_ARM_JOINT_STATE: JointState,
    TOPIC_HAND_JOINT_STATE: JointState,
    TOPIC_ARM_JOINT_COMMAND: JointCommand,
    TOPIC_OBJECT_STATE: ObjectState,
    TOPIC_EFFECTOR_STATE: EffectorState,
    TOPIC_VISION_OBJECT: VisionObject,
    TOPIC_OPTIMIZATION_COST: OptimizationCost,
}

_JSON_TYPES = {
    float: "number",
    int: "integer",
    str: "string",
    bool: "boolean",
    list: "array",
    dict: "object",
}


def json_schema(cls: type) -> dict[str, Any]:
    """A JSON schema (draft 2020-12 subset) of a payload dataclass."""
    hints = typing.get_type_hints(cls)
    props = {}
    for f in dataclasses.fields(cls):
        tp = typing.get_origin(hints[f.name]) or hints[f.name]
        props[f.name] = {"type": _JSON_TYPES.get(tp, "object")}
    return {
        "title": cls.__name__,
        "type": "object",
        "properties": props,
        "required": [f.name for f in dataclasses.fields(cls)],
    }


_FIELD_NAMES: dict[type, tuple[str, ...]] = {}


def to_dict(payload: Any) -> dict[str, Any]:
    """A payload dataclass (or a plain dict) as a JSON-ready dict."""
    if isinstance(payload, dict):
        return payload
    cls = type(payload)
    names = _FIELD_NAMES.get(cls)
    if names is None:
        names = _FIELD_NAMES[cls] = tuple(f.name for f in dataclasses.fields(payload))
    return {name: getattr(payload, name) for name in names}


@dataclass
class VisionChip:
    t: float  # capture time
    width: int
    height: int
    rows: list  # rows[v]: bit u set = pixel (u, v) is 1
    count: int  # pixels set


def pack_rows(bits: np.ndarray) -> list[int]:
    """A (h, w) 0/1 array as h ints, bit u of row v = bits[v, u]."""
    weights = 1 << np.arange(bits.shape[1], dtype=np.int64)
    return [int(x) for x in (bits.astype(np.int64) @ weights)]


def unpack_rows(rows, width: int) -> np.ndarray:
    """The inverse of :func:`pack_rows`: a (len(rows), width) bool array."""
    r = np.asarray(rows, dtype=np.int64)[:, None]
    return ((r >> np.arange(width, dtype=np.int64)) & 1).astype(bool)
