"""The cameras' optional compiled kernels (replay/sensors/_pixels.c) and their pure-Python paths
against the NumPy/OpenCV pipelines
they replaced, kept here as references, and the stated accuracy of the stick camera.

Each comparison runs over seeded random poses (with and without pixel noise) and reports the
share of frames that agree; the rasteriser itself is checked against the closed-form coverage in
test_raster.py."""

import math

import cv2
import numpy as np
import pytest

from replay.messages import pack_rows, unpack_rows
from replay.scene import Box, Cylinder, Scene, Sphere
from replay.sensors.raster import _pixels  # the accelerator, or None where not built
from replay.sensors.silhouette import _body_points, project_hull
from replay.sensors.stereo import StereoBallCamera, StereoBallCameraParams
from plants.airtable.camera import (
    StickCamera,
    StickCameraParams,
    _moments_opencv,
    _projected_items,
    hull_window,
    render_scene,
    wrap_half_pi,
)
from replay.spatial import quaternion_matrix, yaw_quaternion
from test_raster import polygon_coverage  # the closed-form reference, beside this file

# --- references: the OpenCV pipelines the kernels replaced ------------------------------------


def reference_marker_moments(image, params, origin=(0, 0)):
    """The stick camera's marker moments by the OpenCV pipeline _pixels.marker_moments replaced:
    the camera's own pure-Python path (``_moments_opencv``), as a dict."""
    m = _moments_opencv(image, params, origin)
    if m is None:
        return None
    return {"u": m[0], "v": m[1], "angle": m[2], "pixels": m[3], "background": m[4]}


def reference_ball_blob(image, p):
    """The stereo camera's blob moments as OpenCV computed them before _pixels.ball_blob."""
    h, w = image.shape
    _, mask = cv2.threshold(image, p.threshold, 1, cv2.THRESH_BINARY)
    ex, ey, ew, eh = cv2.boundingRect(mask)
    if ew == 0:
        return None
    ex0, ey0 = max(ex - 4, 0), max(ey - 4, 0)
    ex1, ey1 = min(ex + ew + 4, w), min(ey + eh + 4, h)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask[ey0:ey1, ex0:ex1], connectivity=8)
    i = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    bx, by, bw, bh, area = (int(v) for v in stats[i])
    bx, by = bx + ex0, by + ey0
    if area < p.min_pixels or bx == 0 or by == 0 or bx + bw == w or by + bh == h:
        return None
    x0, y0 = max(bx - 4, 0), max(by - 4, 0)
    x1, y1 = min(bx + bw + 4, w), min(by + bh + 4, h)
    labels = labels[y0 - ey0 : y1 - ey0, x0 - ex0 : x1 - ex0]
    blob = (labels == i).astype(np.uint8)
    if p.moments == "binary":
        m = cv2.moments(blob, binaryImage=True)
        return {"u": x0 + m["m10"] / m["m00"], "v": y0 + m["m01"] / m["m00"], "area": area}
    roi = image[y0:y1, x0:x1].astype(np.float32)
    free = labels == 0
    region = cv2.dilate(blob, np.ones((5, 5), np.uint8)).astype(bool) & (free | blob.astype(bool))
    ring = roi[~region & free]
    if ring.size:
        background = float(np.partition(ring, ring.size // 2)[ring.size // 2])
    else:
        background = 255.0 * p.background
    weight = np.where(region, roi - np.float32(background), np.float32(0.0))
    m = cv2.moments(weight)
    if m["m00"] <= 0.0:
        return None
    return {
        "u": x0 + m["m10"] / m["m00"],
        "v": y0 + m["m01"] / m["m00"],
        "area": area,
        "background": background,
    }


# --- scenes ---------------------------------------------------------------------------------

# the stick_3step geometry: camera 1 m above (0, 0.2), 0.846 rad across 512 px (1.8 mm/px);
# the airtable plant's stick (0.3 x 0.01 m, albedo 0.3) and marker (0.08 x 0.006 m, white)
STICK_3STEP = dict(position=[0.0, 0.2, 1.0], target=[0.0, 0.2, 0.0], fov_x=0.846)


def stick_scene(x, y, theta, tips=()):
    q = yaw_quaternion(theta)
    prims = [
        Box("stick", (x, y, 0.0025), q, (0.3, 0.01, 0.005), albedo=0.3),
        Box("marker", (x, y, 0.00525), q, (0.08, 0.006, 0.0005), albedo=1.0),
    ]
    for k, (tx, ty) in enumerate(tips):
        prims.append(Cylinder(f"tip{k}", (tx, ty, 0.01), (0, 0, 0, 1), 0.005, 0.02, albedo=0.1))
    return Scene(prims)


def random_stick_scenes(n, seed):
    rng = np.random.default_rng(seed)
    out = []
    for k in range(n):
        x, y, th = rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.5), rng.uniform(-math.pi, math.pi)
        # every third pose with fingertips near (and sometimes over) the marker's ends
        tips = []
        if k % 3 == 0:
            for s in (-1.0, 1.0):
                d = rng.uniform(0.03, 0.06)
                tips.append((x + s * d * math.cos(th), y + s * d * math.sin(th)))
        out.append(((x, y, th), stick_scene(x, y, th, tips)))
    return out


# --- the stick camera -----------------------------------------------------------------------


@pytest.mark.parametrize("sigma", [0.0, 8.0])
def test_compiled_marker_moments_equal_the_opencv_pipeline(sigma):
    """On the very frames the sensor took (its window, with its noise), the compiled moments
    are OpenCV's to 1e-9 px / 1e-9 rad in every frame either measured."""
    cam = StickCamera(
        StickCameraParams(**STICK_3STEP, noise_sigma=sigma), rng=np.random.default_rng(5)
    )
    agree = measured = 0
    scenes = random_stick_scenes(120, seed=21)
    for _, scene in scenes:
        cam.measure(0.0, scene)
        img, window = cam._last
        got = StickCamera.marker_moments(img, cam.params, origin=window[:2])
        ref = reference_marker_moments(img, cam.params, origin=window[:2])
        assert (got is None) == (ref is None)
        if ref is None:
            continue
        measured += 1
        ok = (
            abs(got["u"] - ref["u"]) < 1e-9
            and abs(got["v"] - ref["v"]) < 1e-9
            and abs(wrap_half_pi(got["angle"] - ref["angle"])) < 1e-9
            and got["pixels"] == ref["pixels"]
            and got["background"] == ref["background"]
        )
        agree += ok
    print(f"sigma {sigma}: {agree}/{measured} frames agree, {measured}/{len(scenes)} measured")
    assert measured >= 0.9 * len(scenes) and agree == measured


def test_only_the_primitives_near_the_window_are_drawn_and_it_changes_nothing():
    """The marker window rendered from the culled primitives equals the same window rendered
    from all of them (the fingertips far away are skipped, near ones drawn)."""
    cam = StickCamera(StickCameraParams(**STICK_3STEP), rng=np.random.default_rng(0))
    rng = np.random.default_rng(4)
    for _ in range(60):
        x, y, th = rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.5), rng.uniform(-math.pi, math.pi)
        tips = [tuple(rng.uniform(-0.4, 0.4, 2) + (x, y)) for _ in range(3)]
        tips.append((x + 0.04 * math.cos(th), y + 0.04 * math.sin(th)))  # on the marker's end
        scene = stick_scene(x, y, th, tips)
        cam.measure(0.0, scene)
        img, window = cam._last
        full = render_scene(cam.camera, scene, background=cam.params.background, window=window)
        np.testing.assert_array_equal(img, np.clip(np.rint(full), 0, 255).astype(np.uint8))


def _area(P):
    return 0.5 * abs(np.sum(P[:, 0] * np.roll(P[:, 1], -1) - np.roll(P[:, 0], -1) * P[:, 1]))


def test_hulls_equal_opencv_convex_hulls():
    """_pixels.project_hull against projecting with NumPy and cv2.convexHull: the same polygon
    (the same vertices, to the bit) for boxes and cylinders in random poses."""
    cam = StickCamera.make_camera(StickCameraParams(**STICK_3STEP))
    rng = np.random.default_rng(8)
    for k in range(200):
        q = rng.normal(size=4)
        pos = (*rng.uniform(-0.3, 0.3, 2), rng.uniform(0.0, 0.5))
        if k % 2:
            prim = Box("b", pos, tuple(q), tuple(rng.uniform(0.002, 0.2, 3)))
        else:
            prim = Cylinder("c", pos, tuple(q), rng.uniform(0.002, 0.05), rng.uniform(0.002, 0.2))
        body = _body_points(prim)
        hull, box = project_hull(cam, body, prim.orientation, prim.position)
        world = body @ quaternion_matrix(prim.orientation).T + np.asarray(pos)
        uv = cam.project(world).astype(np.float32)
        ref = cv2.convexHull(uv).reshape(-1, 2).astype(np.float64)
        assert _area(hull) == pytest.approx(_area(ref), rel=1e-5, abs=1e-3)
        # the same vertices to the bit: the same float32 pixels as NumPy's projection
        d = np.abs(hull[:, None, :] - ref[None, :, :]).max(axis=2)
        assert d.min(axis=1).max() == 0.0 and d.min(axis=0).max() == 0.0
        np.testing.assert_allclose(box, [*hull.min(axis=0), *hull.max(axis=0)])
    # behind the camera: no hull
    behind = Box("b", (0.0, 0.2, 1.5), (0, 0, 0, 1), (0.1, 0.1, 0.1))
    assert project_hull(cam, _body_points(behind), behind.orientation, behind.position) is None


def reference_measure(cam, scene):
    """(x, y, theta) as the stick camera measured before its kernels: the same silhouettes and
    window, rendered with the closed-form coverage (test_raster.py) and measured with OpenCV."""
    p = cam.params
    items = _projected_items(cam.camera, scene)
    hull_box = next(it[4] for it in items if it[3] == p.marker)
    x0, y0, x1, y1 = hull_window(cam.camera, hull_box)
    img = np.full((y1 - y0, x1 - x0), 255.0 * p.background, np.float32)
    for _, albedo, hull, _, _ in items:
        cov = polygon_coverage(hull, x0, y0, x1 - x0, y1 - y0)
        alpha = np.minimum(np.maximum(cov, 0.0), 1.0).astype(np.float32)
        img += alpha * (np.float32(255.0 * albedo) - img)
    img8 = np.clip(np.rint(img), 0, 255).astype(np.uint8)
    f = reference_marker_moments(img8, p, origin=(x0, y0))
    if f is None:
        return None
    z = float(scene.get(p.marker).position[2])
    u, v, a = f["u"], f["v"], f["angle"]
    pts = cam.camera.backproject_to_height(
        np.array([[u, v], [u + 10.0 * math.cos(a), v + 10.0 * math.sin(a)]]), z
    )
    return pts[0, 0], pts[0, 1], math.atan2(pts[1, 1] - pts[0, 1], pts[1, 0] - pts[0, 0])


def test_stick_camera_accuracy_bias_and_noise_before_and_after():
    """The stated accuracy (plants/airtable/camera.py): noise-free, over 200 random poses
    of the stick_3step geometry (1.8 mm per pixel, no fingertips), the error of the measured
    (x, y, theta) against the true pose. Measured, after (the compiled kernels) and before (the
    closed-form coverage and OpenCV moments) alike: bias x +0.4, y -0.5 um, theta +0.0005 deg;
    std x 7.6, y 8.3 um, theta 0.011 deg; worst 43 um (1/40 px), 0.097 deg. The two agree to
    1e-9 m in every pose: the kernels compute what the reference did."""
    cam = StickCamera(StickCameraParams(**STICK_3STEP), rng=np.random.default_rng(0))
    after, before = [], []
    for (x, y, th), _ in random_stick_scenes(200, seed=31):
        scene = stick_scene(x, y, th)
        m, r = cam.measure(0.0, scene), reference_measure(cam, scene)
        assert m is not None and r is not None
        after.append((m.x - x, m.y - y, wrap_half_pi(m.theta - th)))
        before.append((r[0] - x, r[1] - y, wrap_half_pi(r[2] - th)))
    for name, e in (("after", np.array(after)), ("before", np.array(before))):
        bias, std = e.mean(axis=0), e.std(axis=0)
        worst_p, worst_a = np.hypot(e[:, 0], e[:, 1]).max(), np.abs(e[:, 2]).max()
        print(
            f"{name}: bias x {bias[0] * 1e6:+.2f} y {bias[1] * 1e6:+.2f} um, theta "
            f"{math.degrees(bias[2]):+.4f} deg; std x {std[0] * 1e6:.1f} y {std[1] * 1e6:.1f} um,"
            f" theta {math.degrees(std[2]):.4f} deg; worst {worst_p * 1e6:.0f} um "
            f"{math.degrees(worst_a):.3f} deg"
        )
        assert np.all(np.abs(bias[:2]) < 3e-6) and abs(bias[2]) < math.radians(0.005)
        assert np.all(std[:2] < 12e-6) and std[2] < math.radians(0.02)
        assert worst_p < 60e-6 and worst_a < math.radians(0.15)
    np.testing.assert_allclose(after, before, atol=1e-9)


# --- the stereo camera ----------------------------------------------------------------------


def throw_scene(rng, box=False):
    x = rng.uniform(0.7, 2.3)
    pos = (x, rng.uniform(-0.1, 0.1), 0.5 + (x - 0.7) * 0.3 + rng.uniform(-0.05, 0.05))
    prims = [Sphere("ball", pos, 0.0175, albedo=0.9)]
    if box:
        prims.insert(0, Box("wall", (1.2, 0.3, 0.7), (0, 0, 0, 1), (0.2, 0.05, 0.3), albedo=0.4))
    return Scene(prims)


@pytest.mark.parametrize("sigma,moments", [(0.0, "grey"), (6.0, "grey"), (6.0, "binary")])
def test_compiled_ball_blob_equals_the_opencv_pipeline(sigma, moments):
    p = StereoBallCameraParams(noise_sigma=sigma, moments=moments)
    s = StereoBallCamera(p, rng=np.random.default_rng(2))
    rng = np.random.default_rng(9)
    agree = found = n = 0
    for k in range(80):
        s.measure(0.0, throw_scene(rng, box=k % 4 == 0))
        for img in s.last_images:
            n += 1
            got, ref = StereoBallCamera.blob(img, p), reference_ball_blob(img, p)
            assert (got is None) == (ref is None)
            if ref is None:
                continue
            found += 1
            agree += (
                abs(got["u"] - ref["u"]) < 1e-9
                and abs(got["v"] - ref["v"]) < 1e-9
                and got["area"] == ref["area"]
                and (moments == "binary" or got["background"] == ref["background"])
            )
    print(f"sigma {sigma} {moments}: {agree}/{found} blobs agree, {found}/{n} images with a blob")
    assert found >= 0.8 * n and agree == found


def test_the_rendered_window_measures_as_the_whole_image():
    """Noise-free, the stereo camera renders only the box around the silhouettes: the same
    measurement (to 1e-12) as rendering both whole images, and the same whole images. On the
    step-by-step path, whose window is ``_window`` (the compiled one is held equal to it by
    test_compiled_stereo_frame_equals_the_step_by_step_measurement)."""
    p = StereoBallCameraParams()
    win = StereoBallCamera(p, rng=np.random.default_rng(0))
    whole = StereoBallCamera(p, rng=np.random.default_rng(0))
    whole._window = lambda camera, boxes: (0, 0, p.width, p.height)  # type: ignore[method-assign]
    rng = np.random.default_rng(12)
    for k in range(60):
        scene = throw_scene(rng, box=k % 3 == 0)
        a, b = win.measure(0.0, scene), whole.measure(0.0, scene)
        assert (a is None) == (b is None)
        if a is not None:
            np.testing.assert_allclose(a.position, b.position, atol=1e-12)
            assert a.features == b.features
        for x, y in zip(win.last_images, whole.last_images):
            np.testing.assert_array_equal(x, y)
    assert win.last_images[0].shape == (p.height, p.width)


def test_triangulation_equals_opencv():
    s = StereoBallCamera(StereoBallCameraParams(), rng=np.random.default_rng(0))
    rng = np.random.default_rng(3)
    for _ in range(200):
        X = np.array([rng.uniform(0.7, 2.3), rng.uniform(-0.2, 0.2), rng.uniform(0.4, 1.0)])
        uv = [c.project(X) + rng.normal(0, 0.3, 2) for c in s.cameras]  # inconsistent rays too
        ref = cv2.triangulatePoints(
            s.projections[0], s.projections[1], uv[0].reshape(2, 1), uv[1].reshape(2, 1)
        ).ravel()
        np.testing.assert_allclose(s.triangulate(*uv), ref[:3] / ref[3], atol=1e-9)


# --- the vision chip ------------------------------------------------------------------------


@pytest.mark.skipif(_pixels is None, reason="the _pixels accelerator is not built")
def test_compiled_pack_rows_equals_pack_rows():
    rng = np.random.default_rng(1)
    for w in (1, 2, 16, 62, 63):
        bits = rng.random((int(rng.integers(1, 20)), w)) < 0.4
        rows, count = _pixels.pack_rows(bits, w, bits.shape[0])
        assert rows == pack_rows(bits) and count == int(bits.sum())
    with pytest.raises(ValueError):
        _pixels.pack_rows(np.zeros((2, 64), bool), 64, 2)  # pack_rows' int64: 63 bits


def test_pack_rows_is_exact_at_any_width():
    """Rows are Python ints: a chip wider than 63 px (int64) packs and unpacks exactly."""
    rng = np.random.default_rng(2)
    for w in (1, 8, 63, 64, 65, 80, 200):
        bits = rng.random((int(rng.integers(1, 12)), w)) < 0.5
        rows = pack_rows(bits)
        assert rows == [sum(1 << u for u in range(w) if row[u]) for row in bits]
        assert (unpack_rows(rows, w) == bits).all()


def test_window_of_a_box_on_the_stick_camera_is_clipped_to_the_image():
    cam = StickCamera.make_camera(StickCameraParams(**STICK_3STEP))
    assert hull_window(cam, (-20.0, 5.0, 3.0, 9.5)) == (0, 0, 12, 19)  # + 8 px, clipped
    assert hull_window(cam, (600.0, 5.0, 700.0, 9.5)) is None


@pytest.mark.skipif(_pixels is None, reason="the _pixels accelerator is not built")
def test_kernels_refuse_bad_buffers_and_see_nothing_in_empty_images():
    assert StereoBallCamera.blob(np.zeros((0, 0), np.uint8)) is None
    assert StickCamera.marker_moments(np.zeros((0, 5), np.uint8), StickCameraParams()) is None
    with pytest.raises(ValueError, match="negative image size"):
        _pixels.coverage(np.zeros((3, 2)), 0, 0, np.zeros(4), -2, -2)
    with pytest.raises(ValueError, match="img"):  # a float64 image where float32 is meant
        _pixels.composite([np.zeros((3, 2))], [1.0], 0, 0, np.zeros((4, 4)), 4, 4)
    with pytest.raises(ValueError, match="body"):
        _pixels.project_hull(
            np.zeros(7),
            (0, 0, 0, 1.0),
            (0, 0, 0.0),
            np.eye(3),
            np.zeros(3),
            1,
            1,
            0,
            0,
            np.zeros(4),
        )
