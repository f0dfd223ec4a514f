"""Synthetic stereo ball vision for the catching experiment (Namiki & Ishikawa, Sec. IV-A).

The paper measures the ball's 3-D position ``r_o`` at 1 kHz with two column-parallel vision
systems (CPV: 128 x 128 photodetectors, segmentation, target extraction and image moments in
1 ms); the ball "was thrown to the direction of the arm through between two vision systems".
This sensor does the same with images:

1. each camera's 8-bit 128 x 128 image is rendered from the scene's silhouettes
   (:mod:`replay.sensors.silhouette`: the sphere's exact perspective ellipse, boxes as projected
   hulls, each pixel weighted by the exact area covered) plus Gaussian pixel noise from the sensor's ``rng``;
2. segmentation by a grey-level threshold; the target is the largest 8-connected blob (the
   arm is not in the plant's scene, so the ball is usually the only bright thing); a blob cut
   by the image border is rejected;
3. image moments give the centroid: by default on grey levels above the local
   background within the blob dilated by 2 px (partly covered edge pixels count by their
   coverage, so the centroid is sub-pixel), or, with ``moments: binary``, on the segmented
   binary image, as a 1-bit vision chip would;
4. the linear (DLT) triangulation of ``cv2.triangulatePoints`` with the two cameras'
   ``K [R | t]`` gives ``r_o``.

The centroid of a sphere's silhouette is not the projection of its centre: the ellipse's
centre lies radially outward from the principal point by ``r^2 / (Z^2 - r^2)`` of the projected
centre's distance (:func:`~replay.sensors.silhouette.sphere_centroid_bias`). With the defaults it
is at most ~0.045 px (ball at x = 2.2 m, 0.55 m from a camera and ~40 px off-axis) and ~0.004 px
near the catch point; removing it changes the worst triangulation error over typical throws from
1.45 to 1.25 mm and the median from 0.18 to 0.13 mm. It is removed anyway
(``bias_correction``): after a first triangulation each centroid is scaled back towards the
principal point by ``(Z^2 - r^2) / Z^2`` (``Z``: that camera's depth of the first estimate, ``r``:
the ball's known radius, the tracked Sphere's) and the point is triangulated again.

Published: ``VisionObject(t, position=[x, y, z], features={"centroids": [[u, v], [u, v]],
"areas": [a0, a1]})`` with the *measured* (uncorrected) centroids in pixels and the areas as
pixels above threshold in each blob; None when the tracked primitive is absent or either camera
has no whole blob.

Default geometry (the paper gives none; ours, after "thrown ... toward the arm through between two
vision systems"): the arm base at the origin, the catch point near (0.7, 0, 0.5) m, throws from
about (3.2, 0, 1.0) m along -x at 8-10 m/s. The two cameras stand either side of the flight path
at x = 2.6 m, y = +-0.4 m (a 0.8 m baseline), z = 0.8 m, 0.6 m in front of the release, so
the ball flies between them and away from them towards the arm. Both look at (1.9, 0, 0.8) m on
the flight path, the aim that keeps the ball's image furthest from the borders (>= 20 px) over the
last 1.5 m (x = 2.2 -> 0.7 m) of throws at 8-10 m/s to arrival points within +-0.1 m of the catch
point; a ball is whole in both images from x ~ 2.34 m on. With a 60 deg field of view the rays
meet at ~88 deg at x = 2.2 m (0.57 m from each camera) and ~23 deg at the catch point (1.96 m).
The arm (not in the plant's scene today) is then background, not an occluder between the
cameras and the ball. The 35 mm ball spans ~8 px at x = 2.2 m and ~2 px at the catch point.

Accuracy (tests/replay/sensors/test_stereo_vision.py; the paper states none): noise-free, over 432 points of
the last 1.5 m of such throws, worst 1.25 mm, median 0.13 mm, the worst near the catch point,
where the centroid of a 2-px blob carries the pixel grid's own sampling error (~0.03 px, the
same for a real sensor) and the rays meet at 23 deg; with 1-bit moments, worst 24.5 mm, median
2.3 mm; with pixel noise sigma = 5 grey levels, worst ~11 mm, median ~0.8 mm.

Cost: noise-free, each camera renders only the box around the silhouettes plus 6 px (outside it
the image is exactly the background, below the threshold, and the blob's moments look at most
4 px around the blob), filled in only when the whole images are asked for (:attr:`last_images`);
with pixel noise the whole images are rendered, every pixel drawn from the rng as before. The
per-pixel work (ellipse polygon, exact-coverage compositing, quantising, segmentation and
moments) and the triangulation run in the optional accelerator (``_pixels.c``) where it is
built, else as NumPy/OpenCV (the same algorithms, equal to 1e-9 px: tests/replay/sensors/
test_fast_cameras.py): ~0.2 ms a noise-free pair compiled, ~2 ms in Python.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.foxglove.image import WindowedImage
from replay.interfaces import Sensor
from replay.messages import TOPIC_VISION_OBJECT, VisionObject
from replay.params import ParamError, param
from replay.scene import Scene, Sphere
from replay.sensors.pinhole import (
    Intrinsics,
    PinholeCamera,
    check_image_size,
    look_at_rotation,
)
from replay.accel import accelerator
from replay.sensors.raster import composite, quantise
from replay.sensors.silhouette import correct_sphere_centroid, drawables, render_views

import cv2  # (the blob's and the triangulation's pure-Python path: the OpenCV they replaced)

_pixels = accelerator("replay.sensors._pixels")

_VIEWS = ("cam0", "cam1")  # the two cameras' image views (frame_images)


@dataclass
class StereoBallCameraParams:
    cam0_position: list[float] = param(
        [2.6, 0.4, 0.8],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="optical centre of camera 0 (world). Default: 0.4 m to the +y side of the flight "
        "path, 0.6 m in front of the release (the ball is thrown between the two cameras)",
    )
    cam0_target: list[float] = param(
        [1.9, 0.0, 0.8],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="world point on camera 0's optical axis. Default: on the flight path, chosen to "
        "centre the ball's image from x = 2.2 m to the catch point (0.7, 0, 0.5) m",
    )
    cam1_position: list[float] = param(
        [2.6, -0.4, 0.8],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="optical centre of camera 1 (world); default: the mirror image of camera 0, a "
        "0.8 m stereo baseline",
    )
    cam1_target: list[float] = param(
        [1.9, 0.0, 0.8],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="world point on camera 1's optical axis",
    )
    up: list[float] = param(
        [0.0, 0.0, 1.0],
        unit="1",
        length=3,
        ge=-1e3,
        le=1e3,
        doc="world direction shown as 'up' in both images",
    )
    fov: float = param(
        math.radians(60.0),
        unit="rad",
        gt=0.0,
        lt=math.pi,
        doc="vertical field of view, edge to edge (square pixels; 60 deg default: f = 110.9 px)",
    )
    width: int = param(128, unit="px", ge=8, le=2048, doc="image width; paper: 128 (CPV)")
    height: int = param(128, unit="px", ge=8, le=2048, doc="image height; paper: 128 (CPV)")
    noise_sigma: float = param(
        0.0,
        unit="grey level",
        ge=0.0,
        le=1000,
        doc="standard deviation of Gaussian pixel noise (0..255 scale)",
    )
    threshold: float = param(
        100.0,
        unit="grey level",
        ge=0.0,
        le=255.0,
        doc="pixels brighter than this are ball (ball 0.9 * 255 on "
        "0.1 * 255): a pixel 37 % covered by the ball passes, so a "
        "1.5 px ball is still seen",
    )
    min_pixels: int = param(
        1, unit="px", ge=1, le=2048 * 2048, doc="smallest blob (pixels above threshold) accepted"
    )
    moments: str = param(
        "grey",
        choices=("grey", "binary"),
        doc="grey: moments of grey level above the local background in the blob "
        "grown by 2 px (sub-pixel); binary: moments of the segmented blob "
        "(a 1-bit vision chip's)",
    )
    bias_correction: bool = param(
        True,
        doc="correct the sphere-silhouette centroid bias (needs "
        "the tracked primitive to be a Sphere: its radius)",
    )
    background: float = param(
        0.1, unit="1", ge=0.0, le=1.0, doc="albedo of the (uniform) background"
    )
    tracked: str = param(
        "ball", max_length=100, doc="name of the scene primitive whose position is measured"
    )
    log_images: bool = param(
        True,
        doc="write both cameras' images to the log (foxglove.RawImage, /camera/SENSOR/cam0 and "
        "cam1) at the camera rate: ~0.3 KiB after the log's zstd and ~0.04 ms a frame pair",
    )

    def __post_init__(self) -> None:
        check_image_size(self.width, self.height)
        for i, (eye, target) in enumerate(
            ((self.cam0_position, self.cam0_target), (self.cam1_position, self.cam1_target))
        ):
            try:
                look_at_rotation(eye, target, self.up)
            except ValueError as exc:
                raise ParamError(
                    f"cam{i}_target" if "coincide" in str(exc) else "up", f"camera {i}: {exc}"
                ) from None
        if np.allclose(self.cam0_position, self.cam1_position):
            raise ParamError(
                "cam1_position", "the two cameras are at the same place: no stereo baseline"
            )


def _blob(found: tuple | None, binary: bool) -> dict | None:
    """A blob kernel's (u, v, area, background) as the camera's blob record (no background for
    binary moments)."""
    if found is None:
        return None
    return {
        "u": found[0],
        "v": found[1],
        "area": found[2],
        "background": None if binary else found[3],
    }


class StereoBallCamera(Sensor):
    """Two 128 x 128 cameras, blob moments and triangulation: ``/vision/object`` (``r_o``)."""

    Params = StereoBallCameraParams
    images_per_frame = 2  # cam0 and cam1 (a run's projected log size: replay.scenario.log_size)
    topic = TOPIC_VISION_OBJECT
    description = (
        "two 128x128 pinhole cameras either side of the throw; threshold, image "
        "moments, linear triangulation -> ball position r_o"
    )

    def __init__(
        self, params: StereoBallCameraParams, *, rng: np.random.Generator, spec=None
    ) -> None:
        super().__init__(params, rng=rng, spec=spec)
        self.cameras = self.make_cameras(params)
        self.projections = [c.projection_matrix() for c in self.cameras]
        self._P = [np.ascontiguousarray(P, dtype=np.float64) for P in self.projections]
        # (optical centre, optical axis) of each camera, for depths
        self._axes = [
            (tuple(c.position.tolist()), tuple(c.rotation[:, 2].tolist())) for c in self.cameras
        ]
        self._background_level = int(
            quantise(np.array([255.0 * params.background], dtype=np.float32))[0]
        )
        # the per-frame path's constants: ball_blob's settings, the cameras' principal points
        self._blob_args = (
            float(params.threshold),
            int(params.min_pixels),
            int(params.moments == "binary"),
            255.0 * float(params.background),
        )
        self._centres = [(c.intrinsics.cx, c.intrinsics.cy) for c in self.cameras]
        self._last: list = [None, None]
        self._found: tuple = (None, None)  # the blob kernels' tuples of the last frame

    # --- helpers usable without a sensor instance -------------------------------------------
    @staticmethod
    def make_cameras(
        params: StereoBallCameraParams | None = None,
    ) -> tuple[PinholeCamera, PinholeCamera]:
        """The two look-at pinhole cameras (square pixels, principal point at the centre)."""
        p = params if params is not None else StereoBallCameraParams()
        f = (p.height / 2.0) / math.tan(p.fov / 2.0)
        k = Intrinsics(
            fx=f,
            fy=f,
            cx=(p.width - 1) / 2.0,
            cy=(p.height - 1) / 2.0,
            width=int(p.width),
            height=int(p.height),
        )
        return tuple(
            PinholeCamera.look_at(k, eye, target, p.up)  # type: ignore[return-value]
            for eye, target in ((p.cam0_position, p.cam0_target), (p.cam1_position, p.cam1_target))
        )

    @staticmethod
    def render(
        scene: Scene,
        params: StereoBallCameraParams | None = None,
        rng: np.random.Generator | None = None,
        cameras: tuple[PinholeCamera, PinholeCamera] | None = None,
    ) -> list[np.ndarray]:
        """The two 8-bit images the cameras would see (noise only if ``rng`` is given)."""
        p = params if params is not None else StereoBallCameraParams()
        cams = cameras if cameras is not None else StereoBallCamera.make_cameras(p)
        out = []
        for img in render_views(cams, scene, background=p.background):
            if rng is not None and p.noise_sigma > 0.0:
                img += np.float32(p.noise_sigma) * rng.standard_normal(img.shape, dtype=np.float32)
            out.append(quantise(img))
        return out

    @staticmethod
    def blob(
        image: np.ndarray,
        params: StereoBallCameraParams | None = None,
        origin: tuple[int, int] = (0, 0),
    ) -> dict | None:
        """Segment an 8-bit image and take the largest blob's moments: ``u``, ``v`` (centroid,
        pixels), ``area`` (pixels above threshold), ``background`` (grey level, grey mode), or
        None when there is no whole blob of ``min_pixels``. ``image`` may be a window of the
        full image whose first pixel is ``origin`` (the rest of which is background).

        The blob is the largest 8-connected one above ``threshold`` (None if it touches the
        image border). Grey moments weigh the grey level above the local background (the median
        of the free pixels 3-4 px around the blob grown by 2 px, signed, so that zero-mean noise
        leaves the centroid unbiased) within the blob grown by 2 px (5 x 5). Computed in one
        pass by the optional accelerator (``_pixels.ball_blob``), else the OpenCV pipeline it
        replaced (:func:`_ball_blob`)."""
        p = params if params is not None else StereoBallCameraParams()
        img = np.ascontiguousarray(image, dtype=np.uint8)
        h, w = img.shape
        args = (float(p.threshold), int(p.min_pixels), int(p.moments == "binary"))
        found = _ball_blob(
            img,
            w,
            h,
            *args,
            255.0 * float(p.background),
            int(origin[0]),
            int(origin[1]),
            int(p.width),
            int(p.height),
        )
        return _blob(found, p.moments == "binary")

    def frame_images(self) -> list[tuple[str, WindowedImage]]:
        """The last frame's images (with their noise): ``[("cam0", WindowedImage), ("cam1",
        ...)]``, each its rendered window in the background (:attr:`last_images` whole)."""
        p, level = self.params, self._background_level
        return [
            (view, WindowedImage(p.height, p.width, level, last[1], last[0]))
            for view, last in zip(_VIEWS, self._last)
            if last is not None
        ]

    def triangulate(self, uv0, uv1) -> np.ndarray:
        """World point (3,) from a pixel in each image: the linear (DLT) triangulation of
        ``cv2.triangulatePoints`` (:func:`_triangulate`; NaN at infinity)."""
        X = _triangulate(
            self._P[0], self._P[1], float(uv0[0]), float(uv0[1]), float(uv1[0]), float(uv1[1])
        )
        return np.full(3, np.nan) if X is None else np.array(X)

    def _depth(self, i: int, X) -> float:
        """Depth (m, along the optical axis) of world point X in camera i."""
        (ox, oy, oz), (zx, zy, zz) = self._axes[i]
        return (float(X[0]) - ox) * zx + (float(X[1]) - oy) * zy + (float(X[2]) - oz) * zz

    def locate(self, uv0, uv1, radius: float | None = None) -> np.ndarray:
        """Ball centre from the two silhouette centroids; with ``radius`` (m), the centroids are
        first corrected for the sphere's perspective bias (one refinement step)."""
        X = self.triangulate(uv0, uv1)
        if radius is None or radius <= 0.0 or not all(map(math.isfinite, X)):
            return X
        fixed = []
        for i, (cam, uv) in enumerate(zip(self.cameras, (uv0, uv1))):
            z = self._depth(i, X)
            if z <= radius:
                return X
            fixed.append(correct_sphere_centroid(cam, uv, z, radius))
        return self.triangulate(*fixed)

    # --- the sensor ---------------------------------------------------------------------------
    @property
    def last_images(self) -> list[np.ndarray | None]:
        """The two whole last frames (background outside the rendered windows)."""
        out: list[np.ndarray | None] = []
        p, level = self.params, self._background_level
        for last in self._last:
            if last is None:
                out.append(None)
            elif last[1] == (0, 0, p.width, p.height):
                out.append(last[0])  # rendered whole
            else:
                out.append(WindowedImage(p.height, p.width, level, last[1], last[0]).full())
        return out

    def _window(self, camera: PinholeCamera, boxes) -> tuple[int, int, int, int]:
        """The part of the image to render: all of it with pixel noise (its every pixel is drawn
        from the rng, as before) or when the background itself passes the threshold; else the
        box around the silhouettes plus 5 px (the blob's moments look at most 4 px around it),
        outside which the image is exactly the background, below the threshold."""
        p = self.params
        k = camera.intrinsics
        if p.noise_sigma > 0.0 or self._background_level > p.threshold or not boxes:
            return (0, 0, k.width, k.height) if boxes or p.noise_sigma > 0.0 else (0, 0, 0, 0)
        x0, y0, x1, y1 = boxes[0]
        for b in boxes[1:]:
            x0, y0, x1, y1 = min(x0, b[0]), min(y0, b[1]), max(x1, b[2]), max(y1, b[3])
        m = 6  # the polygon's pixels reach 1 px beyond its box, the moments 4 px beyond them
        wx0, wy0 = max(int(math.floor(x0)) - m, 0), max(int(math.floor(y0)) - m, 0)
        wx1, wy1 = (
            min(int(math.ceil(x1)) + m + 1, k.width),
            min(int(math.ceil(y1)) + m + 1, k.height),
        )
        if wx1 <= wx0 or wy1 <= wy0:
            return (0, 0, 0, 0)
        return (wx0, wy0, wx1, wy1)

    def _locate_f(self, uv0, uv1, radius: float | None):
        """:meth:`locate` on floats: (x, y, z), or None at infinity. The bias correction as
        :func:`~replay.sensors.silhouette.correct_sphere_centroid` computes it."""
        P0, P1 = self._P
        X = _triangulate(P0, P1, uv0[0], uv0[1], uv1[0], uv1[1])
        if X is None or radius is None or radius <= 0.0 or not all(map(math.isfinite, X)):
            return X
        fixed = []
        r2 = radius * radius
        for i, (u, v) in enumerate((uv0, uv1)):
            z = self._depth(i, X)
            if z <= radius:
                return X
            cx, cy = self._centres[i]
            s = (z * z - r2) / (z * z)
            fixed.append((cx + (u - cx) * s, cy + (v - cy) * s))
        (a, b), (c, d) = fixed
        return _triangulate(P0, P1, a, b, c, d)

    def measure(self, t: float, scene: Scene) -> VisionObject | None:
        """The module doc's pipeline: each camera's window, image and blob, then the
        triangulation with its bias correction."""
        p = self.params
        noise = p.noise_sigma > 0.0
        grey = 255.0 * p.background
        blob_args = self._blob_args
        W, H = int(p.width), int(p.height)
        founds = []
        last = []
        for camera in self.cameras:
            drawn = drawables(camera, scene)
            window = self._window(camera, [d[2] for d in drawn])
            x0, y0, x1, y1 = window
            w, h = x1 - x0, y1 - y0
            img = np.full((h, w), grey, np.float32)
            if drawn and w and h:
                composite(img, [d[0] for d in drawn], [d[1] for d in drawn], (x0, y0))
            if noise:
                img += np.float32(p.noise_sigma) * self.rng.standard_normal(
                    img.shape, dtype=np.float32
                )
            img8 = quantise(img)
            last.append((img8, window))
            found = _ball_blob(img8, w, h, *blob_args, x0, y0, W, H) if w and h else None
            founds.append(found)
        self._last = last
        self._found = tuple(founds)
        try:
            tracked = scene.get(p.tracked)
        except KeyError:
            return None
        b0, b1 = founds  # (u, v, area, background): the blob records' fields (_blob)
        if b0 is None or b1 is None:
            return None
        uv0, uv1 = (b0[0], b0[1]), (b1[0], b1[1])
        radius = None
        if p.bias_correction and isinstance(tracked, Sphere):
            radius = float(tracked.radius)
        X = self._locate_f(uv0, uv1, radius)
        if X is None or not all(map(math.isfinite, X)):
            return None
        if self._depth(0, X) <= 0.0 or self._depth(1, X) <= 0.0:
            return None  # a mismatch behind a camera
        return VisionObject(
            t=t,
            position=list(X),
            features={"centroids": [list(uv0), list(uv1)], "areas": [b0[2], b1[2]]},
        )


# --- the blob and the triangulation: the accelerator's, or OpenCV's ----------------------


def _ball_blob(img, w, h, threshold, min_pixels, binary, default_bg, ox, oy, W, H):
    """(u, v, area, background) of the largest 8-connected blob above ``threshold`` in a
    window (first pixel (ox, oy)) of a W x H image, or None (:meth:`StereoBallCamera.blob`):
    the accelerator (``_pixels.ball_blob``) where built, else the OpenCV pipeline it replaced
    (equal to 1e-9 px: test_fast_cameras.py)."""
    if _pixels is not None:
        return _pixels.ball_blob(img, w, h, threshold, min_pixels, binary, default_bg, ox, oy, W, H)
    _, mask = cv2.threshold(img, threshold, 1, cv2.THRESH_BINARY)
    ex, ey, ew, eh = cv2.boundingRect(mask)
    if ew == 0:
        return None
    ex0, ey0 = max(ex - 4, 0), max(ey - 4, 0)
    ex1, ey1 = min(ex + ew + 4, w), min(ey + eh + 4, h)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(mask[ey0:ey1, ex0:ex1], connectivity=8)
    i = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    bx, by, bw, bh, area = (int(v) for v in stats[i])
    bx, by = bx + ex0, by + ey0
    if area < min_pixels or bx + ox == 0 or by + oy == 0 or bx + ox + bw == W or by + oy + bh == H:
        return None
    x0, y0 = max(bx - 4, 0), max(by - 4, 0)
    x1, y1 = min(bx + bw + 4, w), min(by + bh + 4, h)
    labels = labels[y0 - ey0 : y1 - ey0, x0 - ex0 : x1 - ex0]
    blob = (labels == i).astype(np.uint8)
    if binary:
        m = cv2.moments(blob, binaryImage=True)
        return (ox + x0 + m["m10"] / m["m00"], oy + y0 + m["m01"] / m["m00"], area, 0.0)
    roi = img[y0:y1, x0:x1].astype(np.float32)
    free = labels == 0
    region = cv2.dilate(blob, np.ones((5, 5), np.uint8)).astype(bool) & (free | blob.astype(bool))
    ring = roi[~region & free]
    if ring.size:
        background = float(np.partition(ring, ring.size // 2)[ring.size // 2])
    else:
        background = default_bg
    weight = np.where(region, roi - np.float32(background), np.float32(0.0))
    m = cv2.moments(weight)
    if m["m00"] <= 0.0:
        return None
    return (ox + x0 + m["m10"] / m["m00"], oy + y0 + m["m01"] / m["m00"], area, background)


def _triangulate(P0, P1, u0, v0, u1, v1):
    """The linear (DLT) two-view triangulation of ``cv2.triangulatePoints``: (x, y, z), or None
    at infinity (the accelerator's ``_pixels.triangulate`` where built)."""
    if _pixels is not None:
        return _pixels.triangulate(P0, P1, u0, v0, u1, v1)
    X = cv2.triangulatePoints(
        np.asarray(P0, dtype=np.float64).reshape(3, 4),
        np.asarray(P1, dtype=np.float64).reshape(3, 4),
        np.array([[u0], [v0]], dtype=np.float64),
        np.array([[u1], [v1]], dtype=np.float64),
    ).ravel()
    if X[3] == 0.0:
        return None
    return (float(X[0] / X[3]), float(X[1] / X[3]), float(X[2] / X[3]))
