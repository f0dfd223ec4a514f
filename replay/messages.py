"""Message payloads of the log contract (docs/DESIGN.md): one dataclass per topic.

Every message carries ``t``, simulated seconds. Fields are SI (m, kg, s, rad). A payload's JSON
schema is derived from its fields, so the MCAP file is self-describing for the ``mcap`` CLI and
Foxglove. Topic names and field names are a contract: add topics and fields, rename none.
"""

from __future__ import annotations

import dataclasses
import enum
import types
import typing
from dataclasses import dataclass, field
from typing import Annotated, Any

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


@dataclass(frozen=True)
class Length:
    """``Annotated[list[float], Length(3)]``: a list of exactly ``n`` items in the schema;
    ``empty=True``: or ``[]`` (nothing measured yet)."""

    n: int
    empty: bool = False


@dataclass(frozen=True)
class OneOf:
    """``Annotated[str, OneOf("a", "b")]``: an enum in the schema, a plain ``str`` to mypy (a
    ``Literal`` would make every assignment from a ``str`` variable a type error)."""

    values: tuple

    def __init__(self, *values: Any) -> None:
        object.__setattr__(self, "values", values)


Vec2 = Annotated[list[float], Length(2)]  # [x, y] or [u, v]
Vec3 = Annotated[list[float], Length(3)]  # [x, y, z] (m, m/s, rad/s, N, N*m)
Quat = Annotated[list[float], Length(4)]  # [qx, qy, qz, qw]
Pose6 = Annotated[list[float], Length(6)]  # [x, y, z, roll, pitch, yaw]


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
    data: dict[str, Any] = field(default_factory=dict)  # per kind (docs/DESIGN.md)


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
    tips: list[Vec2]  # [[x, y], [x, y]] fingertip centres (m)


@dataclass
class VisionStick:
    t: float  # capture time of the image
    x: float
    y: float
    theta: float


@dataclass
class JointState:
    t: float
    name: list[str]
    position: list[float]
    velocity: list[float]
    effort: list[float]


@dataclass
class JointCommand:
    t: float
    position: list[float]  # q_d (rad)
    torque: list[float]  # (N*m)


@dataclass
class ObjectState:
    t: float
    position: Vec3
    orientation: Quat
    velocity: Vec3
    angular_velocity: Vec3


@dataclass
class EffectorState:
    t: float
    position: Vec3
    desired_position: Vec3


@dataclass
class VisionObject:
    t: float
    position: Vec3  # measured [x, y, z] (m)
    features: dict[str, Any] = field(default_factory=dict)  # the sensor's own (centroids, ...)


@dataclass
class OptimizationCost:
    t: float
    iteration: int
    torque_cost: float
    velocity_cost: float


@dataclass
class HandState:
    """``/hand/state``: the air table's hand (Higashimori et al. 2007, Sec. IV-A): XY base (m)
    and the two fingers' joint angles [[q1, q2], [q1, q2]] (rad), actual and target."""

    t: float
    base: Vec2
    joints: Annotated[list[Vec2], Length(2)]
    base_target: Vec2
    joint_targets: Annotated[list[Vec2], Length(2)]


@dataclass
class StickEstimateMessage:
    """``/control/stick_estimate``: the stick controllers' phase and, once the estimator has a
    fit, the stick's state at ``t`` from the fit made at ``t_ref`` over ``n`` images, with the
    fit's residuals (m, rad)."""

    t: float
    phase: Annotated[str, OneOf("observe", "approach", "close", "captured")]
    step: int  # index of the next collision
    ready: bool
    t_ref: float | None = None
    x: float | None = None
    y: float | None = None
    theta: float | None = None
    vx: float | None = None
    vy: float | None = None
    omega: float | None = None
    n: int | None = None
    rms_xy: float | None = None
    rms_theta: float | None = None


# topic -> payload type, for the contract topics
TOPICS: dict[str, type] = {
    TOPIC_SCENARIO: ScenarioInfo,
    TOPIC_EVENTS: Event,
    TOPIC_STICK_STATE: StickState,
    TOPIC_FINGERS_STATE: FingersState,
    TOPIC_HAND_STATE: HandState,
    TOPIC_STICK_ESTIMATE: StickEstimateMessage,
    TOPIC_VISION_STICK: VisionStick,
    TOPIC_ARM_JOINT_STATE: JointState,
    TOPIC_HAND_JOINT_STATE: JointState,
    TOPIC_ARM_JOINT_COMMAND: JointCommand,
    TOPIC_OBJECT_STATE: ObjectState,
    TOPIC_EFFECTOR_STATE: EffectorState,
    TOPIC_VISION_OBJECT: VisionObject,
    TOPIC_OPTIMIZATION_COST: OptimizationCost,
}

_SCALARS = {float: "number", int: "integer", str: "string", bool: "boolean"}


def type_schema(tp: Any) -> dict[str, Any]:
    """The JSON schema of one annotated type: scalars, ``list[X]`` (``items``), ``tuple``
    (fixed or ``...``), ``Annotated[..., Length(n)]``, ``Annotated[str, OneOf(...)]``, ``dict[str, X]``, ``X | None``,
    ``Literal``, ``Enum`` and nested dataclasses. ``Any`` is any JSON value. A bare ``list`` or
    ``dict`` gives a loose schema (no ``items``): annotate what it holds."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin is Annotated:
        out = type_schema(args[0])
        for meta in args[1:]:
            if isinstance(meta, Length) and meta.empty:
                out["anyOf"] = [{"maxItems": 0}, {"minItems": meta.n, "maxItems": meta.n}]
            elif isinstance(meta, Length):
                out.update(minItems=meta.n, maxItems=meta.n)
            elif isinstance(meta, OneOf):
                out = {"enum": list(meta.values)}
        return out
    if tp is Any:
        return {}
    if tp in _SCALARS:
        return {"type": _SCALARS[tp]}
    if tp is type(None):
        return {"type": "null"}
    if origin in (typing.Union, types.UnionType):
        return {"anyOf": [type_schema(a) for a in args]}
    if origin is typing.Literal:
        return {"enum": list(args)}
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        return {"enum": [m.value for m in tp]}
    if dataclasses.is_dataclass(tp):
        return json_schema(tp)  # type: ignore[arg-type]
    if origin in (list, tuple) and args:
        if origin is tuple and args[-1] is not Ellipsis:
            n = len(args)
            return {
                "type": "array",
                "prefixItems": [type_schema(a) for a in args],
                "items": False,
                "minItems": n,
                "maxItems": n,
            }
        return {"type": "array", "items": type_schema(args[0])}
    if origin is dict and args:
        values = type_schema(args[1])
        return {"type": "object", "additionalProperties": values if values else True}
    if tp in (list, tuple) or origin in (list, tuple):
        return {"type": "array"}  # loose: a plug-in's bare ``list`` (tests keep ours precise)
    if tp is dict or origin is dict:
        return {"type": "object"}
    return {}  # any other type: any JSON value


def json_schema(cls: type) -> dict[str, Any]:
    """The JSON schema (draft 2020-12) of a payload dataclass: each field from its annotation
    (:func:`type_schema`); a field with a default may be left out of a message."""
    hints = typing.get_type_hints(cls, include_extras=True)
    fields = dataclasses.fields(cls)
    return {
        "title": cls.__name__,
        "type": "object",
        "properties": {f.name: type_schema(hints[f.name]) for f in fields},
        "required": [
            f.name
            for f in fields
            if f.default is dataclasses.MISSING and f.default_factory is dataclasses.MISSING
        ],
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
    rows: list[int]  # rows[v]: bit u set = pixel (u, v) is 1
    count: int  # pixels set


def pack_rows(bits: np.ndarray) -> list[int]:
    """A (h, w) 0/1 array as h ints, bit u of row v = bits[v, u] (any width: Python ints)."""
    packed = np.packbits(np.asarray(bits, dtype=bool), axis=1, bitorder="little")
    return [int.from_bytes(row.tobytes(), "little") for row in packed]


def unpack_rows(rows, width: int) -> np.ndarray:
    """The inverse of :func:`pack_rows`: a (len(rows), width) bool array."""
    n = (width + 7) // 8
    data = b"".join(int(r).to_bytes(n, "little") for r in rows)
    bits = np.unpackbits(np.frombuffer(data, np.uint8).reshape(-1, n), axis=1, bitorder="little")
    return bits[:, :width].astype(bool)
