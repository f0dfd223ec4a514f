"""Foxglove's messages written straight in the protobuf wire format (protobuf.dev, "Encoding"):
``/tf``, ``/scene``, ``/joint_states`` and camera images, the ones written at the frame or
camera rate, and ``/log``'s lines (the protobuf classes' first use in a run is slow).

Filling the ``foxglove_schemas_protobuf`` classes costs ~0.2 us an attribute (a /tf of 15
frames ~60 us); here a frame transform is one ``struct.pack`` of its seven doubles behind the
cached bytes of its frame names, and the timestamp, /tf's frame transforms and the joint states
are compiled, as are the primitives' transforms and scene entities (``_wire.c``, 3-20x
cheaper; the Python references ``_timestamp``, ``_frame_transforms``, ``_body_transforms``,
``_scene_update`` and ``_joint_states`` kept for the tests). Every double is written, zeros too (the library leaves a zero
out; a reader gives 0.0 either way), so the bytes are fixed by the values; the messages decode
to the library's own (tests/replay/foxglove/test_wire.py builds both from seeded random
input). Field numbers are those of the schemas (foxglove.FrameTransform: timestamp 1, parent
2, child 3, translation 4, rotation 5; ...).
"""

from __future__ import annotations

import functools
import struct
from typing import Iterable, Sequence

from replay.foxglove import _wire
from replay.scene import Box, Cylinder, Frame, Sphere

# tag bytes: (field number << 3) | wire type (0 varint, 1 fixed64, 2 length-delimited)
_VEC3 = struct.Struct("<BdBdBd")  # x 1, y 2, z 3 (foxglove.Vector3)
_QUAT = struct.Struct("<BdBdBdBd")  # x 1, y 2, z 3, w 4 (foxglove.Quaternion, foxglove.Color)
# FrameTransform's translation (4) and rotation (5) with their lengths
_TRANSFORM = struct.Struct("<BBBdBdBdBBBdBdBdBd")
_POSE = struct.Struct("<BBBBBdBdBdBBBdBdBdBd")  # Pose: position 1, orientation 2, in its field 1
_JOINT = struct.Struct("<BdBdBd")  # JointState position 2, velocity 3, effort 5
_DOUBLE = struct.Struct("<Bd")
_IDENTITY = (0.0, 0.0, 0.0, 1.0)


def varint(n: int) -> bytes:
    """A non-negative integer as a protobuf varint."""
    if n < 0x80:
        return bytes((n,))
    out = bytearray()
    while n >= 0x80:
        out.append((n & 0x7F) | 0x80)
        n >>= 7
    out.append(n)
    return bytes(out)


def field(tag: int, data: bytes) -> bytes:
    """A length-delimited field (``tag`` = field number << 3 | 2)."""
    return bytes((tag,)) + varint(len(data)) + data


@functools.lru_cache(maxsize=1024)
def _text(tag: int, text: str) -> bytes:
    return field(tag, text.encode())


def _timestamp(t_ns: int) -> bytes:
    """A ``google.protobuf.Timestamp`` of ``t_ns`` as field 1 of its message (seconds 1 and
    nanos 2, each left out at 0 as the library does): the reference of :func:`timestamp`."""
    sec, nsec = divmod(t_ns, 1_000_000_000)
    body = (b"\x08" + varint(sec) if sec else b"") + (b"\x10" + varint(nsec) if nsec else b"")
    return b"\x0a" + bytes((len(body),)) + body


def _frame_transforms(frames: Iterable[Frame], ts: bytes) -> bytes:
    """The reference of :func:`frame_transforms`' compiled transforms (``ts``: a timestamp
    field)."""
    pack = _TRANSFORM.pack
    parts = []
    for f in frames:
        (x, y, z), (qx, qy, qz, qw) = f.position, f.orientation
        body = b"".join(
            (
                ts,
                _text(0x12, f.parent),
                _text(0x1A, f.child),
                pack(0x22, 27, 9, x, 17, y, 25, z, 0x2A, 36, 9, qx, 17, qy, 25, qz, 33, qw),
            )
        )
        parts.append(b"\x0a" + varint(len(body)) + body)
    return b"".join(parts)


# compiled (_wire.c; the references above and _joint_states below): ~20x cheaper a call
timestamp = _wire.timestamp


def frame_transforms(frames: Iterable[Frame], t_ns: int) -> bytes:
    """``foxglove.FrameTransforms``: each frame's pose in its parent at ``t_ns``."""
    return _wire.frame_transforms(frames, timestamp(t_ns))


def body_transforms(primitives: Iterable, parent: str, t_ns: int) -> bytes:
    """``foxglove.FrameTransforms`` of each primitive as a frame of its own name in ``parent``
    (a sphere unrotated): the transforms of :func:`frame_transforms` without making the frames
    (the messages' repeated fields concatenate). Compiled (``_wire.c``)."""
    return _wire.body_transforms(primitives, timestamp(t_ns) + _text(0x12, parent), Sphere)


def _body_transforms(primitives: Iterable, parent: str, t_ns: int) -> bytes:
    """The reference of :func:`body_transforms`' compiled transforms."""
    head = _timestamp(t_ns) + _text(0x12, parent)
    n_head = len(head) + 67  # + the translation and rotation fields
    pack = _TRANSFORM.pack
    parts: list[bytes] = []
    for p in primitives:
        child = _text(0x1A, p.name)
        (x, y, z) = p.position
        qx, qy, qz, qw = _IDENTITY if isinstance(p, Sphere) else p.orientation
        parts += (
            b"\x0a",
            varint(n_head + len(child)),
            head,
            child,
            pack(0x22, 27, 9, x, 17, y, 25, z, 0x2A, 36, 9, qx, 17, qy, 25, qz, 33, qw),
        )
    return b"".join(parts)


def _grey(albedo: float) -> float:
    """The albedo as a grey, lifted so that a black body still shows on a dark background."""
    return 0.25 + 0.75 * min(max(float(albedo), 0.0), 1.0)


# (kind, name, shape, albedo) -> (the entity's id and primitive field up to its pose, the
# primitive's fields after its pose): a scene's bodies keep their shape and colour from frame to
# frame, so only their poses are packed each time (keys compare by value: a size of -0.0 is
# written as the 0.0 seen first)
_SHAPES: dict[tuple, tuple[bytes, bytes]] = {}


def _shape_fields(p) -> tuple[bytes, bytes] | None:
    if isinstance(p, Box):
        key: tuple = (Box, p.name, tuple(p.size), p.albedo)
    elif isinstance(p, Sphere):
        key = (Sphere, p.name, p.radius, p.albedo)
    elif isinstance(p, Cylinder):
        key = (Cylinder, p.name, p.radius, p.length, p.albedo)
    else:
        return None
    fields = _SHAPES.get(key)
    if fields is None:
        if len(_SHAPES) > 4096:
            _SHAPES.clear()
        v = _grey(p.albedo)
        color = _QUAT.pack(9, v, 17, v, 25, v, 33, 1.0)
        vec3 = _VEC3.pack
        if isinstance(p, Box):  # cubes 8: size 2, color 3
            tag, sx, sy, sz = 0x42, *p.size
            tail = b"\x12\x1b" + vec3(9, sx, 17, sy, 25, sz) + b"\x1a\x24" + color
        elif isinstance(p, Sphere):  # spheres 9: size 2, color 3
            tag, d = 0x4A, 2.0 * p.radius
            tail = b"\x12\x1b" + vec3(9, d, 17, d, 25, d) + b"\x1a\x24" + color
        else:  # cylinders 10: size 2, bottom and top scale 3, 4, color 5; its axis body z
            tag, d = 0x52, 2.0 * p.radius
            tail = (
                b"\x12\x1b"
                + vec3(9, d, 17, d, 25, p.length)
                + _DOUBLE.pack(0x19, 1.0)
                + _DOUBLE.pack(0x21, 1.0)
                + b"\x2a\x24"
                + color
            )
        mid = _text(0x1A, p.name) + bytes((tag,)) + varint(69 + len(tail))  # + the pose
        fields = _SHAPES[key] = (mid, tail)
    return fields


def scene_update(primitives: Sequence, frame_id: str, t_ns: int) -> bytes:
    """``foxglove.SceneUpdate``: each box, sphere and cylinder as one entity (id = its name) of
    one primitive at its pose in ``frame_id``, grey by albedo (others are left out). Compiled
    (``_wire.c``), the shapes' fixed fields from :func:`_shape_fields`."""
    head = timestamp(t_ns) + _text(0x12, frame_id)
    return _wire.scene_update(primitives, head, _shape_fields, Sphere)


def _scene_update(primitives: Sequence, frame_id: str, t_ns: int) -> bytes:
    """The reference of :func:`scene_update`'s compiled entities."""
    head = _timestamp(t_ns) + _text(0x12, frame_id)
    n_head = len(head) + 69  # + the pose field
    pose = _POSE.pack
    parts: list[bytes] = []
    for p in primitives:
        fields = _shape_fields(p)
        if fields is None:
            continue
        mid, tail = fields
        (x, y, z) = p.position
        qx, qy, qz, qw = _IDENTITY if isinstance(p, Sphere) else p.orientation
        parts += (
            b"\x12",  # entities 2
            varint(n_head + len(mid) + len(tail)),
            head,
            mid,
            pose(0x0A, 67, 0x0A, 27, 9, x, 17, y, 25, z, 0x12, 36, 9, qx, 17, qy, 25, qz, 33, qw),
            tail,
        )
    return b"".join(parts)


def _joint_states(names, position, velocity, effort, ts: bytes) -> bytes:
    """The reference of :func:`joint_states`' compiled message (``ts``: a timestamp field)."""
    pack = _JOINT.pack
    parts = [ts]
    for n, q, v, e in zip(names, position, velocity, effort):
        joint = _text(0x0A, n) + pack(0x11, q, 0x19, v, 0x29, e)
        parts.append(b"\x12" + varint(len(joint)) + joint)
    return b"".join(parts)


def joint_states(names, position, velocity, effort, t_ns: int) -> bytes:
    """``foxglove.JointStates``: each joint's name, position, velocity and effort."""
    return _wire.joint_states(names, position, velocity, effort, timestamp(t_ns))


def log_line(level: int, message: str, name: str, t_ns: int) -> bytes:
    """``foxglove.Log``: timestamp 1, level 2 (an enum: left out at 0), message 3 and name 4
    (left out when empty), as the library writes them."""
    return b"".join(
        (
            timestamp(t_ns),
            b"\x10" + varint(level) if level else b"",
            field(0x1A, message.encode()) if message else b"",
            _text(0x22, name) if name else b"",
        )
    )


@functools.lru_cache(maxsize=256)
def image_tail(frame_id: str, fmt: str) -> bytes:
    """The fields of a ``foxglove.CompressedImage`` after its data (field 2): format 3, frame
    id 4; a camera's message is ``replay.foxglove.png.png_message(timestamp(t_ns),
    image_tail(frame_id, "png"), image)``."""
    return _text(0x1A, fmt) + _text(0x22, frame_id)
