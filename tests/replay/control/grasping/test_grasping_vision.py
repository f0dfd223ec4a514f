"""The grasping method's vision (replay/control/grasping/self_window.py, features.py,
recognition.py) and head loop (eq. 1), on images rendered by the vision chip sensor: Self
Windowing including what happens when the image moves more than a pixel a frame, moments and
shape, x_o from the constraint plane, and the head's tracking."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from replay.log.reader import LogReader
from replay.resources import scenario_dir
from replay.runner import Runner
from replay.scenario import load_scenario

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from grasp_rig import rig  # noqa: E402

from plants.arm_rig.head import HeadServo  # noqa: E402
from replay.control.grasping.features import blob, blob_rows  # noqa: E402
from replay.control.grasping.head_tracking import HeadParams, HeadTrackingTask  # noqa: E402
from replay.control.grasping.recognition import (
    RecognitionParams,
    RecognitionTask,  # noqa: E402
    shape_of,
)
from replay.control.grasping.self_window import track_rows  # noqa: E402
from replay.messages import (
    TOPIC_GRASP_OBJECT,
    TOPIC_HEAD_ENCODERS,
    TOPIC_VISION_CHIP,
    JointState,
    pack_rows,
    unpack_rows,
)  # noqa: E402
from replay.robot.head import camera_pose, look_angles  # noqa: E402
from replay.scene import Box, Scene, Sphere  # noqa: E402
from replay.sensors.vision_chip import VisionChipParams, VisionChipSensor  # noqa: E402

from tests.replay.control.grasping.oracles import (  # noqa: E402
    NumpyCamera,
    dilate4,
    meet_plane,
    self_window,
    track,
)

FOV = math.radians(12.0)


@pytest.fixture(scope="module")
def spec():
    plant = rig()
    s = plant.spec()
    plant.close()
    return s


def chip_sensor(**kw):
    return VisionChipSensor(VisionChipParams(fov=FOV, **kw), rng=np.random.default_rng(0))


def head_scene(spec, prim, angles) -> Scene:
    R, c = camera_pose(spec.head, *angles)
    return Scene(
        [prim],
        readings={
            "head": {
                "name": ["pan", "tilt"],
                "position": list(angles),
                "velocity": [0.0, 0.0],
                "camera_rotation": R,
                "camera_position": c,
            }
        },
    )


def bar(x0: int, w: int = 4, h: int = 3) -> np.ndarray:
    img = np.zeros((16, 16), bool)
    img[6 : 6 + h, max(x0, 0) : max(x0 + w, 0)] = True
    return img


def test_dilate4_grows_by_the_4_neighbourhood():
    img = np.zeros((5, 5), bool)
    img[2, 2] = True
    d = dilate4(img)
    assert d.sum() == 5 and d[1, 2] and d[3, 2] and d[2, 1] and d[2, 3] and not d[1, 1]


def test_pack_and_unpack_rows_round_trip():
    img = np.random.default_rng(1).random((16, 16)) > 0.5
    np.testing.assert_array_equal(unpack_rows(pack_rows(img), 16), img)


def frames_until_lost(speed: int, width: int = 4, frames: int = 12) -> int | None:
    target = bar(2, width)
    for k in range(1, frames):
        target = self_window(target, bar(2 + speed * k, width))
        if not target.any():
            return k
    return None


def test_self_window_keeps_a_target_that_moves_a_pixel_a_frame():
    target = bar(2)
    for k in range(1, 11):
        target = self_window(target, bar(2 + k))
        assert target.sum() == 12  # whole: 4 x 3 pixels every frame


@pytest.mark.parametrize("speed", [2, 3, 5])
def test_self_window_loses_a_faster_target_after_width_over_speed_minus_one_frames(speed):
    """Moving s > 1 px a frame, the target keeps only what lies within a pixel of the old one:
    it loses s - 1 columns a frame and is gone after ceil(width / (s - 1)) frames
    (docs/grasping.md)."""
    width = 4
    assert frames_until_lost(speed, width) == math.ceil(width / (speed - 1))
    assert frames_until_lost(1, width) is None


def test_track_reacquires_from_the_whole_image():
    img = bar(5)
    target, again = track(None, img)
    assert again and target.sum() == img.sum()
    target, again = track(np.zeros_like(img), img)
    assert again


def random_blobs(rng, n: int, w: int = 16, h: int = 16):
    """Seeded random binary images: noise, rectangles and discs (some cut by the border), and
    a target image near each (a moved copy, for Self Windowing)."""
    out = []
    v, u = np.mgrid[0:h, 0:w]
    for i in range(n):
        kind = i % 3
        if kind == 0:
            img = rng.random((h, w)) < rng.uniform(0.05, 0.6)
        elif kind == 1:
            c, s = math.cos(rng.uniform(0, math.pi)), math.sin(rng.uniform(0, math.pi))
            du, dv = u - rng.uniform(-2, w + 1), v - rng.uniform(-2, h + 1)
            img = (abs(du * c + dv * s) < rng.uniform(0.5, 6)) & (
                abs(-du * s + dv * c) < rng.uniform(0.5, 4)
            )
        else:
            img = (u - rng.uniform(0, w)) ** 2 + (v - rng.uniform(0, h)) ** 2 < rng.uniform(1, 30)
        prev = np.roll(img, (int(rng.integers(-2, 3)), int(rng.integers(-2, 3))), axis=(0, 1))
        out.append((img, prev & (rng.random((h, w)) < 0.9)))
    return out


def test_packed_rows_self_windowing_and_features_equal_the_array_versions():
    """``track_rows`` and ``blob_rows`` (the task's per-frame path, on the chip's packed rows)
    against ``track`` and ``blob`` (arrays, the reference) over seeded random images: the same
    target bits and area, border flag, and features within 1e-9."""
    rng = np.random.default_rng(12)
    cases = random_blobs(rng, 300) + random_blobs(rng, 30, w=9, h=12)
    ok = 0
    for img, prev in cases:
        h, w = img.shape
        rows, prev_rows = pack_rows(img), pack_rows(prev)
        target, again = track(prev, img)
        target_rows, again_rows = track_rows(prev_rows, rows, w)
        good = again == again_rows and target_rows == pack_rows(target)
        for fill in (True, False):
            a, b = blob(target, fill=fill), blob_rows(target_rows, w, fill=fill)
            if a is None or b is None:
                good &= a is None and b is None
                continue
            good &= (a.area, a.touches_border) == (b.area, b.touches_border)
            fa, fb = (
                [a.u, a.v, a.elongation, a.length, a.width],
                [b.u, b.v, b.elongation, b.length, b.width],
            )
            good &= bool(np.allclose(fa, fb, rtol=0.0, atol=1e-9))
            # phi is defined modulo pi (an isotropic blob's is arbitrary: its elongation is 1)
            dphi = math.remainder(a.phi - b.phi, math.pi)
            good &= abs(dphi) < 1e-9 or a.elongation < 1.0 + 1e-6
            good &= (math.isnan(a.fill) and math.isnan(b.fill)) or abs(a.fill - b.fill) < 1e-9
        ok += bool(good)
    print(f"packed-row vision: {ok}/{len(cases)} random images agree with the array versions")
    assert ok == len(cases)


def test_moments_give_centre_and_rotation():
    img = np.zeros((16, 16), bool)
    img[5:8, 3:11] = True  # 8 x 3, along u
    b = blob(img)
    assert (b.u, b.v) == pytest.approx((6.5, 6.0))
    assert b.phi == pytest.approx(0.0, abs=1e-12)
    assert b.fill == pytest.approx(1.0) and b.elongation > 2.0
    assert blob(img.T).phi == pytest.approx(math.pi / 2, abs=1e-12)


def test_shape_from_chip_images_over_random_poses(spec):
    """Seeded randomised: boxes and balls at random places on the plane (within +-4 cm of the
    view's centre) and box rolls, seen by the 16 x 16 chip; reports the recognition rate."""
    rng = np.random.default_rng(7)
    sensor = chip_sensor()
    centre = np.array([0.75, 0.0, 0.55])
    angles = look_angles(spec.head, centre)
    params = RecognitionParams(fov=FOV)
    right, n = 0, 0
    for kind in ("rectangle", "circle"):
        for _ in range(30):
            p = centre + np.array([0.0, *rng.uniform(-0.04, 0.04, 2)])
            if kind == "rectangle":
                roll = rng.uniform(-0.5, 0.5)
                prim = Box(
                    "box",
                    tuple(p),
                    (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2)),
                    (0.05, 0.10, 0.05),
                    0.9,
                )
            else:
                prim = Sphere("ball", tuple(p), 0.035, 0.9)
            b = blob(sensor.image(head_scene(spec, prim, angles)))
            right += shape_of(b, params) == kind
            n += 1
    rate = right / n
    print(f"shape recognised in {right}/{n} views ({rate:.0%})")
    assert rate >= 0.9


def recognise(spec, prim, angles, frames=1):
    task = RecognitionTask(RecognitionParams(fov=FOV, shape_frames=1), spec=spec)
    sensor = chip_sensor()
    out = None
    for k in range(frames):
        t = k * 1e-3
        chip = sensor.measure(t, head_scene(spec, prim, angles))
        enc = JointState(t, ["pan", "tilt"], list(angles), [0.0, 0.0], [0.0, 0.0])
        task.update(t, [(TOPIC_HEAD_ENCODERS, enc), (TOPIC_VISION_CHIP, chip)])
        out = task.telemetry(t)[TOPIC_GRASP_OBJECT]
    return task, out


def test_position_on_the_constraint_plane_from_one_chip_image(spec):
    """A ball on the plane anywhere in the view: x_o from the 16 x 16 image within 5 mm (a pixel
    is ~11 mm there); the box's roll within 0.1 rad."""
    rng = np.random.default_rng(3)
    centre = np.array([0.75, 0.0, 0.55])
    angles = look_angles(spec.head, centre)
    errs = []
    for _ in range(20):
        p = centre + np.array([0.0, *rng.uniform(-0.03, 0.03, 2)])
        _, out = recognise(spec, Sphere("ball", tuple(p), 0.035, 0.9), angles)
        assert out.found and out.shape == "circle"
        errs.append(np.linalg.norm(np.asarray(out.position) - p))
    print(
        f"ball position error: median {np.median(errs) * 1e3:.1f} mm, "
        f"max {np.max(errs) * 1e3:.1f} mm"
    )
    assert max(errs) < 0.005
    roll = 0.3
    box = Box(
        "box",
        tuple(centre),
        (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2)),
        (0.05, 0.10, 0.05),
        0.9,
    )
    _, out = recognise(spec, box, angles)
    assert out.shape == "rectangle"
    assert out.roll == pytest.approx(roll, abs=0.1)


def test_recognised_pose_and_jacobian_equal_the_numpy_camera_over_random_views(spec):
    """The task's x_o, roll, size and image Jacobian (its plane geometry) against the
    NumPy ``Camera`` (ray, meet_plane, jacobian) at the target's own moments, for seeded random
    boxes (rolled, off centre) and head angles off the line of sight: equal within 1e-9."""
    rng = np.random.default_rng(15)
    cam = NumpyCamera(spec.head, FOV, 16, 16)
    centre = np.array([0.75, 0.0, 0.55])
    ok, n = 0, 40
    for _ in range(n):
        p = centre + np.array([0.0, *rng.uniform(-0.03, 0.03, 2)])
        roll = float(rng.uniform(-1.0, 1.0))
        box = Box(
            "box",
            tuple(p),
            (math.sin(roll / 2), 0.0, 0.0, math.cos(roll / 2)),
            (0.05, 0.10, 0.05),
            0.9,
        )
        angles = tuple(np.add(look_angles(spec.head, centre), rng.uniform(-0.02, 0.02, 2)))
        task, out = recognise(spec, box, angles)
        task_b = blob_rows(task._target, 16)  # the target the task measured
        pose = camera_pose(spec.head, *angles)
        o, d = cam.ray(angles, (task_b.u, task_b.v), pose)
        X = meet_plane(o, d, task.plane_point, task.pn)
        o2, d2 = cam.ray(
            angles, (task_b.u + math.cos(task_b.phi), task_b.v + math.sin(task_b.phi)), pose
        )
        e = meet_plane(o2, d2, task.plane_point, task.pn) - X
        axis = math.atan2(float(e @ task.pv), float(e @ task.pu))
        J = cam.jacobian(angles, X, pose)
        scale = float(np.linalg.norm(X - o)) / cam.f
        good = out.found and np.allclose(out.position, X, rtol=0.0, atol=1e-9)
        good &= np.allclose(out.jacobian, J, rtol=1e-9, atol=1e-9)
        good &= np.allclose(out.size, [task_b.length * scale, task_b.width * scale], atol=1e-9)
        good &= out.roll is None or abs(math.remainder(out.roll - axis, math.pi)) < 1e-9
        ok += bool(good)
    print(f"recognised pose and Jacobian: {ok}/{n} random views equal the NumPy camera's")
    assert ok == n


def test_head_loop_centres_the_target(spec):
    """Eq. 1 with the head model's image Jacobian: a ball 4 cm off the line of sight is brought
    to the image centre by the head's servo within 0.15 s, no prediction involved."""
    centre = np.array([0.75, 0.0, 0.55])
    prim = Sphere("ball", (0.75, 0.04, 0.58), 0.035, 0.9)
    angles = np.array(look_angles(spec.head, centre))
    servo = HeadServo(spec.head, 300.0, 1e-3, angles)
    rec = RecognitionTask(RecognitionParams(fov=FOV), spec=spec)
    head = HeadTrackingTask(HeadParams(), spec=spec)
    sensor = chip_sensor()
    err = None
    for k in range(150):
        t = k * 1e-3
        chip = sensor.measure(t, head_scene(spec, prim, servo.q))
        enc = JointState(t, ["pan", "tilt"], servo.q.tolist(), servo.qd.tolist(), [0.0, 0.0])
        rec.update(t, [(TOPIC_HEAD_ENCODERS, enc), (TOPIC_VISION_CHIP, chip)])
        obj = rec.telemetry(t)[TOPIC_GRASP_OBJECT]
        cmd = head.update(t, [(TOPIC_GRASP_OBJECT, obj), (TOPIC_HEAD_ENCODERS, enc)])
        servo.set_command(cmd.head)
        servo.step()
        err = np.asarray(obj.xi) - 7.5
    assert np.linalg.norm(err) < 0.5


def test_image_jacobian_is_the_head_models(spec):
    cam = NumpyCamera(spec.head, FOV, 16, 16)
    X = np.array([0.75, 0.03, 0.52])
    a = np.array(look_angles(spec.head, X)) + [0.02, -0.03]
    J = cam.jacobian(a, X)
    h = 1e-6
    num = np.column_stack(
        [
            (cam.project(a + e, X) - cam.project(a - e, X)) / (2 * h)
            for e in (np.array([h, 0.0]), np.array([0.0, h]))
        ]
    )
    np.testing.assert_allclose(J, num, rtol=1e-5, atol=1e-4)


def test_a_chip_wider_than_63_px_runs_the_grasp_method(tmp_path):
    """Packed rows wider than 63 px (it was an OverflowError in the recognition task: rows
    unpacked as int64)."""
    sc = load_scenario(
        scenario_dir() / "grasp_hexahedron.yaml",
        sets=[
            "sensors.chip.params.width=80",
            "sensors.chip.params.height=70",
            "timing.duration=0.05",
        ],
    )
    result = Runner(sc).run(tmp_path / "wide.mcap")
    assert result.stopped_by != "error", result.error
    chips = [m.data for m in LogReader(tmp_path / "wide.mcap").messages("/vision/chip")]
    assert len(chips) == 50 and {c["width"] for c in chips} == {80}
    assert max(c["count"] for c in chips) > 0  # the object is seen


@pytest.mark.parametrize("latency_ms", [1, 20, 33])
def test_a_frame_a_chip_latency_old_finds_the_head_angles_it_was_taken_at(spec, latency_ms):
    """The recognition ticks every T with the T 1 kHz head readings since its last tick and a
    frame taken T ago (sweeps/grasp_loops.yaml): it finds that frame's angles (a fixed 16
    readings kept found none beyond 16 ms, and every frame was dropped), and keeps no more
    readings than it needs."""
    centre = (0.75, 0.0, 0.55)
    angles = look_angles(spec.head, np.array(centre))
    task = RecognitionTask(RecognitionParams(fov=FOV, shape_frames=1), spec=spec)
    sensor = chip_sensor()
    ball = Sphere("ball", centre, 0.035, 0.9)
    T = latency_ms * 1e-3
    frame = None
    for tick in range(1, 4):
        t = tick * T
        readings = [
            (
                TOPIC_HEAD_ENCODERS,
                JointState(t - i * 1e-3, ["pan", "tilt"], list(angles), [0.0] * 2, [0.0] * 2),
            )
            for i in range(latency_ms - 1, -1, -1)
        ]
        msgs = readings + ([(TOPIC_VISION_CHIP, frame)] if frame is not None else [])
        task.update(t, msgs)
        if frame is not None:
            out = task.telemetry(t)[TOPIC_GRASP_OBJECT]
            assert out.found and out.t == pytest.approx(t - T)
            assert len(task._head) <= latency_ms + 1
        frame = sensor.measure(t, head_scene(spec, ball, angles))
    assert task.frames == 2
