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
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.CylinderPrimitive_pb2 import CylinderPrimitive
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointState_pb2 import JointState
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Log_pb2 import Log
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.SpherePrimitive_pb2 import SpherePrimitive
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
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


def _pose(position, orientation=(0.0, 0.0, 0.0, 1.0)) -> Pose:
    x, y, z = position
    qx, qy, qz, qw = orientation
    return Pose(position=Vector3(x=x, y=y, z=z), orientation=Quaternion(x=qx, y=qy, z=qz, w=qw))


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
        self.log = log
        self._registered: set[str] = set()

    def _write(self, topic: str, msg: Message, t_ns: int) -> None:
        if topic not in self._registered:
            self.log.register_channel(
                topic,
                schema_name=msg.DESCRIPTOR.full_name,
                schema_encoding=SCHEMA_ENCODING,
                schema_data=schema_data(type(msg)),
                message_encoding=MESSAGE_ENCODING,
            )
            self._registered.add(topic)
        self.log.write_raw(topic, msg.SerializeToString(deterministic=True), t_ns)

    def robot_description(self, urdf: str, t_ns: int) -> None:
        if TOPIC_ROBOT_DESCRIPTION not in self._registered:
            self.log.register_channel(
                TOPIC_ROBOT_DESCRIPTION,
                schema_name=STRING_SCHEMA,
                schema_encoding="ros2msg",
                schema_data=b"string data",
                message_encoding="cdr",
            )
            self._registered.add(TOPIC_ROBOT_DESCRIPTION)
        self.log.write_raw(TOPIC_ROBOT_DESCRIPTION, encode_string(urdf), t_ns)

    def transforms(self, frames: Iterable[Frame], t_ns: int) -> None:
        stamp = _stamp(t_ns)
        msg = FrameTransforms(
            transforms=[
                FrameTransform(
                    timestamp=stamp,
                    parent_frame_id=f.parent,
                    child_frame_id=f.child,
                    translation=Vector3(x=f.position[0], y=f.position[1], z=f.position[2]),
                    rotation=Quaternion(
                        x=f.orientation[0],
                        y=f.orientation[1],
                        z=f.orientation[2],
                        w=f.orientation[3],
                    ),
                )
                for f in frames
            ]
        )
        self._write(TOPIC_TF, msg, t_ns)

    def scene(self, primitives: Sequence, t_ns: int) -> None:
        """The primitives as one entity each (id = name) at their world poses."""
        stamp = _stamp(t_ns)
        entities = []
        for p in primitives:
            e = SceneEntity(timestamp=stamp, frame_id=WORLD, id=p.name)
            if isinstance(p, Box):
                e.cubes.append(
                    CubePrimitive(
                        pose=_pose(p.position, p.orientation),
                        size=Vector3(x=p.size[0], y=p.size[1], z=p.size[2]),
                        color=_grey(p.albedo),
                    )
                )
            elif isinstance(p, Sphere):
                d = 2.0 * p.radius
                e.spheres.append(
                    SpherePrimitive(
                        pose=_pose(p.position),
                        size=Vector3(x=d, y=d, z=d),
                        color=_grey(p.albedo),
                    )
                )
            elif isinstance(p, Cylinder):  # its axis is the body z axis, as Foxglove's
                d = 2.0 * p.radius
                e.cylinders.append(
                    CylinderPrimitive(
                        pose=_pose(p.position, p.orientation),
                        size=Vector3(x=d, y=d, z=p.length),
                        bottom_scale=1.0,
                        top_scale=1.0,
                        color=_grey(p.albedo),
                    )
                )
            else:
                continue
            entities.append(e)
        self._write(TOPIC_SCENE, SceneUpdate(entities=entities), t_ns)

    def joint_states(self, names, position, velocity, effort, t_ns: int) -> None:
        self._write(
            TOPIC_JOINT_STATES,
            JointStates(
                timestamp=_stamp(t_ns),
                joints=[
                    JointState(name=n, position=q, velocity=v, effort=e)
                    for n, q, v, e in zip(names, position, velocity, effort)
                ],
            ),
            t_ns,
        )

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
