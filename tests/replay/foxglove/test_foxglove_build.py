"""The 3-D topics' messages, built and encoded by foxglove-sdk (``foxglove.messages``), are byte
for byte what the ``foxglove_schemas_protobuf`` constructors make of the same scene (the
reference, written out here), over seeded random scenes: zero and non-zero poses, every
primitive kind, numpy and Python floats, t = 0."""

from __future__ import annotations

import numpy as np
import pytest
from foxglove_schemas_protobuf.Color_pb2 import Color
from foxglove_schemas_protobuf.CubePrimitive_pb2 import CubePrimitive
from foxglove_schemas_protobuf.CylinderPrimitive_pb2 import CylinderPrimitive
from foxglove_schemas_protobuf.FrameTransform_pb2 import FrameTransform
from foxglove_schemas_protobuf.FrameTransforms_pb2 import FrameTransforms
from foxglove_schemas_protobuf.JointState_pb2 import JointState
from foxglove_schemas_protobuf.JointStates_pb2 import JointStates
from foxglove_schemas_protobuf.Pose_pb2 import Pose
from foxglove_schemas_protobuf.Quaternion_pb2 import Quaternion
from foxglove_schemas_protobuf.SceneEntity_pb2 import SceneEntity
from foxglove_schemas_protobuf.SceneUpdate_pb2 import SceneUpdate
from foxglove_schemas_protobuf.SpherePrimitive_pb2 import SpherePrimitive
from foxglove_schemas_protobuf.Vector3_pb2 import Vector3
from google.protobuf.timestamp_pb2 import Timestamp

from replay.foxglove.topics import frame_transforms, joint_states, scene_update
from replay.scene import Box, Cylinder, Frame, Sphere


def _ts(t_ns: int) -> Timestamp:
    sec, nsec = divmod(t_ns, 1_000_000_000)
    return Timestamp(seconds=sec, nanos=nsec)


def _v(x, y, z) -> Vector3:
    return Vector3(x=x, y=y, z=z)


def _q(x, y, z, w) -> Quaternion:
    return Quaternion(x=x, y=y, z=z, w=w)


def _grey(albedo: float) -> Color:
    v = 0.25 + 0.75 * min(max(float(albedo), 0.0), 1.0)
    return Color(r=v, g=v, b=v, a=1.0)


def ref_transforms(frames, t_ns, bodies, parent="world") -> bytes:
    ts = _ts(t_ns)
    out = [
        FrameTransform(
            timestamp=ts,
            parent_frame_id=parent,
            child_frame_id=p.name,
            translation=_v(*p.position),
            rotation=_q(*((0.0, 0.0, 0.0, 1.0) if isinstance(p, Sphere) else p.orientation)),
        )
        for p in bodies
    ]
    out += [
        FrameTransform(
            timestamp=ts,
            parent_frame_id=f.parent,
            child_frame_id=f.child,
            translation=_v(*f.position),
            rotation=_q(*f.orientation),
        )
        for f in frames
    ]
    return FrameTransforms(transforms=out).SerializeToString()


def ref_scene(primitives, frame_id, t_ns) -> bytes:
    ts, entities = _ts(t_ns), []
    for p in primitives:
        if not isinstance(p, (Sphere, Box, Cylinder)):
            continue
        e = SceneEntity(timestamp=ts, frame_id=frame_id, id=p.name)
        c = _grey(p.albedo)
        if isinstance(p, Sphere):
            d = 2.0 * p.radius
            pose = Pose(position=_v(*p.position), orientation=Quaternion(w=1.0))
            e.spheres.append(SpherePrimitive(pose=pose, size=_v(d, d, d), color=c))
        else:
            pose = Pose(position=_v(*p.position), orientation=_q(*p.orientation))
            if isinstance(p, Box):
                e.cubes.append(CubePrimitive(pose=pose, size=_v(*p.size), color=c))
            else:
                d = 2.0 * p.radius
                e.cylinders.append(
                    CylinderPrimitive(
                        pose=pose,
                        size=_v(d, d, p.length),
                        bottom_scale=1.0,
                        top_scale=1.0,
                        color=c,
                    )
                )
        entities.append(e)
    return SceneUpdate(entities=entities).SerializeToString()


def ref_joints(names, q, v, e, t_ns) -> bytes:
    joints = [
        JointState(name=n, position=a, velocity=b, effort=c) for n, a, b, c in zip(names, q, v, e)
    ]
    return JointStates(timestamp=_ts(t_ns), joints=joints).SerializeToString()


def _num(rng, n):
    """n numbers: zeros, negatives, numpy or Python floats."""
    kind = rng.integers(3)
    if kind == 0:
        return tuple(0.0 for _ in range(n))
    x = rng.normal(size=n)
    return tuple(x) if kind == 1 else tuple(float(v) for v in x)


def _scene(rng):
    prims = []
    for i in range(int(rng.integers(0, 6))):
        k = rng.integers(4)
        pos, quat = _num(rng, 3), _num(rng, 4)
        albedo = float(rng.uniform(-0.5, 1.5))
        if k == 0:
            prims.append(Sphere(f"s{i}", pos, float(rng.uniform(0, 1)), albedo))
        elif k == 1:
            prims.append(Box(f"b{i}", pos, quat, _num(rng, 3), albedo))
        elif k == 2:
            prims.append(Cylinder(f"c{i}", pos, quat, float(rng.uniform(0, 1)), 0.3, albedo))
        else:
            prims.append(f"not a primitive {i}")  # left out of /scene
    return prims


@pytest.mark.parametrize("seed", range(40))
def test_sdk_messages_equal_the_generated_classes_ones(seed):
    rng = np.random.default_rng(seed)
    t_ns = 0 if seed % 5 == 0 else int(rng.integers(0, 10**11))
    prims = _scene(rng)
    bodies = [p for p in prims if not isinstance(p, str)]
    frames = [
        Frame(f"p{i}", f"c{i}", _num(rng, 3), _num(rng, 4)) for i in range(int(rng.integers(4)))
    ]
    assert frame_transforms(frames, t_ns, bodies) == ref_transforms(frames, t_ns, bodies)
    assert scene_update(prims, "world", t_ns) == ref_scene(prims, "world", t_ns)
    n = int(rng.integers(0, 5))
    names = [f"j{i}" for i in range(n)]
    q, v, e = _num(rng, n), _num(rng, n), _num(rng, n)
    assert joint_states(names, q, v, e, t_ns) == ref_joints(names, q, v, e, t_ns)


def test_the_reference_tells_a_wrong_pose():
    """(The comparison above can fail: a moved box is a different message.)"""
    box = Box("b", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0))
    moved = Box("b", (0.0, 0.0, 1e-9), (0.0, 0.0, 0.0, 1.0), (1.0, 1.0, 1.0))
    assert scene_update([box], "world", 0) != ref_scene([moved], "world", 0)


def test_a_negative_zero_in_a_pose_reads_back_as_zero():
    """The one difference from the generated classes: prost leaves a -0.0 Vector3 or
    Quaternion field out as a default, so it decodes as 0.0 (the same number)."""
    frame = Frame("world", "a", (-0.0, 1.0, 2.0), (0.0, 0.0, -0.0, 1.0))
    back = FrameTransforms.FromString(frame_transforms([frame], 0)).transforms[0]
    assert (back.translation.x, back.translation.y, back.rotation.z) == (0.0, 1.0, 0.0)
    assert frame_transforms([frame], 0) != ref_transforms([frame], 0, [])
