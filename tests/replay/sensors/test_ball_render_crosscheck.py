"""Cross-check of the OpenCV silhouette renderer against PyBullet's TinyRenderer.

The stereo ball camera never calls PyBullet (too slow for two 1 kHz cameras); here the same
sphere, seen through the same intrinsics and extrinsics (PyBullet view and projection matrices
built from our pinhole cameras), is rendered by ``getCameraImage`` (DIRECT, TinyRenderer) and
the segmentation mask's centroid and pixel count are compared with ours.

Two facts about TinyRenderer, measured here:
- it samples a pixel at its *corner*, not its centre: with image rows top-down, its centroids
  sit at (u + 0.5, v - 0.5) of ours (OpenCV's convention, integer = pixel centre); this is checked
  and removed before comparing;
- ``GEOM_SPHERE`` is a coarse mesh (areas ~7 % small), so the sphere is given as a 64 x 32
  UV-sphere mesh (areas within ~1 % of the exact ellipse for big spheres).
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pybullet as p
import pytest
from pybullet_utils import bullet_client

from replay.scene import Scene, Sphere
from replay.sensors.silhouette import sphere_ellipse
from replay.sensors.stereo import StereoBallCamera, StereoBallCameraParams

PARAMS = StereoBallCameraParams(threshold=0.5 * 255 * (0.1 + 0.9))  # half-coverage level
CORNER_OFFSET = np.array([0.5, -0.5])  # TinyRenderer - ours, px
POSITIONS = [
    (1.0, 0.0, 0.6),
    (1.5, 0.1, 0.7),
    (2.0, -0.05, 0.85),
    (1.2, 0.2, 0.9),
    (0.9, -0.2, 0.5),
    (1.7, -0.15, 0.6),
]


def uv_sphere(r: float, n_lon: int = 64, n_lat: int = 32):
    verts = [[0.0, 0.0, r]]
    for i in range(1, n_lat):
        th = math.pi * i / n_lat
        for j in range(n_lon):
            ph = 2.0 * math.pi * j / n_lon
            verts.append(
                [r * math.sin(th) * math.cos(ph), r * math.sin(th) * math.sin(ph), r * math.cos(th)]
            )
    verts.append([0.0, 0.0, -r])

    def v(i, j):
        return 1 + (i - 1) * n_lon + (j % n_lon)

    idx = []
    for j in range(n_lon):
        idx += [0, v(1, j), v(1, j + 1)]
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            idx += [v(i, j), v(i + 1, j), v(i, j + 1), v(i, j + 1), v(i + 1, j), v(i + 1, j + 1)]
    last = len(verts) - 1
    for j in range(n_lon):
        idx += [last, v(n_lat - 1, j + 1), v(n_lat - 1, j)]
    return verts, idx


class Tiny:
    """A DIRECT PyBullet client with one white sphere mesh per radius."""

    def __init__(self):
        self.bc = bullet_client.BulletClient(connection_mode=p.DIRECT)
        self.bodies: dict[float, int] = {}

    def body(self, radius: float) -> int:
        if radius not in self.bodies:
            verts, idx = uv_sphere(radius)
            vs = self.bc.createVisualShape(
                p.GEOM_MESH, vertices=verts, indices=idx, rgbaColor=[1, 1, 1, 1]
            )
            self.bodies[radius] = self.bc.createMultiBody(
                baseMass=0, baseVisualShapeIndex=vs, basePosition=[0, 0, -50]
            )
        return self.bodies[radius]

    def mask(self, cam, params, pos, radius: float) -> np.ndarray:
        uid = self.body(radius)
        for other in self.bodies.values():
            self.bc.resetBasePositionAndOrientation(other, [0, 0, -50], [0, 0, 0, 1])
        self.bc.resetBasePositionAndOrientation(uid, list(pos), [0, 0, 0, 1])
        # OpenGL camera: looks along -z, y up = our camera's -y
        view = self.bc.computeViewMatrix(
            cam.position.tolist(),
            (cam.position + cam.rotation[:, 2]).tolist(),
            (-cam.rotation[:, 1]).tolist(),
        )
        proj = self.bc.computeProjectionMatrixFOV(
            math.degrees(params.fov), params.width / params.height, 0.01, 20.0
        )
        w, h, _, _, seg = self.bc.getCameraImage(
            params.width, params.height, view, proj, renderer=p.ER_TINY_RENDERER
        )
        return (np.asarray(seg).reshape(h, w) == uid).astype(np.uint8)

    def close(self):
        self.bc.disconnect()


@pytest.fixture(scope="module")
def tiny():
    t = Tiny()
    yield t
    t.close()


def centroid(mask):
    m = cv2.moments(mask, binaryImage=True)
    assert m["m00"] > 0
    return np.array([m["m10"], m["m01"]]) / m["m00"], m["m00"]


def compare(tiny, radius):
    """(TinyRenderer - ours) centroid offsets (px, raw) and area ratios, both cameras."""
    cams = StereoBallCamera.make_cameras(PARAMS)
    offsets, ratios = [], []
    for pos in POSITIONS:
        images = StereoBallCamera.render(Scene([Sphere("ball", pos, radius, 0.9)]), PARAMS)
        for cam, img in zip(cams, images):
            ours = StereoBallCamera.blob(img, PARAMS)
            assert ours is not None
            c, a = centroid(tiny.mask(cam, PARAMS, pos, radius))
            offsets.append(c - (ours["u"], ours["v"]))
            ratios.append(a / ours["area"])
    return np.array(offsets), np.array(ratios)


def test_pixel_convention_offset_is_half_a_pixel(tiny):
    """TinyRenderer's centroids sit at (+0.5, -0.5) px of ours: it samples pixel corners."""
    offsets, _ = compare(tiny, 0.08)
    np.testing.assert_allclose(offsets.mean(axis=0), CORNER_OFFSET, atol=0.08)


@pytest.mark.parametrize(
    "radius, tol_px, tol_area",
    [
        (0.08, 0.25, 0.04),  # 75-530 px blobs: measured <= 0.13 px, <= 2.7 %
        (0.04, 0.3, 0.15),  # 20-130 px: <= 0.17 px, <= 11 % (pixel-count noise of small blobs)
    ],
)
def test_centroids_and_areas_agree_with_tinyrenderer(tiny, radius, tol_px, tol_area):
    offsets, ratios = compare(tiny, radius)
    d = np.linalg.norm(offsets - CORNER_OFFSET, axis=1)
    assert d.max() < tol_px, d
    assert np.abs(ratios - 1.0).max() < tol_area, ratios
    if radius >= 0.08:
        assert abs(np.mean(ratios) - 1.0) < 0.015  # no area bias


def test_the_real_ball_agrees_within_half_a_pixel(tiny):
    """The 35 mm ball (2-8 px across here): centroids within 0.5 px (measured <= 0.35 px, the
    binary mask of a few pixels being the coarser of the two)."""
    offsets, _ = compare(tiny, 0.0175)
    d = np.linalg.norm(offsets - CORNER_OFFSET, axis=1)
    assert d.max() < 0.5, d


def test_triangulating_tinyrenderer_masks_recovers_the_ball(tiny):
    """End to end through PyBullet's own camera model: masks' centroids (corner offset removed)
    triangulated by the sensor land within 1 cm of the centre, median 2 mm (0.08 m sphere,
    0.6-2 m away; measured: worst 6.2 mm, median 1.2 mm, the binary masks' own sampling), and the
    offset matters (without it the median is 7.9 mm). So the view/projection matrices and our
    K [R | t] describe the same cameras."""
    s = StereoBallCamera(PARAMS, rng=np.random.default_rng(0))
    err, raw = [], []
    for pos in POSITIONS:
        c = [centroid(tiny.mask(cam, PARAMS, pos, 0.08))[0] for cam in s.cameras]
        err.append(np.linalg.norm(s.locate(c[0] - CORNER_OFFSET, c[1] - CORNER_OFFSET, 0.08) - pos))
        raw.append(np.linalg.norm(s.locate(c[0], c[1], 0.08) - pos))
    err, raw = 1e3 * np.array(err), 1e3 * np.array(raw)
    print(
        "triangulated TinyRenderer masks: worst %.2f, median %.2f mm (without the offset: "
        "%.1f, %.1f mm)" % (err.max(), np.median(err), raw.max(), np.median(raw))
    )
    assert err.max() < 10.0 and np.median(err) < 2.0
    assert np.median(raw) > 3.0 * np.median(err)


def test_our_areas_match_the_exact_ellipse(tiny):
    """Independently of TinyRenderer: pixels above the half-coverage level count the ellipse's
    area within 3 % for the big sphere."""
    cams = StereoBallCamera.make_cameras(PARAMS)
    for pos in POSITIONS:
        images = StereoBallCamera.render(Scene([Sphere("ball", pos, 0.08, 0.9)]), PARAMS)
        for cam, img in zip(cams, images):
            e = sphere_ellipse(cam, pos, 0.08)
            assert StereoBallCamera.blob(img, PARAMS)["area"] == pytest.approx(e.area, rel=0.03)
