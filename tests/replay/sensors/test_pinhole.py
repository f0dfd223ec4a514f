"""The pinhole camera model: conventions (OpenCV's), round trips, and stereo triangulation."""

import math

import cv2
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from replay.sensors.pinhole import Intrinsics, PinholeCamera, look_at_rotation

from pixel_checks import in_image


def random_camera(rng, width=128, height=96):
    """A camera somewhere around the origin looking at a point near it."""
    eye = rng.uniform(-2.0, 2.0, 3) + np.array([0.0, 0.0, 2.5])
    target = rng.uniform(-0.3, 0.3, 3)
    k = Intrinsics(
        fx=rng.uniform(80, 400),
        fy=rng.uniform(80, 400),
        cx=rng.uniform(40, 80),
        cy=rng.uniform(30, 60),
        width=width,
        height=height,
    )
    return PinholeCamera.look_at(k, eye, target, up=(0.0, 0.0, 1.0))


def test_from_fov_puts_the_field_edge_on_the_image_edge():
    k = Intrinsics.from_fov(640, 480, math.radians(60.0))
    assert k.fx == pytest.approx(320.0 / math.tan(math.radians(30.0)))
    assert k.fy == k.fx
    assert (k.cx, k.cy) == (319.5, 239.5)
    cam = PinholeCamera(k)  # at the origin, looking along world +z
    edge = np.array([math.tan(math.radians(30.0)), 0.0, 1.0])
    u, v = cam.project(edge)
    assert u == pytest.approx(639.5)  # the right edge of the last pixel column
    assert v == pytest.approx(239.5)
    k2 = Intrinsics.from_fov(640, 480, math.radians(60.0), math.radians(40.0))
    assert k2.fy == pytest.approx(240.0 / math.tan(math.radians(20.0)))
    with pytest.raises(ValueError):
        Intrinsics.from_fov(640, 480, math.pi)


def test_look_down_conventions():
    """Straight down with image-up = world +y: world x -> image right, world y -> image up."""
    cam = PinholeCamera.from_fov(
        101,
        101,
        math.radians(40.0),
        eye=(0.2, 0.1, 1.0),
        target=(0.2, 0.1, 0.0),
        up=(0.0, 1.0, 0.0),
    )
    np.testing.assert_allclose(cam.rotation, [[1, 0, 0], [0, -1, 0], [0, 0, -1]], atol=1e-12)
    c = cam.project([0.2, 0.1, 0.0])
    np.testing.assert_allclose(c, [50.0, 50.0], atol=1e-9)
    right = cam.project([0.3, 0.1, 0.0])
    up = cam.project([0.2, 0.2, 0.0])
    assert right[0] > c[0] + 1 and right[1] == pytest.approx(c[1])
    assert up[1] < c[1] - 1 and up[0] == pytest.approx(c[0])


def test_project_agrees_with_cv2_project_points():
    rng = np.random.default_rng(3)
    for _ in range(20):
        cam = random_camera(rng)
        pts = rng.uniform(-0.5, 0.5, (30, 3))
        R, t = cam.extrinsics()
        ref, _ = cv2.projectPoints(pts, cv2.Rodrigues(R)[0], t, cam.intrinsics.K, None)
        np.testing.assert_allclose(cam.project(pts), ref.reshape(-1, 2), rtol=0, atol=1e-8)


def test_projection_matrix_is_the_same_map():
    rng = np.random.default_rng(4)
    cam = random_camera(rng)
    pts = rng.uniform(-0.5, 0.5, (10, 3))
    h = np.column_stack([pts, np.ones(len(pts))]) @ cam.projection_matrix().T
    np.testing.assert_allclose(h[:, :2] / h[:, 2:], cam.project(pts), atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), z=st.floats(-0.2, 0.2))
def test_project_then_backproject_round_trip(seed, z):
    rng = np.random.default_rng(seed)
    cam = random_camera(rng)
    xy = rng.uniform(-0.5, 0.5, (25, 2))
    pts = np.column_stack([xy, np.full(len(xy), z)])
    uv = cam.project(pts)
    np.testing.assert_allclose(cam.backproject_to_height(uv, z), pts, atol=1e-9)
    # a tilted plane through the same points
    normal = np.array([0.1, -0.2, 1.0])
    q = pts - ((pts - pts[0]) @ normal / (normal @ normal))[:, None] * normal
    back = cam.backproject_to_plane(cam.project(q), point=pts[0], normal=normal)
    np.testing.assert_allclose(back, q, atol=1e-9)


def test_ray_passes_through_the_point_and_the_principal_point_is_the_axis():
    rng = np.random.default_rng(5)
    cam = random_camera(rng)
    pts = rng.uniform(-0.5, 0.5, (10, 3))
    origin, d = cam.ray(cam.project(pts))
    np.testing.assert_allclose(origin, cam.position)
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0)
    to_pts = pts - origin
    np.testing.assert_allclose(np.cross(d, to_pts), 0.0, atol=1e-9)
    assert np.all(np.sum(d * to_pts, axis=1) > 0)  # in front, not behind
    _, axis = cam.ray([cam.intrinsics.cx, cam.intrinsics.cy])
    np.testing.assert_allclose(axis, cam.rotation[:, 2], atol=1e-12)


def test_behind_the_camera_and_off_the_sensor():
    cam = PinholeCamera.from_fov(
        64, 48, math.radians(50.0), eye=(0, 0, 1), target=(0, 0, 0), up=(0, 1, 0)
    )
    uv = cam.project([[0, 0, 2.0], [0, 0, 0.0]])
    assert np.all(np.isnan(uv[0])) and np.all(np.isfinite(uv[1]))
    inside = in_image(cam, [[-0.5, -0.5], [63.49, 47.49], [63.5, 10], [10, -0.51], [np.nan, 3]])
    assert inside.tolist() == [True, True, False, False, False]
    # a pixel's ray that points away from the plane does not meet it
    assert np.all(np.isnan(cam.backproject_to_height([31.5, 23.5], 1.5)))


def test_bad_poses_are_refused():
    k = Intrinsics.from_fov(64, 64, 1.0)
    with pytest.raises(ValueError):
        look_at_rotation((0, 0, 1), (0, 0, 0), up=(0, 0, 1))  # up along the view
    with pytest.raises(ValueError):
        look_at_rotation((0, 0, 1), (0, 0, 1))
    with pytest.raises(ValueError):
        PinholeCamera(k, rotation=np.diag([1.0, 1.0, -1.0]))  # a reflection


def test_stereo_triangulation_with_cv2():
    """Two 128 x 128 cameras (as the ball-catching stereo vision) recover 3-D points."""
    k = Intrinsics.from_fov(128, 128, math.radians(45.0))
    target = np.array([0.0, 0.0, 0.5])
    left = PinholeCamera.look_at(k, (-0.3, -1.5, 1.0), target)
    right = PinholeCamera.look_at(k, (0.3, -1.5, 1.0), target)
    rng = np.random.default_rng(6)
    pts = target + rng.uniform(-0.2, 0.2, (50, 3))
    ul, ur = left.project(pts), right.project(pts)
    assert np.all(in_image(left, ul)) and np.all(in_image(right, ur))
    h = cv2.triangulatePoints(
        left.projection_matrix(),
        right.projection_matrix(),
        ul.T.astype(np.float64),
        ur.T.astype(np.float64),
    )
    np.testing.assert_allclose((h[:3] / h[3]).T, pts, atol=1e-7)
    # a quarter-pixel error per view: a pixel is ~12 mm wide at 1.8 m and the depth error is
    # that times depth / baseline (~3), so errors of a few mm to ~1 cm, never a miss
    noisy = cv2.triangulatePoints(
        left.projection_matrix(),
        right.projection_matrix(),
        (ul + rng.uniform(-0.25, 0.25, ul.shape)).T,
        (ur + rng.uniform(-0.25, 0.25, ur.shape)).T,
    )
    err = np.linalg.norm((noisy[:3] / noisy[3]).T - pts, axis=1)
    assert 0.0 < err.max() < 0.02
