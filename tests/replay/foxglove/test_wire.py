"""Foxglove's messages in the wire format (replay/foxglove/wire.py) against the protobuf classes
filled attribute by attribute (the way topics.py wrote them before, kept here as the reference):
seeded random frames, primitives, joints and images decode to equal messages."""

from __future__ import annotations

import math

import numpy as np
import pytest
from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate

from replay.foxglove import wire
from replay.foxglove.png import encode_png, png_message
from replay.scene import Box, Cylinder, Frame, Sphere


def _stamp(msg, t_ns):
    msg.seconds, msg.nanos = divmod(t_ns, 1_000_000_000)


def reference_transforms(frames, t_ns):
    msg = FrameTransforms()
    for f in frames:
        x = msg.transforms.add()
        _stamp(x.timestamp, t_ns)
        x.parent_frame_id, x.child_frame_id = f.parent, f.child
        x.translation.x, x.translation.y, x.translation.z = f.position
        x.rotation.x, x.rotation.y, x.rotation.z, x.rotation.w = f.orientation
    return msg


def reference_scene(primitives, t_ns):
    msg = SceneUpdate()
    for p in primitives:
        e = msg.entities.add()
        _stamp(e.timestamp, t_ns)
        e.frame_id, e.id = "world", p.name
        if isinstance(p, Box):
            shape = e.cubes.add()
            shape.size.x, shape.size.y, shape.size.z = p.size
            q = p.orientation
        elif isinstance(p, Sphere):
            shape = e.spheres.add()
            shape.size.x = shape.size.y = shape.size.z = 2.0 * p.radius
            q = (0.0, 0.0, 0.0, 1.0)
        else:
            shape = e.cylinders.add()
            shape.size.x = shape.size.y = 2.0 * p.radius
            shape.size.z = p.length
            shape.bottom_scale = shape.top_scale = 1.0
            q = p.orientation
        pos, rot = shape.pose.position, shape.pose.orientation
        pos.x, pos.y, pos.z = p.position
        rot.x, rot.y, rot.z, rot.w = q
        v = 0.25 + 0.75 * min(max(float(p.albedo), 0.0), 1.0)
        shape.color.r = shape.color.g = shape.color.b = v
        shape.color.a = 1.0
    return msg


def body_frame(p):
    """A primitive as a frame of its own name in world (a sphere unrotated)."""
    q = (0.0, 0.0, 0.0, 1.0) if isinstance(p, Sphere) else p.orientation
    return Frame("world", p.name, p.position, q)


def reference_joints(names, q, v, e, t_ns):
    msg = JointStates()
    _stamp(msg.timestamp, t_ns)
    for n, a, b, c in zip(names, q, v, e):
        j = msg.joints.add()
        j.name, j.position, j.velocity, j.effort = n, a, b, c
    return msg


def compressed_image(t_ns, frame_id, data):
    """A CompressedImage of given bytes from the wire module's parts (png_message's layout)."""
    head = wire.timestamp(t_ns) + b"\x12" + wire.varint(len(data))
    return head + data + wire.image_tail(frame_id, "png")


def _value(rng):
    """A double as the plants give them: often exactly 0 or -0, sometimes huge or tiny."""
    r = rng.random()
    if r < 0.2:
        return 0.0
    if r < 0.25:
        return -0.0
    return float(rng.normal() * 10.0 ** rng.integers(-8, 8))


def _t_ns(rng):
    return int(rng.choice([0, 1_000_000_000, int(rng.integers(0, 10**12))]))


def _name(rng):
    return "".join(rng.choice(list("abcxyz_/0é"), size=int(rng.integers(0, 12))))


def _quat(rng):
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    return tuple(float(x) for x in q) if rng.random() < 0.7 else (0.0, 0.0, 0.0, 1.0)


def _primitives(rng, names=None):
    """Random boxes, spheres and cylinders (named b0, s1, ... or ``names(rng)``)."""
    prims = []
    for i in range(int(rng.integers(0, 8))):
        pos, q, albedo = tuple(_value(rng) for _ in range(3)), _quat(rng), rng.uniform(-1, 2)
        kind = rng.integers(0, 3)
        name = f"{'bsc'[kind]}{i}" if names is None else names(rng)
        if kind == 0:
            prims.append(Box(name, pos, q, tuple(abs(_value(rng)) for _ in range(3)), albedo))
        elif kind == 1:
            prims.append(Sphere(name, pos, abs(_value(rng)), albedo=albedo))
        else:
            prims.append(Cylinder(name, pos, q, abs(_value(rng)), 0.3, albedo=albedo))
    return prims


def test_wire_messages_decode_to_the_protobuf_classes_own():
    rng = np.random.default_rng(31)
    n, agree = 200, 0
    for _ in range(n):
        t = _t_ns(rng)
        frames = [
            Frame(_name(rng), _name(rng), tuple(_value(rng) for _ in range(3)), _quat(rng))
            for _ in range(int(rng.integers(0, 20)))
        ]
        prims = _primitives(rng)
        joints = [[_name(rng) for _ in range(7)]] + [[_value(rng) for _ in range(7)]] * 3
        data = bytes(rng.integers(0, 256, size=int(rng.integers(0, 300)), dtype=np.uint8))
        pixels = rng.integers(0, 256, size=(int(rng.integers(1, 40)), 7)).astype(np.uint8)
        png_image = CompressedImage()
        _stamp(png_image.timestamp, t)
        png_image.frame_id, png_image.data, png_image.format = "x", encode_png(pixels), "png"
        image = CompressedImage()
        _stamp(image.timestamp, t)
        image.frame_id, image.data, image.format = _name(rng), data, "png"
        ok = (
            FrameTransforms.FromString(wire.frame_transforms(frames, t))
            == reference_transforms(frames, t)
            and SceneUpdate.FromString(wire.scene_update(prims, "world", t))
            == reference_scene(prims, t)
            and FrameTransforms.FromString(wire.body_transforms(prims, "world", t))
            == reference_transforms([body_frame(p) for p in prims], t)
            and JointStates.FromString(wire.joint_states(*joints, t))
            == reference_joints(*joints, t)
            and CompressedImage.FromString(compressed_image(t, image.frame_id, data)) == image
            and CompressedImage.FromString(
                png_message(wire.timestamp(t), wire.image_tail("x", "png"), pixels)
            )
            == png_image
        )
        agree += ok
    print(f"wire messages equal to the protobuf classes' for {agree}/{n} random inputs")
    assert agree == n


def test_wire_doubles_are_exact_and_the_bytes_fixed_by_the_values():
    f = [Frame("world", "a", (math.pi, -0.0, 1e-300), (0.0, 0.0, 0.0, 1.0))]
    msg = FrameTransforms.FromString(wire.frame_transforms(f, 5))
    tr = msg.transforms[0].translation
    assert tr.x == math.pi and math.copysign(1.0, tr.y) == -1.0 and tr.z == 1e-300
    assert wire.frame_transforms(f, 5) == wire.frame_transforms(list(f), 5)
    assert wire.varint(300) == b"\xac\x02" and wire.varint(0) == b"\x00"


def test_compiled_wire_parts_equal_their_python_references():
    """_wire.c's timestamp, frame transforms and joint states: the bytes of wire.py's Python
    references on seeded random frames (long names: multi-byte varints), joints and times."""
    rng = np.random.default_rng(31)
    n, equal = 300, 0
    for i in range(n):
        t_ns = _t_ns(rng) if i % 3 else int(rng.integers(0, 2**62))
        ts = wire._timestamp(t_ns)
        frames = [
            Frame(
                _name(rng) * int(rng.integers(1, 30)),
                _name(rng),
                tuple(_value(rng) for _ in range(3)),
                _quat(rng),
            )
            for _ in range(int(rng.integers(0, 20)))
        ]
        k = int(rng.integers(0, 9))
        names = [_name(rng) * int(rng.integers(1, 20)) for _ in range(k)]
        q, v, e = (
            np.array([_value(rng) for _ in range(k + int(rng.integers(0, 2)))]) for _ in "qve"
        )
        prims = _primitives(rng, names=lambda rng: _name(rng) * int(rng.integers(1, 20)))
        parent = _name(rng)
        same = (
            wire.timestamp(t_ns) == ts
            and wire.frame_transforms(frames, t_ns) == wire._frame_transforms(frames, ts)
            and wire.frame_transforms(iter(frames), t_ns) == wire._frame_transforms(frames, ts)
            and wire.joint_states(names, q, v, e, t_ns) == wire._joint_states(names, q, v, e, ts)
            and wire.joint_states(names, list(q), tuple(v), e, t_ns)
            == wire._joint_states(names, q, v, e, ts)
            and wire.body_transforms(prims, parent, t_ns)
            == wire._body_transforms(prims, parent, t_ns)
            and wire.scene_update(prims, parent, t_ns) == wire._scene_update(prims, parent, t_ns)
        )
        equal += same
    print(f"compiled wire parts = Python references for {equal}/{n} random messages")
    assert equal == n
    with pytest.raises(TypeError):
        wire.frame_transforms([Frame("a", 1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))], 0)
    with pytest.raises(ValueError):
        wire.frame_transforms([Frame("a", "b", (0.0, 0.0), (0.0, 0.0, 0.0, 1.0))], 0)


def test_log_lines_are_the_protobuf_classes_bytes():
    from foxglove_schemas_protobuf.Log_pb2 import Log

    rng = np.random.default_rng(32)
    n = 300
    for _ in range(n):
        t_ns, level = _t_ns(rng), int(rng.integers(0, 6))
        message = _name(rng) * int(rng.integers(0, 30))
        name = "paper-replay" if rng.random() < 0.8 else _name(rng)
        msg = Log(level=level, message=message, name=name)
        _stamp(msg.timestamp, t_ns)
        msg.timestamp.SetInParent()  # (set, even when 0 s 0 ns, as the topic's messages are)
        assert wire.log_line(level, message, name, t_ns) == msg.SerializeToString(
            deterministic=True
        )
    print(f"/log lines = the protobuf class's bytes for {n}/{n} random lines")
