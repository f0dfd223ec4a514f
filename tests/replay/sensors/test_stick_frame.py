"""The stick camera's compiled frame (``_stick_frame.frame``) against its Python reference
(``StickCamera.measure_reference``): the same window, the same pixels and the same measurement,
to the bit (the capture's closed loop is sensitive to one pixel)."""

import math

import numpy as np

from replay.scene import Box, Cylinder, Scene, Sphere
import pytest

from replay.sensors import stick_camera
from replay.sensors.stick_camera import StickCamera, StickCameraParams
from replay.spatial import yaw_quaternion

if stick_camera._stick_frame is None or stick_camera._pixels is None:
    pytest.skip("the stick-frame accelerator is not built", allow_module_level=True)

STICK_3STEP = dict(position=[0.0, 0.2, 1.0], target=[0.0, 0.2, 0.0], fov_x=0.846)


def table_scene(rng, tips=2):
    """The airtable plant's scene (plants/airtable/plant.py scene): a stick, its marker and two
    fingertips, at a random pose with the tips near the stick or anywhere on the table."""
    x, y, th = rng.uniform(-0.3, 0.3), rng.uniform(-0.1, 0.5), rng.uniform(-math.pi, math.pi)
    q = yaw_quaternion(th)
    prims = [
        Box("stick", (x, y, 0.0025), q, (0.1, 0.01, 0.005), albedo=0.3),
        Box("marker", (x, y, 0.00525), q, (0.08, 0.006, 0.0005), albedo=1.0),
    ]
    for k in range(tips):
        if rng.uniform() < 0.7:  # near the stick: over it, at its side or over the marker
            s, d = rng.uniform(-0.06, 0.06), rng.uniform(-0.012, 0.012)
            tx, ty = (
                x + s * math.cos(th) - d * math.sin(th),
                y + s * math.sin(th) + d * math.cos(th),
            )
        else:
            tx, ty = rng.uniform(-0.4, 0.4), rng.uniform(-0.2, 0.6)
        prims.append(Cylinder(f"tip{k}", (tx, ty, 0.005), (0, 0, 0, 1), 0.005, 0.01, albedo=0.1))
    return Scene(prims)


def agree(cam: StickCamera, scene: Scene) -> bool:
    fast = cam.measure(0.0, scene)
    img, window = cam._last
    ref = cam.measure_reference(0.0, scene)
    return fast == ref and window == cam._last[1] and np.array_equal(img, cam._last[0])


def test_frame_equals_the_reference_over_random_scenes():
    rng = np.random.default_rng(11)
    cam = StickCamera(StickCameraParams(**STICK_3STEP), rng=np.random.default_rng(0))
    n, same, seen, fast = 400, 0, 0, 0
    for i in range(n):
        scene = table_scene(rng, tips=i % 3)
        if i % 2:
            scene.primitives.reverse()  # another drawing order
        fast += cam._frame(scene) is not None
        same += agree(cam, scene)
        seen += cam.measure(0.0, scene) is not None
    print(f"compiled frame = reference: {same}/{n} ({fast} compiled, {seen} with a measurement)")
    assert same == n
    assert fast > 0.9 * n and seen > 0.8 * n  # the compiled path did most frames


def test_frames_the_compiled_path_leaves_to_the_reference():
    rng = np.random.default_rng(3)
    cam = StickCamera(StickCameraParams(**STICK_3STEP), rng=np.random.default_rng(0))
    scene = table_scene(rng)
    # no marker, a marker out of view, a sphere in the scene: the reference does them
    no_marker = Scene([p for p in scene.primitives if p.name != "marker"])
    away = Scene(
        [Box("marker", (5.0, 5.0, 0.005), (0, 0, 0, 1), (0.08, 0.006, 0.0005), albedo=1.0)]
    )
    ball = Scene([*scene.primitives, Sphere("ball", (0.0, 0.2, 0.05), 0.02, albedo=0.8)])
    for s in (no_marker, away, ball):
        assert cam._frame(s) is None
        assert agree(cam, s)
    assert cam.measure(0.0, no_marker) is None and cam._last[1] == (0, 0, 512, 512)
    # with noise, measure is the reference with its random pixels
    noisy = StickCamera(
        StickCameraParams(**STICK_3STEP, noise_sigma=10.0), rng=np.random.default_rng(5)
    )
    again = StickCamera(
        StickCameraParams(**STICK_3STEP, noise_sigma=10.0), rng=np.random.default_rng(5)
    )
    assert noisy.measure(0.0, scene) == again.measure_reference(0.0, scene)


def test_moments_kernel_equals_pixels_marker_moments():
    """_stick_frame.moments (the frame's marker moments, summing only nonzero weights) against
    _pixels.marker_moments on seeded random images: rendered stick frames, with noise, and
    blobs of random pixels at random thresholds; the same tuple, to the bit."""
    from replay.sensors import _pixels, _stick_frame

    rng = np.random.default_rng(5)
    cam = StickCamera(StickCameraParams(**STICK_3STEP, noise_sigma=0.0), rng=rng)
    images = []
    for i in range(150):
        cam.measure_reference(0.0, table_scene(rng, tips=i % 3))
        img, window = cam._last
        images.append((img, window[0], window[1], 192.0))
        noisy = np.clip(img + rng.normal(0.0, 20.0, img.shape), 0, 255).astype(np.uint8)
        images.append((noisy, window[0], window[1], float(rng.uniform(100.0, 250.0))))
    for _ in range(150):
        h, w = rng.integers(1, 40, 2)
        img = (rng.uniform(size=(h, w)) < rng.uniform(0.05, 0.9)) * rng.integers(0, 256, (h, w))
        thr = float(rng.choice([-1.0, 0.0, 254.5, 255.0, rng.uniform(0, 255)]))
        images.append((img.astype(np.uint8), int(rng.integers(0, 3)), int(rng.integers(0, 3)), thr))
    found = 0
    for img, ox, oy, thr in images:
        h, w = img.shape
        args = (np.ascontiguousarray(img), w, h, thr, 5, ox, oy, 512, 512)
        ref = _pixels.marker_moments(*args)
        assert _stick_frame.moments(*args) == ref
        found += ref is not None
    print(f"moments kernel = reference on {len(images)} images ({found} with a blob)")
    assert found > 0.4 * len(images)
