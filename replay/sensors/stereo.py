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
3. image moments (``cv2.moments``) give the centroid: by default on grey levels above the local
   background within the blob dilated by 2 px (partly covered edge pixels count by their
   coverage, so the centroid is sub-pixel), or, with ``moments: binary``, on the segmented
   binary image, as a 1-bit vision chip would;
4. ``cv2.triangulatePoints`` with the two cameras' ``K [R | t]`` gives ``r_o``.

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
2.3 mm; with pixel noise sigma = 5 grey levels, worst ~11 mm, median ~0.8 mm. Cost: ~0.25 ms
per ``measure`` (two cameras) without noise, ~0.6 ms with (drawing 2 x 16384 normals).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from replay.interfaces import Sensor
from replay.messages import TOPIC_VISION_OBJECT, VisionObject
from replay.params import ParamError, param
from replay.scene import Scene, Sphere
from replay.sensors.pinhole import Intrinsics, PinholeCamera, look_at_rotation
from replay.sensors.silhouette import correct_sphere_centroid, render_views

_DILATE = np.ones((5, 5), np.uint8)  # the grey-moment region: the blob grown by 2 px
_MARGIN = 4  # px around the blob: region (2) + background ring (2)


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
        doc="write both cameras' images to the log (PNG, /camera/SENSOR/cam0 and cam1) at the "
        "camera rate: ~0.2 KiB and ~0.1 ms a frame pair",
    )

    def __post_init__(self) -> None:
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


class StereoBallCamera(Sensor):
    """Two 128 x 128 cameras, blob moments and triangulation: ``/vision/object`` (``r_o``)."""

    Params = StereoBallCameraParams
    topic = TOPIC_VISION_OBJECT
    description = (
        "two 128x128 pinhole cameras either side of the throw; threshold, image "
        "moments, cv2.triangulatePoints -> ball position r_o"
    )

    def __init__(
        self, params: StereoBallCameraParams, *, rng: np.random.Generator, spec=None
    ) -> None:
        super().__init__(params, rng=rng, spec=spec)
        self.cameras = self.make_cameras(params)
        self.projections = [c.projection_matrix() for c in self.cameras]
        self.last_images: list[np.ndarray | None] = [None, None]
        self.last_blobs: list[dict | None] = [None, None]

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
            out.append(np.clip(np.rint(img), 0, 255).astype(np.uint8))
        return out

    @staticmethod
    def blob(image: np.ndarray, params: StereoBallCameraParams | None = None) -> dict | None:
        """Segment an 8-bit image and take the largest blob's moments: ``u``, ``v`` (centroid,
        pixels), ``area`` (pixels above threshold), ``background`` (grey level, grey mode), or
        None when there is no whole blob of ``min_pixels``."""
        p = params if params is not None else StereoBallCameraParams()
        h, w = image.shape
        _, mask = cv2.threshold(image, p.threshold, 1, cv2.THRESH_BINARY)  # image > threshold
        ex, ey, ew, eh = cv2.boundingRect(mask)
        if ew == 0:
            return None
        # label only around the bright pixels (a full 128 x 128 labelling costs ~0.2 ms)
        ex0, ey0 = max(ex - _MARGIN, 0), max(ey - _MARGIN, 0)
        ex1, ey1 = min(ex + ew + _MARGIN, w), min(ey + eh + _MARGIN, h)
        n, labels, stats, _ = cv2.connectedComponentsWithStats(
            mask[ey0:ey1, ex0:ex1], connectivity=8
        )
        i = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        bx, by, bw, bh, area = (int(v) for v in stats[i])
        bx, by = bx + ex0, by + ey0
        if area < p.min_pixels:
            return None
        if bx == 0 or by == 0 or bx + bw == w or by + bh == h:
            return None  # cut by the image border
        x0, y0 = max(bx - _MARGIN, 0), max(by - _MARGIN, 0)
        x1, y1 = min(bx + bw + _MARGIN, w), min(by + bh + _MARGIN, h)
        labels = labels[y0 - ey0 : y1 - ey0, x0 - ex0 : x1 - ex0]
        blob = (labels == i).astype(np.uint8)
        if p.moments == "binary":
            m = cv2.moments(blob, binaryImage=True)
            return {
                "u": x0 + m["m10"] / m["m00"],
                "v": y0 + m["m01"] / m["m00"],
                "area": area,
                "background": None,
            }
        roi = image[y0:y1, x0:x1].astype(np.float32)
        free = labels == 0
        region = cv2.dilate(blob, _DILATE).astype(bool) & (free | blob.astype(bool))
        ring = roi[~region & free]
        if ring.size:  # local background: the median
            background = float(np.partition(ring, ring.size // 2)[ring.size // 2])
        else:
            background = 255.0 * p.background
        # signed weights: zero-mean noise around the blob leaves the centroid unbiased
        weight = np.where(region, roi - np.float32(background), np.float32(0.0))
        m = cv2.moments(weight)
        if m["m00"] <= 0.0:
            return None  # no signal above the background
        return {
            "u": x0 + m["m10"] / m["m00"],
            "v": y0 + m["m01"] / m["m00"],
            "area": area,
            "background": background,
        }

    def frame_images(self) -> list[tuple[str, np.ndarray]]:
        """The last frame's images (with their noise): ``[("cam0", uint8 HxW), ("cam1", ...)]``."""
        return [(f"cam{i}", img) for i, img in enumerate(self.last_images) if img is not None]

    def triangulate(self, uv0, uv1) -> np.ndarray:
        """World point (3,) from a pixel in each image (``cv2.triangulatePoints``, linear)."""
        X = cv2.triangulatePoints(
            self.projections[0],
            self.projections[1],
            np.asarray(uv0, np.float64).reshape(2, 1),
            np.asarray(uv1, np.float64).reshape(2, 1),
        ).ravel()
        if X[3] == 0.0:
            return np.full(3, np.nan)
        return X[:3] / X[3]

    def locate(self, uv0, uv1, radius: float | None = None) -> np.ndarray:
        """Ball centre from the two silhouette centroids; with ``radius`` (m), the centroids are
        first corrected for the sphere's perspective bias (one refinement step)."""
        X = self.triangulate(uv0, uv1)
        if radius is None or radius <= 0.0 or not np.all(np.isfinite(X)):
            return X
        fixed = []
        for cam, uv in zip(self.cameras, (uv0, uv1)):
            z = float(cam.to_camera(X)[2])
            if z <= radius:
                return X
            fixed.append(correct_sphere_centroid(cam, uv, z, radius))
        return self.triangulate(*fixed)

    # --- the sensor ---------------------------------------------------------------------------
    def measure(self, t: float, scene: Scene) -> VisionObject | None:
        p = self.params
        images = self.render(scene, p, self.rng, self.cameras)
        self.last_images = images
        blobs = [self.blob(img, p) for img in images]
        self.last_blobs = blobs
        try:
            tracked = scene.get(p.tracked)
        except KeyError:
            return None
        if blobs[0] is None or blobs[1] is None:
            return None
        uv = [(b["u"], b["v"]) for b in blobs]
        radius = None
        if p.bias_correction and isinstance(tracked, Sphere):
            radius = float(tracked.radius)
        X = self.locate(uv[0], uv[1], radius)
        if not np.all(np.isfinite(X)):
            return None
        if any(float(cam.to_camera(X)[2]) <= 0.0 for cam in self.cameras):
            return None  # a mismatch behind a camera
        return VisionObject(
            t=t,
            position=[float(v) for v in X],
            features={
                "centroids": [[float(u), float(v)] for u, v in uv],
                "areas": [int(b["area"]) for b in blobs],
            },
        )
