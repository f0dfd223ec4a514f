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
- ``/camera/SENSOR/VIEW`` (``foxglove.CompressedImage``, PNG): each camera frame.

Every message is stamped with simulated time (header ``timestamp`` = log time) and serialised
deterministically, so the same run gives the same bytes.
"""

from __future__ import annotations

from typing import Iterable, Sequence

import numpy as np
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.message import Message
from google.protobuf.timestamp_pb2 import Timestamp

from replay.foxglove.png import encode_png
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


def _stamp(t_ns: int) -> Timestamp:
    return Timestamp(seconds=t_ns // 1_000_000_000, nanos=t_ns % 1_000_000_000)


def _grey(albedo: float) -> Color:
    """The albedo as a grey, lifted so that a black body still shows on a dark background."""
    v = 0.25 + 0.75 * min(max(float(albedo), 0.0), 1.0)
    return Color(r=v, g=v, b=v, a=1.0)


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


def log_level(kind: str, data: dict) -> Log.Level.ValueType:
    """``foxglove.Log`` level of an event: errors, warnings, a failed outcome a warning."""
    if kind in _ERROR_KINDS:
        return Log.ERROR
    if kind in _WARNING_KINDS or (kind == "outcome" and data.get("success") is False):
        return Log.WARNING
    return Log.INFO


class FoxgloveTopics:
    """The Foxglove topics of one log: ``FoxgloveTopics(log_writer)``, then one call a message."""

    def __init__(self, log) -> None:
        self.log = log  # a replay.log.LogWriter
        self._channels: dict[str, int] = {}  # topic -> channel id
        self._schemas: dict[str, int] = {}  # schema name -> id (each stored once)

    def _channel(self, topic: str, schema: str, encoding: str, data: bytes, message: str) -> int:
        if schema not in self._schemas:
            self._schemas[schema] = self.log.register_schema(schema, encoding, data)
        channel = self._channels[topic] = self.log.register_channel(
            topic, message, self._schemas[schema]
        )
        return channel

    def _write(self, topic: str, msg: Message, t_ns: int) -> None:
        channel = self._channels.get(topic)
        if channel is None:
            name = msg.DESCRIPTOR.full_name
            channel = self._channel(
                topic, name, SCHEMA_ENCODING, schema_data(type(msg)), MESSAGE_ENCODING
            )
        self.log.write_raw(channel, msg.SerializeToString(deterministic=True), t_ns)

    def robot_description(self, urdf: str, t_ns: int) -> None:
        channel = self._channels.get(TOPIC_ROBOT_DESCRIPTION)
        if channel is None:
            channel = self._channel(
                TOPIC_ROBOT_DESCRIPTION, STRING_SCHEMA, "ros2msg", b"string data", "cdr"
            )
        self.log.write_raw(channel, encode_string(urdf), t_ns)

    # The messages are filled in place (``add()``, attribute by attribute): ~4x faster than
    # building them from nested constructors, same bytes.
    def transforms(self, frames: Iterable[Frame], t_ns: int) -> None:
        msg = FrameTransforms()
        sec, nsec = divmod(t_ns, 1_000_000_000)
        for f in frames:
            x = msg.transforms.add()
            x.timestamp.seconds, x.timestamp.nanos = sec, nsec
            x.parent_frame_id, x.child_frame_id = f.parent, f.child
            tr, rot = x.translation, x.rotation
            tr.x, tr.y, tr.z = f.position
            rot.x, rot.y, rot.z, rot.w = f.orientation
        self._write(TOPIC_TF, msg, t_ns)

    def scene(self, primitives: Sequence, t_ns: int) -> None:
        """The primitives as one entity each (id = name) at their world poses."""
        msg = SceneUpdate()
        sec, nsec = divmod(t_ns, 1_000_000_000)
        for p in primitives:
            if not isinstance(p, (Box, Sphere, Cylinder)):
                continue
            e = msg.entities.add()
            e.timestamp.seconds, e.timestamp.nanos = sec, nsec
            e.frame_id, e.id = WORLD, p.name
            if isinstance(p, Box):
                shape = e.cubes.add()
                shape.size.x, shape.size.y, shape.size.z = p.size
                orientation = p.orientation
            elif isinstance(p, Sphere):
                shape = e.spheres.add()
                d = 2.0 * p.radius
                shape.size.x = shape.size.y = shape.size.z = d
                orientation = (0.0, 0.0, 0.0, 1.0)
            else:  # a Cylinder: its axis is the body z axis, as Foxglove's
                shape = e.cylinders.add()
                d = 2.0 * p.radius
                shape.size.x, shape.size.y, shape.size.z = d, d, p.length
                shape.bottom_scale = shape.top_scale = 1.0
                orientation = p.orientation
            pos, rot = shape.pose.position, shape.pose.orientation
            pos.x, pos.y, pos.z = p.position
            rot.x, rot.y, rot.z, rot.w = orientation
            shape.color.CopyFrom(_grey(p.albedo))
        self._write(TOPIC_SCENE, msg, t_ns)

    def joint_states(self, names, position, velocity, effort, t_ns: int) -> None:
        msg = JointStates()
        msg.timestamp.seconds, msg.timestamp.nanos = divmod(t_ns, 1_000_000_000)
        for n, q, v, e in zip(names, position, velocity, effort):
            j = msg.joints.add()
            j.name, j.position, j.velocity, j.effort = n, q, v, e
        self._write(TOPIC_JOINT_STATES, msg, t_ns)

    def event(self, kind: str, data: dict, text: str, t_ns: int) -> None:
        """One ``/events`` message as a log line: ``KIND {data as JSON}``."""
        self._write(
            TOPIC_LOG,
            Log(
                timestamp=_stamp(t_ns),
                level=log_level(kind, data),
                message=f"{kind} {text}",
                name="paper-replay",
            ),
            t_ns,
        )

    def image(self, sensor: str, view: str, image: np.ndarray, t_ns: int) -> None:
        self._write(
            camera_topic(sensor, view),
            CompressedImage(
                timestamp=_stamp(t_ns),
                frame_id=f"{sensor}/{view}",
                data=encode_png(image),
                format="png",
            ),
            t_ns,
        )
