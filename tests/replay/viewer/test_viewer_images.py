"""The viewer's camera panel: the logged stereo images at the shown time, the measured centroid
drawn where the vision found it."""

from __future__ import annotations

import numpy as np
import pytest

from replay.log import LogReader
from replay.runner import Runner
from replay.scenario import load_scenario
from replay.viewer.app import Viewer
from replay.viewer.images import MARK, SIZE, load_image_tracks, mark_radius

from conftest import ROOT


@pytest.fixture(scope="module")
def catch_log(tmp_path_factory):
    sc = load_scenario(ROOT / "scenarios" / "catch_optimised.yaml", ["timing.duration=0.12"])
    return Runner(sc).run(tmp_path_factory.mktemp("v") / "catch.mcap").path


def _is_mark(px) -> bool:
    return bool(np.abs(np.asarray(px, int) - MARK).max() < 30)


def test_image_tracks_mark_the_measured_centroid(catch_log):
    r = LogReader(catch_log)
    sensors = {"stereo": {"type": "stereo_ball"}}
    tracks = load_image_tracks(catch_log, sensors)
    assert [t.topic for t in tracks] == ["/camera/stereo/cam0", "/camera/stereo/cam1"]
    vision = list(r.messages("/vision/object"))
    assert vision
    for view, tr in enumerate(tracks):
        assert len(tr.marks) == len(vision)
        m = vision[len(vision) // 2]
        k = tr.index(m.t)
        assert tr.t_ns[k] == m.t_ns
        rgb = tr.frame(k)
        assert rgb.shape == (SIZE, SIZE, 3)
        u, v = m.data["features"]["centroids"][view]
        s = SIZE / 128
        x, y = round((u + 0.5) * s - 0.5), round((v + 0.5) * s - 0.5)
        d = mark_radius(s)
        assert _is_mark(rgb[y, x + d]) and _is_mark(rgb[y - d, x]) and not _is_mark(rgb[y, x])
        before = tr.frame(0)  # the first frame: the ball not yet seen, no cross
        assert not any(_is_mark(p) for p in before.reshape(-1, 3))
    assert tracks[0].index(-1.0) is None


def test_viewer_shows_the_images_with_the_log(catch_log):
    v = Viewer.open([catch_log], port=0)
    try:
        assert v.images is not None and len(v.images.handles) == 2
        t = LogReader(catch_log).series("/vision/object")[-1]["t"]
        v.show(t)
        for handle in v.images.handles:
            img = np.asarray(handle.image)
            assert img.shape == (SIZE, SIZE, 3)
            assert any(_is_mark(p) for p in img.reshape(-1, 3))
    finally:
        v.stop()
