"""Synthetic overhead vision of the stick: accuracy, sub-pixel response, noise, visibility."""

import dataclasses
import math

import numpy as np
import pytest

from replay.interfaces import Sensor
from replay.messages import VisionStick
from replay.scene import Box, Cylinder, Scene, Sphere
from replay.spatial import yaw_quaternion
from replay.sensors.pinhole import PinholeCamera
from plants.airtable.camera import StickCamera, StickCameraParams, render_scene, wrap_half_pi

from pixel_checks import in_image

STICK = (0.100, 0.010, 0.005)  # L x W (paper) x an assumed thickness (m)


def stick_scene(x, y, theta, marker=(0.060, 0.008), tips=(), reverse=False):
    """A 100 mm x 10 mm grey stick with a thin white marker on top, optional fingertips."""
    q = yaw_quaternion(theta)
    prims = [
        Box("stick", (x, y, STICK[2] / 2), q, STICK, albedo=0.3),
        Box("marker", (x, y, STICK[2] + 0.00025), q, (*marker, 0.0005), albedo=1.0),
    ]
    for k, (tx, ty) in enumerate(tips):
        prims.append(Cylinder(f"tip{k}", (tx, ty, 0.01), (0, 0, 0, 1), 0.005, 0.02, albedo=0.1))
    return Scene(prims[::-1] if reverse else prims)


def camera(seed=0, **kw):
    return StickCamera(StickCameraParams(**kw), rng=np.random.default_rng(seed))


def errors(m, x, y, theta):
    return math.hypot(m.x - x, m.y - y), abs(wrap_half_pi(m.theta - theta))


def random_poses(n, seed, reach=0.25):
    rng = np.random.default_rng(seed)
    return [(*rng.uniform(-reach, reach, 2), rng.uniform(-math.pi, math.pi)) for _ in range(n)]


def test_is_a_sensor_with_declared_params():
    assert issubclass(StickCamera, Sensor) and StickCamera.topic == "/vision/stick"
    assert StickCamera.Params is StickCameraParams
    for f in dataclasses.fields(StickCameraParams):
        assert f.metadata.get("doc"), f.name  # every field made with param(doc=...)
    p = StickCameraParams()
    assert (p.width, p.height, p.position, p.target, p.noise_sigma) == (
        512,
        512,
        [0.0, 0.0, 1.0],
        [0.0, 0.0, 0.0],
        0.0,
    )
    # +-0.3 m of table is in view at the default resolution, with a margin
    cam = StickCamera.make_camera(p)
    corners = cam.project([[0.3, 0.3, 0.0], [-0.3, -0.3, 0.0], [0.3, -0.3, 0.0]])
    assert np.all(in_image(cam, corners))
    assert cam.position[2] == 1.0


@pytest.mark.parametrize("marker", [(0.060, 0.008), (0.080, 0.006)])
def test_accuracy_over_random_poses(marker):
    """Noise-free worst case over 150 poses in +-0.25 m (a pixel is 1.25 mm at the table):
    measured 0.034 mm / 0.067 deg for the 60 x 8 mm marker, 0.016 mm / 0.023 deg for 80 x 6 mm."""
    cam = camera()
    pos, ang = [], []
    for x, y, th in random_poses(150, seed=11):
        m = cam.measure(0.5, stick_scene(x, y, th, marker))
        assert isinstance(m, VisionStick) and m.t == 0.5
        assert -math.pi / 2 < m.theta <= math.pi / 2
        e_p, e_a = errors(m, x, y, th)
        pos.append(e_p)
        ang.append(e_a)
    assert max(pos) < 0.05e-3  # m: 1/25 of a pixel
    assert max(ang) < math.radians(0.1)
    assert np.sqrt(np.mean(np.square(pos))) < 0.02e-3


@pytest.mark.parametrize("marker,tol", [((0.080, 0.006), 0.025e-3), ((0.060, 0.008), 0.05e-3)])
def test_subpixel_shifts_move_the_measurement_by_as_much(marker, tol):
    """0.2 mm (0.16 px) steps are resolved, also for a marker aligned with the pixel grid.

    Measured worst deviation from the true shift over 7 steps: 0.019 mm for the 80 x 6 mm marker,
    0.043 mm for 60 x 8 mm, whose 1 mm stick border (0.8 px) lets the dark table into the
    marker's edge pixels."""
    cam = camera()
    for x, y, th in [
        (0.0, 0.0, 0.0),
        (0.0312, -0.071, math.pi / 2),
        (-0.11, 0.05, 0.4),
        (0.2, 0.17, -1.2),
    ]:
        for ux, uy in [(1.0, 0.0), (0.0, 1.0)]:
            base = cam.measure(0.0, stick_scene(x, y, th, marker))
            for k in range(1, 8):
                d = 0.2e-3 * k
                m = cam.measure(0.0, stick_scene(x + ux * d, y + uy * d, th, marker))
                assert m.x - base.x == pytest.approx(ux * d, abs=tol)
                assert m.y - base.y == pytest.approx(uy * d, abs=tol)


def test_noise_spreads_the_measurement_without_biasing_it():
    x, y, th = 0.07, -0.04, 0.6
    scene = stick_scene(x, y, th)
    clean_p, _ = errors(camera().measure(0.0, scene), x, y, th)
    spread = {}
    for sigma in (5.0, 20.0):
        cam = camera(seed=7, noise_sigma=sigma)
        ms = [cam.measure(0.0, scene) for _ in range(60)]
        ex = np.array([m.x - x for m in ms])
        ey = np.array([m.y - y for m in ms])
        et = np.array([wrap_half_pi(m.theta - th) for m in ms])
        spread[sigma] = (ex.std(), et.std())
        # unbiased-ish: the mean error is within the noise-free error plus 4 standard errors
        for e in (ex, ey):
            assert abs(e.mean()) < clean_p + 4 * e.std() / math.sqrt(len(e)) + 1e-6
        assert abs(et.mean()) < math.radians(0.05) + 4 * et.std() / math.sqrt(len(et))
        assert max(errors(m, x, y, th)[0] for m in ms) < 1e-3  # still sub-millimetre
    assert spread[20.0][0] > 2 * spread[5.0][0] > 0.0
    assert spread[20.0][1] > 2 * spread[5.0][1] > 0.0


def test_marker_out_of_view_or_too_small_is_none():
    cam = camera()
    assert cam.measure(0.0, stick_scene(0.5, 0.0, 0.3)) is None  # well off the image
    assert cam.measure(0.0, stick_scene(0.31, 0.0, 0.0)) is None  # cut by the border
    assert cam.measure(0.0, stick_scene(0.0, 0.0, 0.0, marker=(0.004, 0.004))) is None
    no_marker = Scene([p for p in stick_scene(0.0, 0.0, 0.0).primitives if p.name != "marker"])
    assert cam.measure(0.0, no_marker) is None
    assert cam.last_image is not None and cam.last_image.max() < 100  # the grey stick only
    # the same stick well inside the view is seen
    assert cam.measure(0.0, stick_scene(0.2, 0.0, 0.0)) is not None


def test_depends_only_on_the_scene_and_the_seed():
    a, b = stick_scene(0.1, 0.05, 0.3), stick_scene(-0.15, 0.2, -1.0)
    cam = camera()
    first = cam.measure(0.0, a)
    cam.measure(0.0, b)
    assert cam.measure(0.0, a) == first
    assert camera().measure(0.0, a) == first
    # draw order of the scene does not matter (far-to-near painting)
    assert cam.measure(0.0, stick_scene(0.1, 0.05, 0.3, reverse=True)) == first
    # a stick turned by pi is the same picture: theta is known modulo pi
    assert cam.measure(0.0, stick_scene(0.1, 0.05, 0.3 + math.pi)) == pytest.approx(first)
    # noisy: same seed -> same sequence; another seed -> another one
    seqs = []
    for seed in (1, 1, 2):
        noisy = camera(seed=seed, noise_sigma=8.0)
        seqs.append([noisy.measure(0.0, x) for x in (a, b, a)])
    assert seqs[0] == seqs[1] and seqs[0] != seqs[2]
    assert seqs[0][0] != seqs[0][2]  # fresh noise per frame


def test_offset_and_other_camera_poses():
    x, y, th = 0.05, 0.02, 0.2
    base = camera().measure(0.0, stick_scene(x, y, th))
    shifted = camera(position_offset=[0.002, -0.001]).measure(0.0, stick_scene(x, y, th))
    assert shifted.x - base.x == pytest.approx(0.002, abs=1e-9)
    assert shifted.y - base.y == pytest.approx(-0.001, abs=1e-9)
    moved = camera(position=[0.1, 0.0, 1.0], target=[0.1, 0.0, 0.0])
    assert errors(moved.measure(0.0, stick_scene(x, y, th)), x, y, th)[0] < 0.05e-3
    # image "up" = world -x: the picture turns, the measurement does not
    turned = camera(up=[-1.0, 0.0, 0.0]).measure(0.0, stick_scene(x, y, th))
    assert errors(turned, x, y, th)[0] < 0.05e-3 and errors(turned, x, y, th)[1] < 1e-3
    # A camera looking obliquely (17 deg): the image centroid of a perspective-distorted marker
    # is not the image of its centre; the bias grows as the marker's length squared (measured
    # up to 0.6 mm for 80 mm, 0.09 mm for 30 mm). It is a property of image moments, kept.
    oblique = camera(position=[0.3, 0.0, 1.0])
    for x, y, th in random_poses(20, seed=5, reach=0.2):
        e_p, e_a = errors(oblique.measure(0.0, stick_scene(x, y, th)), x, y, th)
        assert e_p < 1e-3 and e_a < math.radians(0.3)
        e_short, _ = errors(
            oblique.measure(0.0, stick_scene(x, y, th, marker=(0.02, 0.006))), x, y, th
        )
        assert e_short < 0.1e-3
    with pytest.raises(ValueError):
        camera(up=[0.0, 0.0, 1.0])  # 'up' along the optical axis


def test_image_content_and_occlusion_by_a_fingertip():
    p = StickCameraParams()
    cam = StickCamera.make_camera(p)
    x, y, th = 0.05, 0.1, 0.5
    img = StickCamera.render(stick_scene(x, y, th), p)
    assert img.shape == (512, 512) and img.dtype == np.uint8
    u, v = np.rint(cam.project([x, y, 0.005])).astype(int)
    assert img[v, u] == 255  # the white marker
    eu, ev = np.rint(cam.project([x + 0.045 * math.cos(th), y + 0.045 * math.sin(th), 0.005]))
    assert img[int(ev), int(eu)] == round(0.3 * 255)  # the grey stick beyond its end
    assert img[10, 10] == round(0.1 * 255)  # the dark table
    # a fingertip over one end of the marker is drawn dark over it, and biases the centroid
    tip = (x + 0.025 * math.cos(th), y + 0.025 * math.sin(th))
    scene = stick_scene(x, y, th, tips=[tip])
    img = StickCamera.render(scene, p)
    tu, tv = np.rint(cam.project([*tip, 0.02])).astype(int)
    assert img[tv, tu] == round(0.1 * 255)
    m = camera().measure(0.0, scene)
    assert m is not None and errors(m, x, y, th)[0] > 1e-3


def test_render_covers_the_true_area():
    """Anti-aliased rendering gives each pixel its covered area: the summed coverage of a marker
    equals its projected area, and a sphere's silhouette has the viewing cone's area."""
    p = StickCameraParams(background=0.0)
    cam = StickCamera.make_camera(p)
    scale = cam.intrinsics.fx / (1.0 - 0.00525)  # px per m at the marker's height
    for th in (0.0, 0.37, 1.2):
        box = Box(
            "marker", (0.013, -0.021, 0.00525), yaw_quaternion(th), (0.060, 0.008, 0.0), albedo=1.0
        )
        img = render_scene(cam, Scene([box]), background=0.0)
        assert img.sum() / 255.0 == pytest.approx(0.060 * 0.008 * scale**2, rel=1e-5)
    eye = PinholeCamera.from_fov(
        200, 200, math.radians(30.0), eye=(0, 0, 1.0), target=(0, 0, 0), up=(0, 1, 0)
    )
    img = render_scene(
        eye, Scene([Sphere("ball", (0.0, 0.0, 0.0), 0.05, albedo=1.0)]), background=0.0
    )
    half_angle = math.asin(0.05 / 1.0)
    expected = math.pi * (eye.intrinsics.fx * math.tan(half_angle)) ** 2
    assert img.sum() / 255.0 == pytest.approx(expected, rel=0.002)


@pytest.mark.parametrize(
    "a,expected",
    [
        (0.0, 0.0),
        (math.pi / 2, math.pi / 2),
        (-math.pi / 2, math.pi / 2),
        (math.pi, 0.0),
        (3.0, 3.0 - math.pi),
        (-2.0, -2.0 + math.pi),
        (7.0, 7.0 - 2 * math.pi),
    ],
)
def test_wrap_half_pi(a, expected):
    assert wrap_half_pi(a) == pytest.approx(expected)
