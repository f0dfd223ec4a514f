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
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from google.protobuf.message import Message

from replay.foxglove import wire
from replay.foxglove.png import WindowedImage, png_messages
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
from replay.scene import Frame

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
        # sensor -> view -> (channel id, the image messages' fields after the PNG)
        self._images: dict[str, dict[str, tuple[int, bytes]]] = {}
        self._record = log.raw_message  # the log's compiled record writer

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

    def _wire(self, topic: str, cls: type[Message]) -> int:
        """The channel of a topic of ``cls`` messages (made on first use)."""
        channel = self._channels.get(topic)
        if channel is None:
            name = cls.DESCRIPTOR.full_name
            channel = self._channel(
                topic, name, SCHEMA_ENCODING, schema_data(cls), MESSAGE_ENCODING
            )
        return channel

    # The messages at the frame and camera rates are written straight in the wire format
    # (replay.foxglove.wire: ~5x cheaper than filling the protobuf classes, same messages).
    def transforms(self, frames: Iterable[Frame], t_ns: int, bodies: Sequence = ()) -> None:
        """``frames``, after each of ``bodies`` (scene primitives) as a frame of its own name in
        ``world``."""
        channel = self._channels.get(TOPIC_TF) or self._wire(TOPIC_TF, FrameTransforms)
        data = wire.body_transforms(bodies, WORLD, t_ns) + wire.frame_transforms(frames, t_ns)
        self.log.write_raw(channel, data, t_ns)

    def scene(self, primitives: Sequence, t_ns: int) -> None:
        """The primitives as one entity each (id = name) at their world poses."""
        channel = self._channels.get(TOPIC_SCENE) or self._wire(TOPIC_SCENE, SceneUpdate)
        self.log.write_raw(channel, wire.scene_update(primitives, WORLD, t_ns), t_ns)

    def joint_states(self, names, position, velocity, effort, t_ns: int) -> None:
        channel = self._channels.get(TOPIC_JOINT_STATES) or self._wire(
            TOPIC_JOINT_STATES, JointStates
        )
        self.log.write_raw(
            channel, wire.joint_states(names, position, velocity, effort, t_ns), t_ns
        )

    def event(self, kind: str, data: dict, text: str, t_ns: int) -> None:
        """One ``/events`` message as a log line: ``KIND {data as JSON}``."""
        channel = self._channels.get(TOPIC_LOG) or self._wire(TOPIC_LOG, Log)
        self.log.write_raw(
            channel,
            wire.log_line(int(log_level(kind, data)), f"{kind} {text}", "paper-replay", t_ns),
            t_ns,
        )

    def images(
        self, sensor: str, frames: Sequence[tuple[str, np.ndarray | WindowedImage]], t_ns: int
    ) -> None:
        """A sensor's frame: each (view, image) on its ``/camera/SENSOR/VIEW`` topic, one
        timestamp for all, in one compiled call (``_png.messages``: each image's PNG message
        to the log's record writer) but for a view's first image, which makes its channel."""
        views = self._images.get(sensor)
        if views is None:
            views = self._images[sensor] = {}
        if not isinstance(frames, (list, tuple)):
            frames = list(frames)
        ts, start = wire.timestamp(t_ns), 0
        while True:
            try:
                start = png_messages(self._record, views, frames, start, ts, t_ns)
            except OSError as exc:
                raise self.log.write_error(exc) from None
            if start < 0:
                return
            view = frames[start][0]
            channel = self._wire(camera_topic(sensor, view), CompressedImage)
            views[view] = (channel, wire.image_tail(f"{sensor}/{view}", "png"))
