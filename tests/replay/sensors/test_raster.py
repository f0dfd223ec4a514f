"""The exact-area rasteriser (replay/sensors/raster.py) against the closed-form per-pixel coverage
it replaced, kept here as the reference."""

import numpy as np
import pytest

from replay.sensors.raster import composite, coverage, quantise


def _positive_part_integral(g0, g1, length):
    """The integral of max(g, 0) over an interval of ``length`` where g runs linearly g0 -> g1."""
    hi, lo = np.maximum(g0, g1), np.minimum(g0, g1)
    crossing = (hi > 0.0) & (lo < 0.0)
    partial = length * np.maximum(hi, 0.0) ** 2 / (2.0 * np.where(crossing, hi - lo, 1.0))
    return np.where(lo >= 0.0, length * (g0 + g1) / 2.0, np.where(crossing, partial, 0.0))


def polygon_coverage(poly, x0, y0, w, h):
    """Reference: exact area (0..1) of a simple polygon (N, 2, pixels) inside each pixel of the
    h x w block whose first pixel is (x0, y0). With F(x, y) the polygon's area in the quadrant
    {X <= x, Y <= y}, a pixel's coverage is the second difference of F over its corners; by
    Green's theorem F = -(loop integral over the boundary, X <= x, of min(Y, y) dX), edge by edge
    in closed form (signed, then oriented). Cost: edges x pixels."""
    P = np.asarray(poly, dtype=float)
    Q = np.roll(P, -1, axis=0)
    sloped = P[:, 0] != Q[:, 0]  # vertical edges add nothing
    P, Q = P[sloped], Q[sloped]
    sign = np.where(Q[:, 0] > P[:, 0], 1.0, -1.0)[:, None, None]
    left = np.where(Q[:, :1] > P[:, :1], P, Q)
    right = np.where(Q[:, :1] > P[:, :1], Q, P)
    xa, ya = left[:, 0, None, None], left[:, 1, None, None]
    xb, yb = right[:, 0, None, None], right[:, 1, None, None]
    xs = (x0 - 0.5 + np.arange(w + 1, dtype=float))[None, None, :]
    ys = (y0 - 0.5 + np.arange(h + 1, dtype=float))[None, :, None]
    length = np.clip(xs, xa, xb) - xa
    yq = ya + (yb - ya) * length / (xb - xa)
    min_integral = length * (ya + yq) / 2.0 - _positive_part_integral(ya - ys, yq - ys, length)
    F = -np.sum(sign * min_integral, axis=0)
    cov = F[1:, 1:] - F[:-1, 1:] - F[1:, :-1] + F[:-1, :-1]
    V = np.asarray(poly, dtype=float)
    area2 = float(np.sum(V[:, 0] * np.roll(V[:, 1], -1) - np.roll(V[:, 0], -1) * V[:, 1]))
    return cov if area2 >= 0.0 else -cov


def test_polygon_coverage_is_the_area_in_each_pixel():
    rng = np.random.default_rng(12)
    g = (np.arange(400) + 0.5) / 400 - 0.5  # 400 x 400 samples per pixel
    for k in range(60):
        c, r = rng.uniform(7, 13, 2), rng.uniform(0.3, 6.0)
        ang = np.sort(rng.uniform(0, 2 * np.pi, rng.integers(3, 12)))
        if k % 3 == 0:  # (nearly) grid-aligned squares
            ang = np.array([0, 0.5, 1, 1.5]) * np.pi + rng.choice([0.0, 1e-14, 1e-9])
        poly = c + r * np.column_stack([np.cos(ang), np.sin(ang)])
        if k % 2:
            poly = poly[::-1]  # either orientation
        cov = polygon_coverage(poly, 0, 0, 20, 20)
        area = 0.5 * abs(
            np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
        )
        assert cov.sum() == pytest.approx(area, abs=1e-9)
        assert cov.min() > -1e-12 and cov.max() < 1 + 1e-12
        ccw = (
            poly
            if np.sum(poly[:, 0] * np.roll(poly[:, 1], -1) - np.roll(poly[:, 0], -1) * poly[:, 1])
            > 0
            else poly[::-1]
        )
        i, j = np.rint(c + rng.uniform(-r, r, 2)).astype(int)
        X, Y = np.meshgrid(i + g, j + g)
        inside = np.ones_like(X, bool)
        for (xa, ya), (xb, yb) in zip(ccw, np.roll(ccw, -1, axis=0)):
            inside &= (xb - xa) * (Y - ya) - (yb - ya) * (X - xa) >= 0
        assert cov[j, i] == pytest.approx(inside.mean(), abs=0.005)
    # an offset block sees the same pixels
    poly = np.array([[3.2, 4.1], [9.7, 5.0], [6.0, 11.3]])
    np.testing.assert_allclose(
        polygon_coverage(poly, 2, 3, 8, 9),
        polygon_coverage(poly, 0, 0, 20, 20)[3:12, 2:10],
        atol=1e-12,
    )


def _random_polygon(rng):
    """A convex polygon (either orientation) of 3-40 vertices, 0.3-30 px across, anywhere."""
    n = int(rng.integers(3, 40))
    ang = np.sort(rng.uniform(0, 2 * np.pi, n))
    r = rng.uniform(0.3, 30.0)
    poly = rng.uniform(-10, 45, 2) + np.column_stack(
        [r * rng.uniform(0.2, 1.0) * np.cos(ang), r * np.sin(ang)]
    )
    return poly[::-1] if rng.random() < 0.5 else poly


def test_the_accumulation_rasteriser_equals_the_closed_form_coverage():
    """Any window (cutting the polygon on any side, or missing it), any orientation, several
    polygons at once: the same areas as the reference to rounding."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        polys = [_random_polygon(rng) for _ in range(int(rng.integers(1, 4)))]
        x0, y0 = (int(v) for v in rng.integers(-8, 12, 2))
        w, h = (int(v) for v in rng.integers(1, 50, 2))
        got = coverage(polys, x0, y0, w, h)
        assert got.shape == (len(polys), h, w)
        for poly, cov in zip(polys, got):
            np.testing.assert_allclose(cov, polygon_coverage(poly, x0, y0, w, h), atol=1e-9)
    # grid-aligned and nearly grid-aligned edges, vertices on pixel boundaries
    for eps in (0.0, 1e-14, 1e-9):
        sq = np.array([[1.5, 1.5], [6.5 + eps, 1.5], [6.5, 4.5 + eps], [1.5 - eps, 4.5]])
        np.testing.assert_allclose(
            coverage([sq], 0, 0, 9, 7)[0], polygon_coverage(sq, 0, 0, 9, 7), atol=1e-9
        )


def test_composite_paints_far_to_near_by_coverage():
    img = np.full((10, 12), 10.0, np.float32)
    back = np.array([[0.0, 0.0], [11.5, 0.0], [11.5, 9.5], [0.0, 9.5]])
    front = np.array([[3.0, 3.0], [5.0, 3.0], [5.0, 5.0], [3.0, 5.0]])
    composite(img, [back, front], [100.0, 250.0])
    assert img[0, 0] == pytest.approx(10.0 + 0.25 * 90.0)  # a quarter of pixel (0, 0)
    assert img[5, 8] == pytest.approx(100.0)
    assert img[4, 4] == pytest.approx(250.0)  # wholly inside the front square
    assert img[3, 3] == pytest.approx(100.0 + 0.25 * 150.0)  # a quarter of it


def test_quantise_is_clip_of_rint():
    rng = np.random.default_rng(0)
    img = np.concatenate(
        [rng.uniform(-20, 280, 5000), np.arange(-2, 258, 0.5), [0.0, -0.0, 255.0, 1e30, -1e30]]
    ).astype(np.float32)
    np.testing.assert_array_equal(quantise(img), np.clip(np.rint(img), 0, 255).astype(np.uint8))


# each case in a child process with a time limit: a kernel that loops for ever (as these did on
# a NaN x coordinate, uninterruptibly) fails the test instead of hanging the suite
_BAD_CHILD = r"""
import sys
import numpy as np
from replay.scene import Box, Scene
from replay.sensors.raster import composite, coverage
bad = float(sys.argv[1])
which = int(sys.argv[2])
poly = np.array([[1.0, 1.0], [6.0, 1.5], [5.0, 6.0], [1.5, 5.0]])
poly[which % 4, which % 2] = bad
def kernel_error(call):
    try:
        call()
    except ValueError as exc:
        return str(exc)
    return "no error"
print(kernel_error(lambda: coverage([poly], 0, 0, 8, 8)))
print(kernel_error(lambda: composite(np.zeros((8, 8), np.float32), [poly], [200.0])))
if which == 0:  # the stick camera's compiled frame, the stick and its marker at a bad place
    from plants.airtable.camera import StickCamera, StickCameraParams
    cam = StickCamera(StickCameraParams(), rng=np.random.default_rng(0))
    marker = Box("marker", (bad, 0.0, 0.01), (0.0, 0.0, 0.0, 1.0), (0.08, 0.006, 0.002), 1.0)
    near = Box("stick", (bad, 0.0, 0.005), (0.0, 0.0, 0.0, 1.0), (0.2, 0.02, 0.01), 0.5)
    try:
        print("measured", cam.measure(0.0, Scene([near, marker])))
    except (ValueError, OverflowError) as exc:
        print("refused", exc)
if which == 1:  # the stereo camera's compiled frame, a ball and a box at a bad place
    from replay.scene import Sphere
    from replay.sensors.stereo import StereoBallCamera, StereoBallCameraParams
    cam = StereoBallCamera(StereoBallCameraParams(), rng=np.random.default_rng(0))
    box = Box("box", (0.0, bad, 1.0), (0.0, 0.0, 0.0, 1.0), (0.1, 0.1, 0.1), 0.5)
    try:
        print("measured", cam.measure(0.0, Scene([Sphere("ball", (bad, 0.0, 1.0), 0.02), box])))
    except (ValueError, OverflowError) as exc:
        print("refused", exc)
"""


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf", "1e300"])
@pytest.mark.parametrize("which", [0, 1, 2, 3])
def test_a_non_finite_or_huge_vertex_is_refused_not_looped_on(bad, which, project_root):
    import subprocess
    import sys

    done = subprocess.run(
        [sys.executable, "-c", _BAD_CHILD, bad, str(which)],
        capture_output=True,
        text=True,
        timeout=60,
        cwd=project_root,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert len(lines) == (3 if which < 2 else 2), done.stdout
    for line in lines[:2]:
        assert "not a finite pixel coordinate" in line, line
    if which < 2:  # the cameras: unseen (None) or refused, and returned (no hang, no crash)
        assert lines[2] == "measured None" or lines[2].startswith("refused"), lines[2]
