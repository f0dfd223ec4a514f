"""The viewer's grasping scene (plants/arm_rig/grasp_viewer_scene.py) without a browser: a grasping log
(the synthetic one of grasp_synthetic.py, with the contract's topics) is drawn with the WAM-7 and
the 14-joint hand from the plant's URDF, the head camera at its logged pose with the chip's
image on its frustum, the recognised object, the reaching target and the phase."""

from __future__ import annotations

import numpy as np
import pytest

from grasp_synthetic import write_grasp_log
from replay.viewer.app import Viewer
from plants.arm_rig.grasp_viewer_scene import GraspScene, chip_image
from replay.spatial import xyzw_to_wxyz


@pytest.fixture(scope="module")
def grasp_log(tmp_path_factory):
    return write_grasp_log(tmp_path_factory.mktemp("grasp_view") / "grasp.mcap", duration=1.2)


@pytest.fixture
def viewer(grasp_log):
    v = Viewer.open([grasp_log], port=0)
    yield v
    v.stop()


def test_grasp_scene_draws_arm_hand_head_and_object(viewer):
    scene = viewer.scenes[0]
    assert isinstance(scene, GraspScene) and scene.urdf is not None, viewer.notes
    assert not scene.notes, scene.notes
    run = viewer.runs[0]
    arm, hand = run.track("/arm/joint_state"), run.track("/hand/joint_state")
    assert len(scene._names) == 7 + 14
    for t in (0.2, 0.9):
        viewer.seek(t)
        q = arm.fields["position"][arm.index(t)]
        h = hand.fields["position"][hand.index(t)]
        cfg = dict(zip(scene._names, scene.urdf._urdf.cfg))
        assert np.allclose([cfg[n] for n in arm.labels["name"]], q)
        assert np.allclose([cfg[n] for n in hand.labels["name"]], h)
        hs = run.track("/head/state")
        i = hs.index(t)
        assert scene.head.visible
        assert np.allclose(scene.head.position, hs.fields["camera_position"][i])
        assert np.allclose(scene.head.wxyz, xyzw_to_wxyz(hs.fields["camera_orientation"][i]))
        ob = run.track("/object/state")
        assert np.allclose(scene.body.position, ob.fields["position"][ob.index(t)])
        xd = run.track("/grasping/arm").at("x_d", t)
        assert scene.reach.visible and np.allclose(scene.reach.position, xd[:3])
        assert scene.recognised.visible
    assert scene.phase_label.text == "hold"  # t = 0.9 s: holding (schedule 0.8-1.3 s)
    viewer.seek(0.2)
    assert scene.phase_label.text == "track"


def test_the_chip_image_is_shown_on_the_frustum(viewer):
    scene = viewer.scenes[0]
    viewer.seek(0.5)
    img = scene.frustum.image
    assert img is not None and img.shape == (128, 128, 3)
    rows = viewer.runs[0].track("/vision/chip").at("rows", 0.5)
    bits = chip_image(rows, 16, 16)[::8, ::8, 0] > 128
    assert bits.sum() == sum(bin(int(r)).count("1") for r in rows) > 0
    assert bits[7, 6] and not bits[0, 0]  # pixel (u=6, v=7) is set by row 7's bit 6


def test_fig9_plots_are_offered(viewer):
    titles = [p.title for p in viewer.scenes[0].plots()]
    assert titles[0].startswith("Y (m)") and titles[1].startswith("X (m)")
    y = viewer.scenes[0].plots()[0].series[0].signal(viewer.runs[0])
    assert y is not None and len(y[0]) == len(viewer.runs[0].track("/grasping/arm"))


def test_the_human_hand_is_drawn_behind_the_object_and_moves_with_it(tmp_path):
    """The human hand that moves the object (/human/state's target): a body of the grasp scene,
    on the far side of the constraint plane from the arm, in the camera's fitted view."""
    from replay.resources import scenario_dir
    from replay.runner import Runner
    from replay.scenario import load_scenario

    sc = load_scenario(scenario_dir() / "grasp_hexahedron.yaml", ["timing.duration=0.15"])
    log = Runner(sc).run(tmp_path / "grasp.mcap").path
    v = Viewer.open([log], port=0)
    try:
        scene = v.scenes[0]
        (hand,) = [b for b in scene.bodies() if b.name == "human_hand"]
        run = v.runs[0]
        human = run.track("/human/state")
        n = np.asarray(scene.params.plane_normal, float) / np.linalg.norm(scene.params.plane_normal)
        seen = []
        for t in (0.05, 0.14):
            pos, _ = hand.pose(run, t)
            target = np.asarray(human.fields["target"][human.index(t)], float)
            off = np.asarray(pos) - target
            assert np.linalg.norm(off - np.dot(off, n) * n) < 1e-9  # on the normal through it
            assert abs(np.dot(pos, n)) > abs(np.dot(target, n))  # farther from the arm's base
            seen.append(pos)
        assert np.linalg.norm(np.subtract(seen[1], seen[0])) > 1e-3  # it moves with the path
        lo, hi = v.fitted()
        assert np.all(np.asarray(seen[0]) >= lo - 0.05) and np.all(np.asarray(seen[0]) <= hi + 0.05)
    finally:
        v.stop()
