"""The Foxglove well-known topics (replay/foxglove): every message decodes with Foxglove's own
protobuf classes, /tf is a tree that reproduces the plant's tool pose, the images are the
cameras' frames, the URDF is the plant's, and the same run gives the same bytes."""

from __future__ import annotations

import shutil
from collections import Counter

import numpy as np
import pytest
import yaml
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage

from replay.foxglove.image import FrameBuffer, WindowedImage, grey, pixels, raw_image
from replay.foxglove.schemas import CLASSES, STRING_SCHEMA, decode, decode_string, message_dict
from replay.log import LogReader
from replay.messages import (
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_MOTION,
    TOPIC_EVENTS,
    TOPIC_JOINT_STATES,
    TOPIC_LOG,
    TOPIC_OBJECT_STATE,
    TOPIC_ROBOT_DESCRIPTION,
    TOPIC_SCENE,
    TOPIC_TF,
    TOPIC_VISION_CHIP,
    unpack_rows,
)
from replay.runner import Runner
from replay.scenario import load_scenario
from replay.spatial import quaternion_matrix

from conftest import ROOT


def run(tmp_path, name, sets, out="run.mcap"):
    sc = load_scenario(ROOT / "scenarios" / f"{name}.yaml", sets)
    return Runner(sc).run(tmp_path / out).path


@pytest.fixture(scope="module")
def catch_log(tmp_path_factory):
    return run(tmp_path_factory.mktemp("catch"), "catch_optimised", ["timing.duration=0.12"])


def decoded(reader: LogReader, topic: str):
    return [(m.t_ns, decode(m.schema, m.data)) for m in reader.raw(topic)]


def test_frame_buffer_gives_each_windowed_frame_whole():
    """Seeded windowed frames through one view's FrameBuffer (windows moving, shrinking, growing,
    the background and the frame size changing now and then) give the bytes of each frame made
    anew (WindowedImage.full): nothing of an earlier window is left behind."""
    rng = np.random.default_rng(29)
    buf = FrameBuffer()
    h, w, bg = 40, 50, 25
    for k in range(300):
        if rng.random() < 0.05:
            h, w = (int(x) for x in rng.integers(1, 60, size=2))
        if rng.random() < 0.05:
            bg = int(rng.integers(0, 256))
        x0, y0 = int(rng.integers(0, w)), int(rng.integers(0, h))
        x1, y1 = int(rng.integers(x0, w + 1)), int(rng.integers(y0, h + 1))
        px = rng.integers(0, 256, size=(y1 - y0, x1 - x0), dtype=np.uint8)
        win = WindowedImage(h, w, bg, (x0, y0, x1, y1), px)
        assert raw_image(win, "c", k, buf) == raw_image(win, "c", k), k
        assert np.array_equal(grey(win, buf), win.full())


def test_raw_images_round_trip_and_are_deterministic():
    """Seeded random frames (uint8, bool, windowed) as foxglove.RawImage: the pixels come back,
    the same frame gives the same bytes, what is not a grey image is refused."""
    rng = np.random.default_rng(13)
    n = 40
    for k in range(n):
        h, w = (int(x) for x in rng.integers(1, 200, size=2))
        img = rng.integers(0, 256, size=(h, w), dtype=np.uint8)
        if rng.random() < 0.5:  # mostly background, as the cameras' images are
            img = np.where(rng.random((h, w)) < 0.95, np.uint8(25), img).astype(np.uint8)
        data = raw_image(img, "cam/view", 1_000_000_007 * k)
        msg = RawImage.FromString(data)
        assert np.array_equal(pixels(msg), img) and msg.frame_id == "cam/view"
        assert (msg.timestamp.seconds, msg.timestamp.nanos) == divmod(1_000_000_007 * k, 10**9)
        assert raw_image(img.copy(), "cam/view", 1_000_000_007 * k) == data
        x0, y0 = int(rng.integers(0, w)), int(rng.integers(0, h))
        x1, y1 = int(rng.integers(x0 + 1, w + 1)), int(rng.integers(y0 + 1, h + 1))
        win = WindowedImage(h, w, 25, (x0, y0, x1, y1), img[y0:y1, x0:x1].copy())
        assert np.array_equal(pixels(RawImage.FromString(raw_image(win, "c", 0))), win.full())
    bits = rng.random((16, 16)) < 0.3
    back = pixels(RawImage.FromString(raw_image(bits, "chip", 0)))
    assert set(np.unique(back)) <= {0, 255} and np.array_equal(back == 255, bits)
    for bad in (np.zeros((4, 4, 3), np.uint8), np.zeros((0, 4), np.uint8), np.zeros((2, 2))):
        with pytest.raises(ValueError):
            grey(bad)
    with pytest.raises(ValueError):
        pixels(RawImage(width=4, height=4, step=4, encoding="mono8", data=b"\0" * 15))


def test_every_well_known_message_decodes(catch_log):
    r = LogReader(catch_log).check()
    assert r.status == "complete", r.problems
    schemas = Counter((m.topic, m.schema, m.encoding) for m in r.raw())
    topics = {t for t, _, _ in schemas}
    assert {TOPIC_TF, TOPIC_SCENE, TOPIC_JOINT_STATES, TOPIC_LOG, TOPIC_ROBOT_DESCRIPTION} <= topics
    assert {"/camera/stereo/cam0", "/camera/stereo/cam1"} <= topics
    for m in r.raw():
        if m.schema == STRING_SCHEMA:
            assert m.encoding == "cdr"
            decode_string(m.data)
            continue
        assert m.encoding == "protobuf" and m.schema in CLASSES
        msg = decode(m.schema, m.data)
        stamp = msg.timestamp if msg.DESCRIPTOR.fields_by_name.get("timestamp") else None
        if stamp is not None:  # the header stamp is the simulated log time
            assert stamp.seconds * 1_000_000_000 + stamp.nanos == m.t_ns
        assert message_dict(m.schema, m.data)  # the golden compare's view decodes too
    # the JSON contract topics are all still there, and read as before
    assert r.series(TOPIC_ARM_JOINT_STATE) and not r.problems
    assert r.topic_counts()[TOPIC_LOG] == r.topic_counts()[TOPIC_EVENTS]


def _chain(tf: dict, frame: str) -> tuple[np.ndarray, np.ndarray]:
    """World pose (R, p) of ``frame`` by composing /tf up to ``world``."""
    R, p = np.eye(3), np.zeros(3)
    seen = set()
    while frame != "world":
        assert frame not in seen, f"cycle at {frame}"
        seen.add(frame)
        parent, t, q = tf[frame]
        Rq = quaternion_matrix(q)
        R, p = Rq @ R, Rq @ p + t
        frame = parent
    return R, p


def test_tf_is_a_tree_reproducing_the_tool_pose_and_the_ball(catch_log):
    r = LogReader(catch_log)
    urdf = decode_string(next(r.raw(TOPIC_ROBOT_DESCRIPTION)).data)
    links = {
        line.split('"')[1] for line in urdf.splitlines() if line.strip().startswith("<link name=")
    }
    tool = {m.t_ns: m.data for m in r.messages(TOPIC_EFFECTOR_MOTION)}
    ball = {m.t_ns: m.data for m in r.messages(TOPIC_OBJECT_STATE)}
    frames = decoded(r, TOPIC_TF)
    assert len(frames) == 13  # 0.12 s at 100 Hz, and the final state
    worst = 0.0
    for t_ns, msg in frames:
        children = [x.child_frame_id for x in msg.transforms]
        assert len(children) == len(set(children)), "a frame with two parents"
        tf = {
            x.child_frame_id: (
                x.parent_frame_id,
                np.array([x.translation.x, x.translation.y, x.translation.z]),
                [x.rotation.x, x.rotation.y, x.rotation.z, x.rotation.w],
            )
            for x in msg.transforms
        }
        assert links <= set(tf), f"URDF links without a frame: {links - set(tf)}"
        for child in tf:
            _chain(tf, child)  # reaches world without a cycle
        _, p_tool = _chain(tf, "wam_tool")
        worst = max(worst, float(np.linalg.norm(p_tool - tool[t_ns]["position"])))
        _, p_ball = _chain(tf, "ball")
        assert np.allclose(p_ball, ball[t_ns]["position"], atol=1e-9)
    assert worst < 1e-6, f"tool frame from /tf off by {worst} m"


def test_joint_states_scene_and_log_match_the_contract_topics(catch_log):
    r = LogReader(catch_log)
    arm = {m.t_ns: m.data for m in r.messages(TOPIC_ARM_JOINT_STATE)}
    for t_ns, msg in decoded(r, TOPIC_JOINT_STATES):
        names = [j.name for j in msg.joints]
        q = [j.position for j in msg.joints]
        a = arm[t_ns]
        assert names[: len(a["name"])] == a["name"]
        assert np.allclose(q[: len(a["name"])], a["position"], atol=1e-12)
        assert len(names) > len(a["name"])  # the hand's joints follow
    ball = {m.t_ns: m.data for m in r.messages(TOPIC_OBJECT_STATE)}
    for t_ns, msg in decoded(r, TOPIC_SCENE):
        (e,) = [e for e in msg.entities if e.id == "ball"]
        (s,) = e.spheres
        p = [s.pose.position.x, s.pose.position.y, s.pose.position.z]
        assert np.allclose(p, ball[t_ns]["position"], atol=1e-9) and s.size.x > 0
    events = r.events()
    lines = decoded(r, TOPIC_LOG)
    assert [m.message.split(" ", 1)[0] for _, m in lines] == [e["kind"] for e in events]
    assert lines[-1][1].message.startswith("outcome")


def test_stereo_images_are_the_camera_frames_at_the_camera_rate(catch_log):
    r = LogReader(catch_log)
    sc = yaml.safe_load(r.scenario()["yaml"])
    rate = sc["sensors"]["stereo"]["rate"]
    duration = sc["timing"]["duration"]
    vision = {m.t_ns: m.data for m in r.messages("/vision/object")}
    seen = 0
    for view in (0, 1):
        images = decoded(r, f"/camera/stereo/cam{view}")
        assert len(images) == round(duration * rate)
        for t_ns, msg in images:
            assert msg.encoding == "mono8" and msg.frame_id == f"stereo/cam{view}"
            img = pixels(msg)
            assert img.shape == (128, 128) and img.dtype == np.uint8
            v = vision.get(t_ns)
            if v is not None:  # the measured centroid lies on the bright ball in the image
                u, vv = v["features"]["centroids"][view]
                assert img[int(round(vv)), int(round(u))] > 100
                seen += 1
    assert vision and seen == 2 * len(vision)  # every measurement had its two images


def test_chip_images_are_the_chip_bits(tmp_path):
    log = run(tmp_path, "grasp_hexahedron", ["timing.duration=0.02"])
    r = LogReader(log)
    chip = {m.t_ns: m.data for m in r.messages(TOPIC_VISION_CHIP)}
    images = decoded(r, "/camera/chip/image")
    assert len(images) == len(chip) == 20
    lit = 0
    for t_ns, msg in images:
        img = pixels(msg)
        c = chip[t_ns]
        assert img.shape == (c["height"], c["width"]) == (16, 16)
        assert np.array_equal(img == 255, unpack_rows(c["rows"], c["width"]))
        assert set(np.unique(img)) <= {0, 255}
        lit += int(c["count"] > 0)
    assert lit > 0
    frames = {x.child_frame_id for x in decoded(r, TOPIC_TF)[0][1].transforms}
    assert {"head_camera", "box", "wam_base"} <= frames
    names = [j.name for j in decoded(r, TOPIC_JOINT_STATES)[0][1].joints]
    assert names[-2:] == ["pan", "tilt"]


def test_stick_camera_images_only_when_asked(tmp_path):
    plain = LogReader(run(tmp_path, "stick_3step", ["timing.duration=0.02"], "a.mcap"))
    assert not any(t.startswith("/camera/") for t in plain.topic_counts())
    frames = {x.child_frame_id for x in decoded(plain, TOPIC_TF)[0][1].transforms}
    assert {"stick", "marker", "tip0", "tip1"} <= frames
    assert TOPIC_ROBOT_DESCRIPTION not in plain.topic_counts()  # no URDF for the air table
    sets = ["timing.duration=0.02", "sensors.camera.params.log_images=true"]
    asked = LogReader(run(tmp_path, "stick_3step", sets, "b.mcap"))
    images = decoded(asked, "/camera/camera/image")
    assert len(images) == 6  # 300 Hz for 0.02 s
    img = pixels(images[0][1])
    assert img.shape == (512, 512) and img.max() > 200  # the white marker is in the frame


def test_frame_rate_zero_writes_no_3d_topics_and_the_same_run_the_same_bytes(tmp_path):
    sets = ["timing.duration=0.03"]
    a = run(tmp_path, "catch_optimised", sets, "a.mcap")
    b = run(tmp_path, "catch_optimised", sets, "b.mcap")
    assert a.read_bytes() == b.read_bytes()
    off = LogReader(run(tmp_path, "catch_optimised", sets + ["timing.frame_rate=0"], "c.mcap"))
    counts = off.topic_counts()
    assert TOPIC_TF not in counts and TOPIC_SCENE not in counts and TOPIC_JOINT_STATES not in counts
    assert counts["/camera/stereo/cam0"] == 30  # images follow the camera, not frame_rate


def test_a_truncated_log_still_gives_its_protobuf_messages(catch_log, tmp_path):
    cut = tmp_path / "cut.mcap"
    data = catch_log.read_bytes()
    cut.write_bytes(data[: len(data) * 2 // 3])
    r = LogReader(cut)
    assert r.truncated
    raw = list(r.raw())
    assert raw and all(m.encoding in ("protobuf", "cdr") for m in raw)
    for m in raw[:50]:
        if m.encoding == "protobuf":
            decode(m.schema, m.data)
    list(r.messages())  # JSON topics read as before, the protobuf ones not counted as damage
    assert not r.damaged, r.problems
    shutil.rmtree(tmp_path, ignore_errors=True)


def test_golden_compare_reads_the_protobuf_topics(tmp_path):
    from replay.golden import compare_logs

    sets = ["timing.duration=0.03"]
    a = run(tmp_path, "catch_optimised", sets, "a.mcap")
    moved = sets + ["plant.params.object_position=[3.22772, 0.001, 0.99913]"]
    b = run(tmp_path, "catch_optimised", moved, "b.mcap")
    tol = {"abs": 1e-6, "rel": 0.0}
    assert not compare_logs(a, a, {}, tol)
    found = {d.topic: d for d in compare_logs(a, b, {}, tol)}
    assert {TOPIC_TF, TOPIC_SCENE, TOPIC_OBJECT_STATE} <= set(found)
    assert "translation" in found[TOPIC_TF].field  # the ball's frame moved by 1 mm in y
    assert "/camera/stereo/cam0" not in found  # image bytes are not compared
