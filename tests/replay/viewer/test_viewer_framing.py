"""What the viewer frames and lists, without a browser: the camera fitted to the moving parts
(not the whole static scene), following the object, the events grouped by kind with the
paper's milestones always listed, overlaid runs each in its own colour, a scene's extra bodies.

Servers bind to 127.0.0.1 on a free port (port 0) and are stopped by each test.
"""

from __future__ import annotations

import numpy as np
import pytest

from plants.arm_rig.viewer_scene import ArmScene
from replay import registry
from replay.viewer.app import Viewer
from replay.viewer.scenes import FIT_MIN_SIZE, Body, fit_bounds, run_color
from synthetic_logs import write_arm_log, write_stick_log
from replay.viewer.timeline import (
    ALL_KINDS,
    MAX_EVENT_BUTTONS,
    kind_counts,
    kind_option,
    milestones,
    select_events,
)


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


# -- the fitted box -----------------------------------------------------------------------------
def test_fit_bounds_pads_skips_nan_and_keeps_a_minimum_size():
    rng = np.random.default_rng(23)
    for _ in range(20):
        c = rng.uniform(-2, 2, 3)
        pts = c + rng.uniform(-0.5, 0.5, (50, 3)) * rng.uniform(0, 2, 3)
        pts[rng.integers(0, 50)] = np.nan
        lo, hi = fit_bounds(pts, margin=0.05, min_size=0.3)
        ok = pts[np.all(np.isfinite(pts), axis=1)]
        assert np.all(lo <= ok.min(axis=0) - 0.05 + 1e-12)
        assert np.all(hi >= ok.max(axis=0) + 0.05 - 1e-12)
        assert np.all(hi - lo >= 0.3 - 1e-12)
        wide = (ok.max(axis=0) - ok.min(axis=0) + 0.1) > 0.3
        assert np.allclose((hi - lo)[wide], (ok.max(axis=0) - ok.min(axis=0) + 0.1)[wide])
    lo, hi = fit_bounds(np.full((3, 3), np.nan))  # nothing finite: a box about the origin
    assert np.allclose((lo + hi) / 2, 0.0) and np.allclose(hi - lo, FIT_MIN_SIZE)


def test_a_catch_is_framed_on_the_hand_and_the_ball_near_it(viewer_factory, tmp_path):
    v = viewer_factory([write_arm_log(tmp_path / "catch.mcap")])
    run, scene = v.runs[0], v.scenes[0]
    lo, hi = v.fitted()
    hand = run.track("/effector/state").fields["position"]
    ball = run.track("/object/state").fields["position"]
    assert np.all(lo <= hand.min(axis=0)) and np.all(hi >= hand.max(axis=0))
    caught = ball[-1]  # in the hand at the end
    assert np.all(lo <= caught) and np.all(hi >= caught)
    # the ball's launch, 1.5 m out, and the floor's origin are not framed: the static scene
    # (scene.bounds) is much larger than the fitted box
    assert not np.all((lo <= ball[0]) & (ball[0] <= hi))
    b_lo, b_hi = scene.bounds()
    assert np.max(hi - lo) < 0.6 * np.max(b_hi - b_lo)
    # the initial camera looks at the fitted box's centre from about its size away
    cam = v.server.initial_camera
    c = (lo + hi) / 2
    assert np.allclose(cam.look_at, c)
    d = np.linalg.norm(np.asarray(cam.position) - c)
    assert 0.8 * np.max(hi - lo) < d < 1.5 * np.max(hi - lo)


def test_a_still_object_in_the_hand_fills_a_small_box(viewer_factory, tmp_path):
    """A grasp: the hand and the box within a few centimetres: the fitted box is the minimum
    size, not the 1.4 m static scene."""
    log = write_arm_log(tmp_path / "g.mcap", arm="wam7", hand="grasp4", obj="box", swing=0.02)
    v = viewer_factory([log])
    lo, hi = v.fitted()
    assert np.max(hi - lo) < 0.5 * np.max(np.subtract(*v.scenes[0].bounds()[::-1]))


def test_without_a_logged_hand_the_object_path_is_framed(viewer_factory, tmp_path, monkeypatch):
    log = write_arm_log(tmp_path / "c.mcap")
    v = viewer_factory([log])
    scene = v.scenes[0]
    monkeypatch.setattr(ArmScene, "hand_path", lambda self: None)
    ball = v.runs[0].track("/object/state").fields["position"]
    assert np.allclose(scene.focus_points(), ball)


def test_the_follow_toggle_is_offered_and_points_at_the_object(viewer_factory, tmp_path):
    v = viewer_factory([write_arm_log(tmp_path / "c.mcap")])
    assert v.follow is not None and v.follow.value is False
    ob = v.runs[0].track("/object/state")
    for t in (0.1, 0.35, 0.7):
        assert np.allclose(v.follow_point(t), ob.at("position", t))
    v.follow.value = True  # no browser connected: following moves no camera, and does not fail
    v.seek(0.3)
    assert v.time == pytest.approx(0.3)
    s = viewer_factory([write_stick_log(tmp_path / "s.mcap")])
    st = s.runs[0].track("/stick/state")
    assert np.allclose(s.follow_point(0.5)[:2], [st.at("x", 0.5), st.at("y", 0.5)])


# -- events ---------------------------------------------------------------------------------------
def _flood(n: int, seed: int) -> list[tuple[str, dict]]:
    rng = np.random.default_rng(seed)
    ev = [
        ("r", {"t": float(t), "kind": str(rng.choice(["torque_limit", "velocity_limit"]))})
        for t in np.sort(rng.uniform(0, 1, n))
    ]
    for kind in ("grasp", "release", "outcome"):
        ev.append(("r", {"t": float(rng.uniform(0, 1)), "kind": kind}))
    return sorted(ev, key=lambda le: le[1]["t"])


def test_milestones_survive_any_flood_and_kinds_are_counted():
    for seed in range(10):
        n = int(np.random.default_rng(seed).integers(0, 2000))
        ev = _flood(n, seed)
        assert [e["kind"] for _, e in milestones(ev)] == [
            e["kind"] for _, e in ev if e["kind"] in ("grasp", "release", "outcome")
        ]
        counts = kind_counts(ev)
        assert sum(counts.values()) == len(ev) and counts["grasp"] == 1
        assert len(select_events(ev, "torque_limit")) == counts.get("torque_limit", 0)
        assert [e["kind"] for _, e in select_events(ev, None, "gras")] == ["grasp"]
        assert select_events(ev, "grasp", "torque") == []


def test_the_viewer_lists_milestones_groups_kinds_and_filters(viewer_factory, tmp_path):
    log = write_arm_log(
        tmp_path / "g.mcap", arm="wam7", hand="grasp4", obj="box", limit_events=500, outcome=True
    )
    v = viewer_factory([log])
    tl = v.timeline
    kinds = [b.label.split("  ")[1].split(" ")[0] for _, b in tl.milestone_buttons]
    assert kinds == ["grasp", "outcome"]  # whatever floods the log
    grasp_t = next(e["t"] for e in v.runs[0].events if e["kind"] == "grasp")
    t, button = tl.milestone_buttons[0]
    assert t == pytest.approx(grasp_t)
    tl.seek(t)
    assert v.time == pytest.approx(grasp_t)
    # the flood is counted and listed up to the limit, the rest said
    assert tl.counts["torque_limit"] == 250 and tl.counts["velocity_limit"] == 250
    assert len(tl.event_buttons) == MAX_EVENT_BUTTONS and tl.more is not None
    assert f"{502 - MAX_EVENT_BUTTONS + 1} more" in tl.more.content
    assert tl.kind.options[0] == ALL_KINDS
    tl.kind.value = kind_option("grasp", 1)
    assert [b.label.split("  ")[1] for _, b in tl.event_buttons] == ["grasp (parts palm+f1+f2)"]
    assert tl.more is None
    tl.kind.value = kind_option("velocity_limit", 250)
    tl.filter.value = "J3"
    labels = [b.label for _, b in tl.event_buttons]
    assert labels and all("velocity_limit" in x and "J3" in x for x in labels)
    tl.filter.value = "no such event"
    assert tl.event_buttons == []


# -- overlays -----------------------------------------------------------------------------------
def test_overlaid_runs_each_in_their_own_colour_with_a_legend(viewer_factory, tmp_path):
    a = write_arm_log(tmp_path / "a.mcap", name="catch_a")
    b = write_arm_log(tmp_path / "b.mcap", name="catch_b", swing=0.55)
    v = viewer_factory([a, b])
    colours = []
    for k, s in enumerate(v.scenes):
        assert s.tint and s.color == run_color(k)
        assert s.urdf is not None and s.urdf_color is not None
        rgb = tuple(round(c * 255) for c in s.urdf_color[:3])
        colours.append(rgb)
        assert rgb == run_color(k) and tuple(s.body.color) == run_color(k)
    assert colours[0] != colours[1]
    legend = v.legend()
    assert "natural" not in legend
    for k, r in enumerate(v.runs):
        assert f"rgb{run_color(k)}" in legend and r.label in legend
    one = viewer_factory([a])  # alone: natural colours
    assert not one.scenes[0].tint and one.scenes[0].urdf_color is None


# -- extra bodies ---------------------------------------------------------------------------------
def test_extra_bodies_of_a_scene_are_drawn_moved_and_framed(viewer_factory, tmp_path, monkeypatch):
    class WithHuman(ArmScene):
        def bodies(self):
            def pose(run, t):
                p = run.track("/object/state").at("position", t)
                if p is None or t > 0.6:
                    return None
                return (np.asarray(p) + [0.0, 0.0, 0.3], (1.0, 0.0, 0.0, 0.0))

            return [Body("human_hand", "box", (0.08, 0.1, 0.03), pose, label="human hand")]

    monkeypatch.setitem(registry._registered["viewer_scene"], "arm_rig", WithHuman)
    v = viewer_factory([write_arm_log(tmp_path / "c.mcap")])
    scene = v.scenes[0]
    assert isinstance(scene, WithHuman)
    ((body, handle),) = scene._bodies
    ob = v.runs[0].track("/object/state")
    v.seek(0.45)
    assert handle.visible
    assert np.allclose(handle.position, ob.at("position", 0.45) + [0, 0, 0.3])
    v.seek(0.7)
    assert not handle.visible
    lo, hi = v.fitted()  # the body's path is framed too
    assert hi[2] >= ob.at("position", 0.45)[2] + 0.3 - 1e-9
