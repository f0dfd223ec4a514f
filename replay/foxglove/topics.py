"""A run's Foxglove well-known topics, written alongside the JSON contract topics (docs/DESIGN.md,
"Foxglove and Rerun topics"; docs/foxglove.md):

- ``/tf`` (``foxglove.FrameTransforms``): every moving body of the plant's scene in ``world``
  and every robot link in its parent link (the plant's :meth:`~replay.interfaces.Plant.frames`);
- ``/scene`` (``foxglove.SceneUpdate``): the scene's primitives (boxes, spheres, cylinders) at
  their world poses, grey by albedo;
- ``/joint_states`` (``foxglove.JointStates``): every joint of the robot (arm, hand, head);
- ``/robot_description``: the robot's URDF, once at t = 0, as ROS 2 ``std_msgs/msg/String``
  (CDR): the one schema Foxglove's URDF layer reads from a topic, and the one Rerun's MCAP
  importer turns into the robot's geometry;
- ``/log`` (``foxglove.Log``): each ``/events`` message as a log line;
- ``/camera/SENSOR/VIEW`` (``foxglove.RawImage``, mono8: :mod:`replay.foxglove.image`): each
  camera frame.

Every message is built with foxglove-sdk's message types (``foxglove.messages``), stamped with
simulated time (header ``timestamp`` = log time) and encoded deterministically, so the same run
gives the same bytes; its schema is the ``foxglove_schemas_protobuf`` class's descriptor, and
readers decode with those classes.
"""

from __future__ import annotations

import functools
from typing import Iterable, Sequence

import foxglove.messages as fm
import numpy as np
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.message import Message

from replay.foxglove.image import FrameBuffer, WindowedImage, raw_image
from replay.foxglove.schemas import (
    MESSAGE_ENCODING,
    SCHEMA_ENCODING,
    STRING_SCHEMA,
    encode_string,
    schema_data,
)
from replay.messages import (
    TOPIC_JOINT_STATES,
    TOPIC_LOG,
    TOPIC_ROBOT_DESCRIPTION,
    TOPIC_SCENE,
    TOPIC_TF,
)
from replay.scene import Box, Cylinder, Frame, Sphere

WORLD = "world"  # the fixed frame every pose hangs from


def camera_topic(sensor: str, view: str) -> str:
    """The image topic of one camera view: ``/camera/SENSOR/VIEW``; its frame is
    ``SENSOR/VIEW``."""
    return f"/camera/{sensor}/{view}"


# the /events kinds that are shown as warnings / errors in the Log panel
_WARNING_KINDS = frozenset(
    {
        "infeasible",
        "missed",
        "miss",
        "drop",
        "torque_limit",
        "velocity_limit",
        "joint_limit",
        "limit",
        "lost",
        "slip",
        "warning",
        "interrupted",
    }
)
_ERROR_KINDS = frozenset({"error", "nan"})


def log_level(kind: str, data: dict) -> fm.LogLevel:
    """``foxglove.Log`` level of an event: errors, warnings, a failed outcome a warning."""
    if kind in _ERROR_KINDS:
        return fm.LogLevel.Error
    if kind in _WARNING_KINDS or (kind == "outcome" and data.get("success") is False):
        return fm.LogLevel.Warning
    return fm.LogLevel.Info


# The messages are built with foxglove-sdk's own message types (``foxglove.messages``, Rust) and
# their ``encode()``: byte for byte what the ``foxglove_schemas_protobuf`` classes serialise
# (tests/replay/foxglove/test_foxglove_build.py; but for a -0.0 in a Vector3 or Quaternion,
# which prost leaves out as a default and so reads back as 0.0), in about half the time:
# /tf of 11 frames 36 -> 24 us, /joint_states 12 -> 5.4 us, a 16 KiB RawImage 3.8 -> 1.8 us.
# The schemas written with them are still the generated classes' descriptors (schemas.py).

_IDENTITY = (0.0, 0.0, 0.0, 1.0)


def timestamp(t_ns: int) -> fm.Timestamp:
    sec, nsec = divmod(t_ns, 1_000_000_000)
    return fm.Timestamp(sec, nsec)


def _vector(v) -> fm.Vector3:
    x, y, z = v
    return fm.Vector3(x=x, y=y, z=z)


def _quaternion(q) -> fm.Quaternion:
    x, y, z, w = q
    return fm.Quaternion(x=x, y=y, z=z, w=w)


def frame_transforms(
    frames: Iterable[Frame], t_ns: int, bodies: Iterable = (), parent: str = WORLD
) -> bytes:
    """``foxglove.FrameTransforms``: each of ``bodies`` (scene primitives) as a frame of its own
    name in ``parent`` (a sphere unrotated), then each frame's pose in its parent, at ``t_ns``."""
    ts = timestamp(t_ns)
    transform = fm.FrameTransform
    poses = [
        (parent, p.name, p.position, _IDENTITY if isinstance(p, Sphere) else p.orientation)
        for p in bodies
    ]
    poses += [(f.parent, f.child, f.position, f.orientation) for f in frames]
    return fm.FrameTransforms(
        transforms=[
            transform(
                timestamp=ts,
                parent_frame_id=parent_id,
                child_frame_id=child_id,
                translation=_vector(position),
                rotation=_quaternion(orientation),
            )
            for parent_id, child_id, position, orientation in poses
        ]
    ).encode()


def _grey(albedo: float) -> float:
    """The albedo as a grey, lifted so that a black body still shows on a dark background."""
    return 0.25 + 0.75 * min(max(float(albedo), 0.0), 1.0)


@functools.lru_cache(maxsize=4096)
def _color(albedo: float) -> fm.Color:
    v = _grey(albedo)
    return fm.Color(r=v, g=v, b=v, a=1.0)


def scene_update(primitives: Sequence, frame_id: str, t_ns: int) -> bytes:
    """``foxglove.SceneUpdate``: each box, sphere and cylinder as one entity (id = its name) of
    one primitive at its pose in ``frame_id``, grey by albedo (others are left out); a
    cylinder's axis is its body z."""
    ts = timestamp(t_ns)
    entities = []
    for p in primitives:
        if not isinstance(p, (Sphere, Box, Cylinder)):
            continue
        color = _color(p.albedo)
        orientation = _IDENTITY if isinstance(p, Sphere) else p.orientation
        pose = fm.Pose(position=_vector(p.position), orientation=_quaternion(orientation))
        entity = functools.partial(fm.SceneEntity, timestamp=ts, frame_id=frame_id, id=p.name)
        if isinstance(p, Sphere):
            d = 2.0 * p.radius
            size = _vector((d, d, d))
            entities.append(entity(spheres=[fm.SpherePrimitive(pose=pose, size=size, color=color)]))
        elif isinstance(p, Box):
            size = _vector(p.size)
            entities.append(entity(cubes=[fm.CubePrimitive(pose=pose, size=size, color=color)]))
        else:
            d = 2.0 * p.radius
            cylinder = fm.CylinderPrimitive(
                pose=pose,
                size=_vector((d, d, p.length)),
                bottom_scale=1.0,
                top_scale=1.0,
                color=color,
            )
            entities.append(entity(cylinders=[cylinder]))
    return fm.SceneUpdate(entities=entities).encode()


def joint_states(names, position, velocity, effort, t_ns: int) -> bytes:
    """``foxglove.JointStates``: each joint's name, position, velocity and effort."""
    joint = fm.JointState
    joints = [
        joint(name=n, position=q, velocity=v, effort=e)
        for n, q, v, e in zip(names, position, velocity, effort)
    ]
    return fm.JointStates(timestamp=timestamp(t_ns), joints=joints).encode()


def log_line(level: fm.LogLevel, message: str, name: str, t_ns: int) -> bytes:
    """``foxglove.Log``: a line of ``level`` from ``name``."""
    return fm.Log(timestamp=timestamp(t_ns), level=level, message=message, name=name).encode()


class FoxgloveTopics:
    """The Foxglove topics of one log: ``FoxgloveTopics(log_writer)``, then one call a message."""

    def __init__(self, log) -> None:
        self.log = log  # a replay.log.LogWriter
        self._channels: dict[str, int] = {}  # topic -> channel id
        self._schemas: dict[str, int] = {}  # schema name -> id (each stored once)
        # sensor -> view -> (channel id, frame id, the frame its windowed frames are built in)
        self._images: dict[str, dict[str, tuple[int, str, FrameBuffer]]] = {}

    def _channel(self, topic: str, schema: str, encoding: str, data: bytes, message: str) -> int:
        if schema not in self._schemas:
            self._schemas[schema] = self.log.register_schema(schema, encoding, data)
        channel = self._channels[topic] = self.log.register_channel(
            topic, message, self._schemas[schema]
        )
        return channel

    def robot_description(self, urdf: str, t_ns: int) -> None:
        channel = self._channels.get(TOPIC_ROBOT_DESCRIPTION)
        if channel is None:
            channel = self._channel(
                TOPIC_ROBOT_DESCRIPTION, STRING_SCHEMA, "ros2msg", b"string data", "cdr"
            )
        self.log.write_raw(channel, encode_string(urdf), t_ns)

    def _proto_channel(self, topic: str, cls: type[Message]) -> int:
        """The channel of a topic of ``cls`` messages (made on first use)."""
        channel = self._channels.get(topic)
        if channel is None:
            name = cls.DESCRIPTOR.full_name
            channel = self._channel(
                topic, name, SCHEMA_ENCODING, schema_data(cls), MESSAGE_ENCODING
            )
        return channel

    def transforms(self, frames: Iterable[Frame], t_ns: int, bodies: Sequence = ()) -> None:
        """``frames``, after each of ``bodies`` (scene primitives) as a frame of its own name in
        ``world``."""
        channel = self._channels.get(TOPIC_TF) or self._proto_channel(TOPIC_TF, FrameTransforms)
        self.log.write_raw(channel, frame_transforms(frames, t_ns, bodies), t_ns)

    def scene(self, primitives: Sequence, t_ns: int) -> None:
        """The primitives as one entity each (id = name) at their world poses."""
        channel = self._channels.get(TOPIC_SCENE) or self._proto_channel(TOPIC_SCENE, SceneUpdate)
        self.log.write_raw(channel, scene_update(primitives, WORLD, t_ns), t_ns)

    def joint_states(self, names, position, velocity, effort, t_ns: int) -> None:
        channel = self._channels.get(TOPIC_JOINT_STATES) or self._proto_channel(
            TOPIC_JOINT_STATES, JointStates
        )
        self.log.write_raw(channel, joint_states(names, position, velocity, effort, t_ns), t_ns)

    def event(self, kind: str, data: dict, text: str, t_ns: int) -> None:
        """One ``/events`` message as a log line: ``KIND {data as JSON}``."""
        channel = self._channels.get(TOPIC_LOG) or self._proto_channel(TOPIC_LOG, Log)
        line = log_line(log_level(kind, data), f"{kind} {text}", "paper-replay", t_ns)
        self.log.write_raw(channel, line, t_ns)

    def images(
        self, sensor: str, frames: Sequence[tuple[str, np.ndarray | WindowedImage]], t_ns: int
    ) -> None:
        """A sensor's frame: each (view, image) as a ``foxglove.RawImage`` on its
        ``/camera/SENSOR/VIEW`` topic (frame ``SENSOR/VIEW``), one timestamp for all."""
        views = self._images.get(sensor)
        if views is None:
            views = self._images[sensor] = {}
        for view, image in frames:
            got = views.get(view)
            if got is None:
                channel = self._proto_channel(camera_topic(sensor, view), RawImage)
                got = views[view] = (channel, f"{sensor}/{view}", FrameBuffer())
            self.log.write_raw(got[0], raw_image(image, got[1], t_ns, got[2]), t_ns)
