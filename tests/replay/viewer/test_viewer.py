"""The replay viewer without a browser: log -> arrays, scenes following the log, timeline,
overlays, plots, errors, port handling, the CLI and ``run --view``.

Servers bind to 127.0.0.1 on a free port (port 0) and are stopped by each test; no test here
asserts on timing (``python -m tools.bench.viewer_load`` measures the load time; one test prints it).
"""

from __future__ import annotations

import math
import socket
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
import yaml
from click.testing import CliRunner

from replay import registry
from replay.cli import main
from replay.interfaces import Controller, Plant
from replay.log import LogReader, LogWriter
from replay.messages import ScenarioInfo, StickState
from replay.params import param
from replay.scenario import params_from_data
from replay.scene import Scene
from replay.viewer import SPEEDS, ViewerError, load_run
from replay.viewer import app as viewer_app
from replay.viewer.app import Viewer, free_port
from plants.airtable import Params as AirTableParams
from plants.airtable.viewer_scene import AirTableScene, StickGeometry
from plants.arm_rig.viewer_scene import ArmScene, plant_models_urdf
from replay.viewer.geometry import cameras
from replay.viewer.scenes import RunScene, scene_class
from synthetic_logs import write_arm_log, write_stick_log
from replay.viewer.timeline import speed_value


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args], catch_exceptions=False)


def one_error_line(r) -> str:
    lines = [l for l in r.output.splitlines() if l.strip()]
    assert len(lines) == 1, r.output
    assert lines[0].startswith("error: ") and "Traceback" not in r.output
    return lines[0]


@pytest.fixture
def stick_log(tmp_path):
    return write_stick_log(tmp_path / "stick.mcap")


@pytest.fixture
def arm_log(tmp_path):
    return write_arm_log(tmp_path / "arm.mcap")


@pytest.fixture
def viewer_factory():
    made = []

    def make(paths, **kw):
        v = Viewer.open(paths, port=0, **kw)
        made.append(v)
        return v

    yield make
    for v in made:
        v.stop()


def _wait_for(cond, what, limit=20.0):
    """Poll ``cond`` (a deadline against hanging, not a timing assertion)."""
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if cond():
            return
        time.sleep(0.02)
    raise AssertionError(f"never happened: {what}")


# ----------------------------------------------------------------------------- log -> arrays
def test_log_loads_into_arrays_found_by_time(stick_log):
    run = load_run(stick_log)
    assert run.label == "synthetic_stick" and run.plant_type == "airtable"
    st = run.track("/stick/state")
    assert len(st) == 1001 and st.fields["x"].dtype == np.float64
    assert np.all(np.diff(st.t) > 0) and st.t[0] == 0.0 and abs(st.t[-1] - 1.0) < 1e-9
    assert run.track("/fingers/state").fields["tips"].shape == (1001, 2, 2)
    assert run.track("/hand/state").fields["joints"].shape == (1001, 2, 2)
    # the frame for a time: searchsorted, the last message at or before t
    assert st.index(-0.1) == -1
    assert st.index(0.0) == 0
    assert st.index(0.2504) == 250
    assert st.index(0.25) == 250
    assert st.index(5.0) == 1000
    assert st.at("x", 0.25) == st.fields["x"][250]
    # the values are the log's
    msgs = [m for m in LogReader(stick_log).messages("/stick/state")]
    assert st.fields["omega"][700] == msgs[700].data["omega"]
    assert [e["kind"] for e in run.events] == ["collision", "collision", "rest"]
    assert run.events[0]["data"]["finger"] == 0 and abs(run.events[0]["t"] - 0.2) < 1e-9
    assert run.notes == []


def test_overlaid_logs_of_one_scenario_name_are_told_apart(stick_log, tmp_path, monkeypatch):
    """`replay view a.mcap b.mcap` of one scenario (the default and a --set variant): each run's
    label, its title, legend and warnings' prefix, says its file where the name is shared."""
    import shutil

    other = tmp_path / "variant.mcap"
    shutil.copy(stick_log, other)
    monkeypatch.setattr(Viewer, "load", lambda self, runs: setattr(self, "runs", runs))
    monkeypatch.setattr(Viewer, "__init__", lambda self, **kw: None)
    v = Viewer.open([stick_log, other])
    assert [r.label for r in v.runs] == [
        "synthetic_stick (stick.mcap)",
        "synthetic_stick (variant.mcap)",
    ]
    alone = Viewer.open([stick_log])
    assert [r.label for r in alone.runs] == ["synthetic_stick"]


def test_names_are_kept_once_and_ragged_fields_noted(tmp_path):
    path = tmp_path / "r.mcap"
    with LogWriter(path) as log:
        for k in range(5):
            log.write(
                "/arm/joint_state",
                {
                    "t": k * 1e-3,
                    "name": ["J1", "J2"],
                    "position": [0.1 * k, 0.2] if k != 3 else [0.1],
                    "velocity": [0.0, 0.0],
                    "effort": [1.0, 2.0],
                },
                k * 1_000_000,
            )
    run = load_run(path)
    tr = run.track("/arm/joint_state")
    assert tr.labels["name"] == ["J1", "J2"]
    assert np.isnan(tr.fields["position"][3]).all() and tr.fields["position"][4, 0] == 0.4
    assert tr.ragged == ("position",) and any("position" in n for n in run.notes)


def test_geometry_from_the_resolved_scenario(tmp_path):
    path = write_stick_log(tmp_path / "long.mcap", length=0.2)
    run = load_run(path)
    g = StickGeometry.of(params_from_data(AirTableParams, run.plant_params, "plant.params"))
    assert g.length == 0.2 and g.visual_width == 0.01 and g.tip_radius == 0.005
    d = StickGeometry.of(AirTableParams())  # the plant's defaults
    assert (d.length, d.tip_height, d.link_lengths) == (0.1, 0.02, (0.07, 0.07))
    # the fingers' kinematics match the logged fingertips (replay.robot.hand2d's convention)
    hs, fi = run.track("/hand/state"), run.track("/fingers/state")
    pts = g.finger_points(hs.fields["base"][100], hs.fields["joints"][100])
    assert np.allclose(pts[:, 2], fi.fields["tips"][100], atol=1e-12)


def test_cameras_from_sensor_params(stick_log, arm_log):
    cams, missing = cameras(load_run(stick_log).sensors)
    assert [c.name for c in cams] == ["camera"] and missing == []
    c = cams[0]
    assert c.position == (0.0, 0.15, 0.7) and abs(c.aspect - 1.0) < 1e-12
    # looking straight down: the camera's z axis (OpenCV forward) is world -z
    w, x, y, z = c.wxyz
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    assert np.allclose(R[:, 2], [0.0, 0.0, -1.0], atol=1e-9)
    cams, _ = cameras(load_run(arm_log).sensors)
    assert len(cams) == 2  # a stereo pair in a list
    cams, missing = cameras(
        {
            "cam": {"type": "stick_camera", "params": {"noise": 0.1}},
            "enc": {"type": "joint_encoders"},
        }
    )
    assert cams == [] and missing == ["cam"]


def test_scenes_are_plugins_found_by_plant_type(monkeypatch, stick_log, arm_log):
    assert scene_class(load_run(stick_log)) is AirTableScene
    assert scene_class(load_run(arm_log)) is ArmScene

    class Variant(AirTableScene):
        @classmethod
        def suits(cls, run):
            return run.label == "picky"

    monkeypatch.setitem(registry._registered["viewer_scene"], "airtable.picky", Variant)
    assert scene_class(load_run(stick_log)) is AirTableScene  # does not suit it
    picky = write_stick_log(stick_log.with_name("picky.mcap"), name="picky")
    assert scene_class(load_run(picky)) is Variant


class _ToyScene(RunScene):
    """A scene for a plant type the viewer has never heard of: a sphere on /toy/state's x."""

    kind = "toy"
    needs = ("/toy/state",)

    def build(self):
        self.ball = self._add(
            self.scene.add_icosphere(f"{self.root}/ball", radius=0.1, color=self.color)
        )

    def update(self, run, t):
        tr = run.track("/toy/state")
        self.ball.position = (float(tr.at("x", t)), 0.0, 0.0)

    def bounds(self):
        return np.array([-1.0, -1.0, 0.0]), np.array([3.0, 1.0, 1.0])


def test_a_new_plant_type_brings_its_own_scene(monkeypatch, tmp_path, viewer_factory):
    path = tmp_path / "toy.mcap"
    with LogWriter(path) as log:
        log.write(
            "/scenario", ScenarioInfo(0.0, "toy", "none", "plant: {type: toy_plant}\n", 0, "x"), 0
        )
        for k in range(3):
            log.write("/toy/state", {"t": k * 0.01, "x": 1.0 * k}, k * 10_000_000)
    with pytest.raises(ViewerError, match="nothing the viewer can draw"):
        scene_class(load_run(path))
    monkeypatch.setitem(registry._registered["viewer_scene"], "toy_plant", _ToyScene)
    v = viewer_factory([path])
    assert isinstance(v.scenes[0], _ToyScene)
    v.seek(0.02)
    assert v.scenes[0].ball.position[0] == 2.0


def test_the_viewer_engine_imports_no_plugin_and_no_simulator():
    import subprocess
    import sys

    code = (
        "import sys; import replay.viewer.app; "
        "assert not [m for m in sys.modules if m.startswith('plants')], 'a plug-in'; "
        "from replay.viewer.scenes import scene_classes; s = scene_classes(); "
        "assert {'airtable', 'arm_rig'} <= set(s), s; "
        "assert 'pybullet' not in sys.modules and 'pymunk' not in sys.modules, 'simulator'"
    )
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr


# ----------------------------------------------------------------------------- bad logs
def test_not_mcap_missing_empty_and_truncated(tmp_path, stick_log):
    junk = tmp_path / "junk.mcap"
    junk.write_text("hello")
    with pytest.raises(ViewerError, match="not an MCAP log"):
        load_run(junk)
    with pytest.raises(ViewerError, match="no such log file"):
        load_run(tmp_path / "nope.mcap")
    data = write_stick_log(tmp_path / "big.mcap", duration=2.0).read_bytes()
    (tmp_path / "head.mcap").write_bytes(data[:64])
    with pytest.raises(ViewerError, match="no messages"):
        load_run(tmp_path / "head.mcap")
    (tmp_path / "cut.mcap").write_bytes(data[: len(data) * 2 // 3])
    run = load_run(tmp_path / "cut.mcap")
    assert run.truncated and run.notes[0].startswith("truncated log: read up to t = ")
    assert 0.1 < run.track("/stick/state").t[-1] < 2.0


def _toy_log(path):
    with LogWriter(path) as log:
        log.write("/scenario", ScenarioInfo(0.0, "toy", "none", "name: toy\n", 0, "x"), 0)
        for k in range(3):
            log.write("/toy/state", {"t": k * 0.01, "x": 1.0 * k}, k * 10_000_000)
    return path


def test_a_log_without_drawable_topics_is_one_clear_error(tmp_path):
    path = _toy_log(tmp_path / "toy.mcap")
    with pytest.raises(ViewerError, match="nothing the viewer can draw.*/stick/state.*/toy/state"):
        scene_class(load_run(path))
    line = one_error_line(invoke("view", path, "--port", 0, "--timeout", 0.1))
    assert "toy.mcap" in line and "/toy/state" in line


def test_cli_view_bad_input_is_one_line_exit_2(tmp_path, stick_log):
    junk = tmp_path / "junk.mcap"
    junk.write_text("not a log")
    r = invoke("view", junk)
    assert r.exit_code == 2 and "not an MCAP log" in one_error_line(r)
    r = invoke("view", stick_log, tmp_path / "missing.mcap")
    assert r.exit_code == 2 and "no such log file" in one_error_line(r)
    r = invoke("view", stick_log, "--host", "no.such.host.invalid", "--timeout", 0.1)
    assert r.exit_code == 2 and "cannot listen on host" in one_error_line(r)


def test_cli_view_serves_on_localhost_then_stops(stick_log, tmp_path):
    data = write_stick_log(tmp_path / "big.mcap", duration=2.0).read_bytes()
    (tmp_path / "cut.mcap").write_bytes(data[: len(data) // 2])
    r = CliRunner().invoke(
        main,
        ["view", str(stick_log), str(tmp_path / "cut.mcap"), "--port", "0", "--timeout", "0.3"],
        catch_exceptions=False,
    )
    assert r.exit_code == 0, r.output
    assert "viewer: http://127.0.0.1:" in r.output
    assert "warning: synthetic_stick (cut.mcap): truncated log" in r.output  # (which of the two)


# ----------------------------------------------------------------------------- ports
def test_port_in_use_moves_to_the_next_free_port_and_says_so():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        busy = s.getsockname()[1]
        port, note = free_port("127.0.0.1", busy)
        assert port > busy and note == f"port {busy} is in use; serving on port {port}"
        v = Viewer(port=busy)
        try:
            assert v.port != busy and v.port_note.startswith(f"port {busy} is in use")
            assert v.server.get_host() == "127.0.0.1"
        finally:
            v.stop()
    assert free_port("127.0.0.1", 0) == (0, "")
    with pytest.raises(ViewerError, match="cannot listen on host"):
        free_port("no.such.host.invalid", 8080)


# ----------------------------------------------------------------------------- scenes
def test_stick_scene_follows_the_log(viewer_factory, stick_log):
    v = viewer_factory([stick_log])
    assert v.url.startswith("http://127.0.0.1:")
    scene = v.scenes[0]
    assert isinstance(scene, AirTableScene) and scene.root == "/run0"
    run = v.runs[0]
    st, fi = run.track("/stick/state"), run.track("/fingers/state")
    for t in (0.0, 0.123, 0.6, 1.0):
        v.seek(t)
        i = st.index(t)
        assert np.allclose(scene.stick.position, (st.fields["x"][i], st.fields["y"][i], 0.0))
        th = st.fields["theta"][i]
        assert np.allclose(scene.stick.wxyz, (math.cos(th / 2), 0, 0, math.sin(th / 2)))
        assert np.allclose(scene.tips[1].position[:2], fi.fields["tips"][fi.index(t), 1])
    # the path so far ends at the stick
    assert np.allclose(scene._path.points[-1, 1, :2], scene.stick.position[:2], atol=1e-6)
    # the stick's sizes come from the scenario; collision markers appear after the collision
    assert scene.geo.length == 0.1
    v.seek(0.1)
    assert [h.visible for _, h in scene.markers] == [False, False]
    v.seek(0.3)
    assert [h.visible for _, h in scene.markers] == [True, False]
    assert len(scene.handles) > 5 and v.notes == []


def test_timeline_steps_frames_jumps_to_events_and_plays(viewer_factory, stick_log):
    v = viewer_factory([stick_log])
    tl = v.timeline
    assert (tl.t0, tl.t1) == (0.0, 1.0) and len(tl.frames) == 1001
    assert "1/100" in SPEEDS and speed_value("1/100") == 0.01 and speed_value("1/10") == 0.1
    v.seek(0.5)
    tl.step(+1)
    assert abs(v.time - 0.501) < 1e-9
    tl.step(-1)
    tl.step(-1)
    assert abs(v.time - 0.499) < 1e-9
    v.seek(0.4995)  # between frames: back is the frame before
    tl.step(-1)
    assert abs(v.time - 0.499) < 1e-9
    v.seek(0.0)
    tl.step(-1)
    assert v.time == 0.0
    # the events list: one button each, jumping there
    labels = [b.label for _, b in tl.event_buttons]
    assert labels[0] == "0.2000 s  collision (finger 0)" and "rest" in labels[-1]
    t_evt, _ = tl.event_buttons[1]
    tl.seek(t_evt)
    assert abs(v.time - 0.45) < 1e-9 and tl.slider.value == v.time
    assert "t = 0.4500 s · frame 451/1001" in tl.status.content
    # play at full speed until the end (deadline, not timing): it stops there, paused
    tl.speed.value = "2"
    tl.toggle()
    assert tl.playing and tl.play.label == "Pause"
    _wait_for(lambda: not tl.playing, "playback to reach the end")
    assert v.time == 1.0 and tl.play.label == "Play"


def test_plots_show_the_signals_with_a_cursor(viewer_factory, stick_log, arm_log):
    v = viewer_factory([stick_log])
    titles = [p.handle.title for p in v.plots.plots]
    assert titles == ["stick speed |v| (m/s)", "stick angular velocity ω (rad/s)"]
    v.seek(0.3)
    data = v.plots.plots[0].handle.data
    x, speed, cursor = data
    j = int(np.flatnonzero(cursor > 1.0)[0])
    assert x[j] == 0.3 and np.all(x[j - 1 : j + 2] == 0.3)  # the cursor: a vertical line
    assert abs(speed[j] - math.hypot(0.15, -0.05)) < 1e-9  # |v| after the first collision
    assert np.all(np.diff(x) >= 0)
    v2 = viewer_factory([arm_log])
    titles = [p.handle.title for p in v2.plots.plots]
    assert titles == ["joint angles (rad)", "joint velocities (rad/s)", "joint torques (N·m)"]
    assert [s["label"] for s in v2.plots.plots[0].handle.series] == [
        "t (s)",
        "J1",
        "J2",
        "J3",
        "J4",
        "now",
    ]


def test_arm_scene_from_the_plants_urdf_with_logged_angles(viewer_factory, arm_log):
    v = viewer_factory([arm_log])
    scene = v.scenes[0]
    assert isinstance(scene, ArmScene) and scene.urdf is not None, v.notes
    # J3 is locked in the scenario: a fixed joint in the URDF, so not actuated
    assert scene._names == ("J1", "J2", "J4", "f1_j1", "f2_j1", "f3_j1")
    run = v.runs[0]
    arm, hand = run.track("/arm/joint_state"), run.track("/hand/joint_state")
    v.seek(0.5)
    q = arm.fields["position"][arm.index(0.5)]
    h = hand.fields["position"][hand.index(0.5)]
    assert np.allclose(scene.urdf._urdf.cfg, [q[0], q[1], q[3], *h])
    ob = run.track("/object/state")
    assert np.allclose(scene.body.position, ob.fields["position"][ob.index(0.5)])
    assert scene.body.visible and scene._path is not None
    assert len([h for h in scene.handles if "cameras" in h.name]) == 4  # 2 frusta + labels
    # the same file the arm plant loads (plants.models' cache, by content)
    assert plant_models_urdf(run.plant_params) == plant_models_urdf(run.plant_params)


GOLDENS = sorted((Path(__file__).resolve().parents[3] / "data" / "golden").glob("*.mcap"))


def _poses(scene) -> dict:
    """Every handle's position and orientation, rounded (what a seek moves)."""
    out = {}
    for h in scene.handles:
        for a in ("position", "wxyz"):
            value = getattr(h, a, None)
            if value is not None:
                out[(h.name, a)] = tuple(np.round(np.asarray(value, float), 6))
    return out


@pytest.mark.parametrize("path", GOLDENS, ids=[p.stem for p in GOLDENS])
def test_every_golden_is_drawn_and_moves(viewer_factory, path):
    """Each golden by its plant type's own scene, its object moved by the slider (the browser
    test draws one golden of each scene that draws differently)."""
    v = viewer_factory([path])
    plant = LogReader(path).scenario_config()["plant"]["type"]
    assert type(v.scenes[0]) is registry.load("viewer_scene", plant)
    t0, t1 = v.timeline.t0, v.timeline.t1
    v.seek(t0 + 0.2 * (t1 - t0))
    a = _poses(v.scenes[0])
    v.seek(t0 + 0.9 * (t1 - t0))
    b = _poses(v.scenes[0])
    moved = {name for (name, _), pose in a.items() if b.get((name, _)) != pose}
    assert any(n.endswith(("/object", "/stick")) for n in moved), sorted(moved)


TEST_URDF = """<?xml version="1.0"?>
<robot name="two_link">
  <link name="base"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
  <link name="l1"><visual><geometry><cylinder radius="0.03" length="0.5"/></geometry>
  </visual></link>
  <link name="l2"><visual><geometry><sphere radius="0.05"/></geometry></visual></link>
  <joint name="J1" type="revolute"><parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
  <joint name="J2" type="revolute"><parent link="l1"/><child link="l2"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def test_the_urdf_source_can_be_pointed_elsewhere(viewer_factory, arm_log, tmp_path):
    urdf = tmp_path / "two_link.urdf"
    urdf.write_text(TEST_URDF)
    seen = []

    def urdf_for(params):
        seen.append(params["arm"])
        return urdf

    v = viewer_factory([arm_log], urdf_for=urdf_for)
    scene = v.scenes[0]
    assert seen == ["wam4"] and scene._names == ("J1", "J2")
    v.seek(0.3)
    q = v.runs[0].track("/arm/joint_state").at("position", 0.3)
    assert np.allclose(scene.urdf._urdf.cfg, q[:2])
    # a URDF that cannot be had: the rest is shown, and the view says what is missing
    v2 = viewer_factory([arm_log], urdf_for=lambda p: tmp_path / "absent.urdf")
    assert v2.scenes[0].urdf is None
    assert any("arm not drawn" in n and "absent.urdf" in n for n in v2.notes)
    v2.seek(0.2)
    assert v2.scenes[0].body.visible


def test_two_logs_overlaid_and_in_step(viewer_factory, tmp_path):
    a = write_stick_log(tmp_path / "a.mcap", name="slow_spin", spin=2.0)
    b = write_stick_log(tmp_path / "b.mcap", name="fast_spin", spin=9.0, duration=0.7)
    v = viewer_factory([a, b])
    assert [s.root for s in v.scenes] == ["/run0", "/run1"]
    assert (v.timeline.t0, v.timeline.t1) == (0.0, 1.0)  # the union of the runs
    v.seek(0.15)
    th = [s.run.track("/stick/state").at("theta", 0.15) for s in v.scenes]
    for s, theta in zip(v.scenes, th):
        assert np.allclose(s.stick.wxyz, (math.cos(theta / 2), 0, 0, math.sin(theta / 2)))
    assert th[0] != th[1]
    v.seek(0.9)  # past the shorter run's end: it holds its last
    assert np.allclose(
        v.scenes[1].stick.position[:2],
        [v.runs[1].track("/stick/state").fields[k][-1] for k in ("x", "y")],
    )
    assert len(v.plots.plots[0].handle.series) == 4  # t, 2 runs, cursor
    labels = [b.label for _, b in v.timeline.event_buttons]
    assert labels[0].startswith("slow_spin: 0.2000 s") and len(labels) == 5
    v.run_toggles[1].value = False  # hide one run: its whole subtree
    assert not v.scenes[1].root_frame.visible and v.scenes[0].root_frame.visible


def test_a_log_missing_some_topics_shows_the_rest_and_says_so(viewer_factory, tmp_path):
    path = tmp_path / "bare.mcap"
    with LogWriter(path) as log:
        for k in range(100):
            log.write(
                "/stick/state", StickState(k / 1000, 0.01 * k, 0.1, 0.0, 1, 0, 0), k * 1_000_000
            )
    v = viewer_factory([path])
    assert any("no /scenario message" in n for n in v.notes)
    assert any("no /fingers/state" in n for n in v.notes)
    v.seek(0.05)
    assert np.allclose(v.scenes[0].stick.position, (0.5, 0.1, 0.0))  # x = 0.01 k
    assert not v.scenes[0].tips[0].visible


def test_load_time_of_a_2s_1khz_log_is_printed(tmp_path, capsys):
    """Measured, not asserted (see tools/bench/viewer_load.py)."""
    path = write_stick_log(tmp_path / "bench.mcap", duration=2.0, rate=1000)
    t0 = time.perf_counter()
    run = load_run(path)
    dt = time.perf_counter() - t0
    assert len(run.track("/stick/state")) == 2001
    with capsys.disabled():
        print(
            f"\n[viewer] 2-s 1 kHz air-table log ({path.stat().st_size // 1024} KiB) "
            f"loaded in {dt:.3f} s"
        )


# ----------------------------------------------------------------------------- run --view
@dataclass
class _SlideParams:
    vx: float = param(0.5, unit="m/s")


class _SlidingStick(Plant):
    """A stick sliding and spinning, logged like the air-table plant (no simulator)."""

    Params = _SlideParams

    def __init__(self, params, *, dt, rng):
        super().__init__(params, dt=dt, rng=rng)
        self.k = 0

    def apply(self, command):
        pass

    def step(self):
        self.k += 1

    def truth(self, t):
        return {
            "/stick/state": StickState(
                t, self.params.vx * t, 0.2, 3.0 * t, self.params.vx, 0.0, 3.0
            ),
            "/fingers/state": {"t": t, "tips": [[-0.02, 0.1], [0.02, 0.1]]},
        }

    def scene(self):
        return Scene([])

    def spec(self):
        return None


@dataclass
class _NoParams:
    pass


class _Idle(Controller):
    Params = _NoParams

    def update(self, t, measurements):
        return None


def test_run_view_shows_the_run_live_then_replays_it(tmp_path, monkeypatch):
    # registered for this test only (monkeypatch takes them out again)
    monkeypatch.setitem(registry._registered["plant"], "sliding_stick", _SlidingStick)
    monkeypatch.setitem(registry._registered["controller"], "idle", _Idle)
    sc = tmp_path / "slide.yaml"
    sc.write_text(
        yaml.safe_dump(
            {
                "name": "slide",
                "paper": "higashimori2007",
                "timing": {"physics_rate": 1000, "duration": 0.3},
                "plant": {"type": "sliding_stick", "params": {"vx": 0.4}},
                "controller": {"type": "idle", "rate": 1000},
            }
        )
    )
    monkeypatch.setattr(viewer_app, "DEFAULT_PORT", 0)
    seen = {}

    def observe_then_stop(self, timeout=None):  # instead of serving until Ctrl-C
        v = self.viewer
        seen.update(
            refreshes=self.refreshes,
            error=self.error,
            url=self.url,
            kind=type(v.scenes[0]).__name__,
            t1=v.timeline.t1,
        )
        v.seek(0.1)
        seen["x"] = v.scenes[0].stick.position[0]
        self.stop()

    monkeypatch.setattr(viewer_app.LiveSession, "wait", observe_then_stop)
    calls = []
    orig = viewer_app.LiveSession.refresh

    def counting_refresh(self):
        orig(self)
        calls.append(len(self.viewer.scenes))

    monkeypatch.setattr(viewer_app.LiveSession, "refresh", counting_refresh)
    out = tmp_path / "slide.mcap"
    r = invoke("run", sc, "-o", out, "--view", "-q")
    assert r.exit_code == 0, r.output
    assert out.is_file() and "viewer: http://127.0.0.1:" in r.output
    assert seen["error"] == "" and seen["refreshes"] >= 1 and calls and calls[-1] == 1
    assert seen["kind"] == "AirTableScene" and abs(seen["t1"] - 0.3) < 1e-9
    assert abs(seen["x"] - 0.04) < 1e-9
    assert "replaying" in r.output
