"""Synthetic overhead vision for the stick-capture experiment (Higashimori et al., Sec. IV-A).

The paper's high-speed vision sits 1 m above the air table and measures the stick's position and
orientation at 300 fps from a white rectangular marker on the stick. This sensor does the same
with images: it renders the scene through a :class:`~replay.sensors.pinhole.PinholeCamera` looking
straight down at the table, adds pixel noise, segments the marker by a grey-level threshold and
takes image moments (``cv2.moments``):

- the centroid, back-projected onto the horizontal plane through the marker's centre (its known
  height), gives (x, y);
- the central second moments give the axis angle ``0.5 atan2(2 mu11, mu20 - mu02)`` in the image,
  mapped to the world through the same back-projection; the marker is symmetric, so theta is
  known modulo pi and is returned in (-pi/2, pi/2].

Looking straight down (the default, as in the paper) the table plane maps to the image by a
similarity, so image moments are exact. A tilted camera (``position`` not above ``target``) sees
the marker in perspective and its image centroid is not the image of the marker's centre: a bias
growing with the marker's length squared (about 0.3-0.6 mm for an 80 mm marker seen 17 degrees
off vertical), as a real camera with image moments would have.

Rendering (:func:`render_scene`) is exactly anti-aliased so that the moments resolve sub-pixel
motion: each primitive's silhouette (the convex hull of its projected outline) is composited
far-to-near with each pixel weighted by the area it covers (:func:`replay.sensors.raster.coverage`,
exact). (OpenCV's ``fillConvexPoly`` with LINE_AA and fractional bits was tried first: it grows a
polygon by 0.6-0.8 px, which must be corrected by hand, and even drawn 4x finer and area-averaged
it left 0.03 px periodic centroid errors, visible as a 0.2 mm step measured as 0.24 mm.)
Moments are taken on the segmented blob dilated by two pixels, weighted by grey level above the
local background (the stick, sampled just beyond the marker's ends), so partly covered edge
pixels count by their coverage.

Defaults: 512 x 512 pixels, 1 m above the table centre looking straight down, 0.62 rad field of
view: 0.64 m of table across the image, 1.25 mm per pixel at the table. That keeps +-0.32 m in
view (the 0.4 m x 0.4 m slider range and the stick's approach, with a margin) while the marker
(80 mm x 6 mm in the airtable plant) still spans about 64 x 5 pixels, a blob of ~300 pixels:
enough for moments good to hundredths of a pixel. The paper does not give its camera's
resolution over the table (its vision [10] is a mega-pixel camera reading selected pixels).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from replay.interfaces import Sensor
from replay.messages import TOPIC_VISION_STICK, VisionStick
from replay.params import ParamError, param
from replay.scene import Box, Cylinder, Scene, Sphere
from replay.spatial import quaternion_matrix, wrap_half_pi
from replay.sensors.pinhole import PinholeCamera, look_at_rotation
from replay.sensors.raster import composite

_RIM = 48  # vertices of a polygon standing in for a circle


# --- geometry of primitives ----------------------------------------------------------------

_BOX_SIGNS = np.array(
    [
        [sx, sy, sz]
        for sz in (-1.0, 1.0)
        for sx, sy in ((1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0))
    ]
)


def box_corners(box: Box) -> np.ndarray:
    """The 8 corners (8, 3) of a box in world coordinates; the last 4 are the body +z face."""
    half = np.array([0.5 * float(s) for s in box.size])
    return (_BOX_SIGNS * half) @ quaternion_matrix(box.orientation).T + np.asarray(
        box.position, dtype=float
    )


def _circle(n: int) -> np.ndarray:
    """An n-gon with the unit circle's area (its vertices a little outside the circle)."""
    a = 2.0 * math.pi * np.arange(n) / n
    scale = math.sqrt(2.0 * math.pi / (n * math.sin(2.0 * math.pi / n)))
    return scale * np.column_stack([np.cos(a), np.sin(a)])


_CIRCLE = _circle(_RIM)


def _outline_points(camera: PinholeCamera, prim) -> np.ndarray:
    """World points whose projections' convex hull is the primitive's silhouette."""
    if isinstance(prim, Box):
        return box_corners(prim)
    if isinstance(prim, Cylinder):
        R = quaternion_matrix(prim.orientation)
        ring = prim.radius * _CIRCLE
        pts = [np.column_stack([ring, np.full(_RIM, s * prim.length / 2.0)]) for s in (-1, 1)]
        return np.vstack(pts) @ R.T + np.asarray(prim.position, dtype=float)
    if isinstance(prim, Sphere):
        c = np.asarray(prim.position, dtype=float)
        u = camera.position - c
        d = float(np.linalg.norm(u))
        if d <= prim.radius:
            return np.empty((0, 3))
        u /= d
        # the circle of tangency of the viewing cone: centre c + r^2/d u, radius r sqrt(1 - r^2/d^2)
        a = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        a /= np.linalg.norm(a)
        b = np.cross(u, a)
        rho = prim.radius * math.sqrt(1.0 - (prim.radius / d) ** 2)
        ring = _CIRCLE
        return c + prim.radius**2 / d * u + rho * (ring[:, :1] * a + ring[:, 1:] * b)
    raise TypeError(f"cannot render {type(prim).__name__}")


def _projected_items(camera: PinholeCamera, scene: Scene) -> list:
    """(distance, albedo, convex hull in pixels) of each drawable primitive, far ones first
    (painter's order by the distance of each primitive's centre from the camera: a marker lying
    on a stick, centred above the stick's centre, is nearer to any camera above the table;
    nearest depth fails for oblique views of such stacks). Primitives reaching behind the camera
    are not drawn."""
    prims, outlines = [], []
    for prim in scene.primitives:
        pts = _outline_points(camera, prim)
        if len(pts):
            prims.append(prim)
            outlines.append(pts)
    if not prims:
        return []
    pc = camera.to_camera(np.concatenate(outlines))  # all outlines in one projection
    k = camera.intrinsics
    z = pc[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        uv = np.column_stack([k.fx * pc[:, 0] / z + k.cx, k.fy * pc[:, 1] / z + k.cy]).astype(
            np.float32
        )
    items = []
    end = 0
    for prim, pts in zip(prims, outlines):
        start, end = end, end + len(pts)
        if np.any(z[start:end] <= 1e-6):
            continue
        hull = cv2.convexHull(uv[start:end]).reshape(-1, 2).astype(np.float64)
        if len(hull) >= 3:
            distance = float(
                np.linalg.norm(np.asarray(prim.position, dtype=float) - camera.position)
            )
            items.append((distance, float(prim.albedo), hull, prim.name))
    items.sort(key=lambda it: -it[0])
    return items


def hull_window(camera: PinholeCamera, hull: np.ndarray, margin: int = 8):
    """The pixel box (x0, y0, x1, y1) around a silhouette plus ``margin``, clipped to the image
    (None if it is off the image)."""
    k = camera.intrinsics
    x0 = max(int(math.floor(hull[:, 0].min())) - margin, 0)
    y0 = max(int(math.floor(hull[:, 1].min())) - margin, 0)
    x1 = min(int(math.ceil(hull[:, 0].max())) + margin + 1, k.width)
    y1 = min(int(math.ceil(hull[:, 1].max())) + margin + 1, k.height)
    return None if x1 <= x0 or y1 <= y0 else (x0, y0, x1, y1)


def render_scene(
    camera: PinholeCamera, scene: Scene, *, background: float = 0.1, window=None, items=None
) -> np.ndarray:
    """A noiseless float32 grey image (0..255) of the scene; ``background`` is an albedo.

    Every primitive is drawn as its silhouette (the convex hull of its projected outline) with
    grey level ``255 * albedo``, far ones first. With ``window = (x0, y0, x1, y1)`` only that
    part of the image is rendered (pixel (x0, y0) of the image is pixel (0, 0) of the result);
    ``items`` are ``_projected_items`` already computed.
    """
    k = camera.intrinsics
    x0, y0, x1, y1 = window if window is not None else (0, 0, k.width, k.height)
    img = np.full((y1 - y0, x1 - x0), 255.0 * background, np.float32)
    polys, greys = [], []
    for _, albedo, hull, _ in items if items is not None else _projected_items(camera, scene):
        lo, hi = hull.min(axis=0), hull.max(axis=0)
        if hi[0] < x0 - 1 or hi[1] < y0 - 1 or lo[0] > x1 or lo[1] > y1:
            continue  # wholly outside the window
        polys.append(hull)
        greys.append(255.0 * albedo)
    composite(img, polys, greys, origin=(x0, y0))
    return img


# (along, across) offsets in px of the 9 samples beyond each end of the blob
_END_SAMPLES = np.array([[s, o] for s in (2.0, 3.0, 4.0) for o in (-1.0, 0.0, 1.0)])


def _background_beyond_ends(image: np.ndarray, blob: np.ndarray, origin) -> float | None:
    """Grey level of what surrounds the marker: the stick just beyond the blob's two ends.

    Moments weigh pixels by ``grey - background``, which is linear in a pixel's coverage only
    if ``background`` is the grey level actually under the marker's edge; a floor set higher
    biases the centroid by up to half a pixel along the axis. The level is the median of 9
    pixels 2-4 px beyond each end of the blob along its long axis (so the stick must extend
    that far beyond the marker, ~5 mm at 1.25 mm/px), the brighter end winning (a dark
    fingertip may cover one end).
    """
    m = cv2.moments(blob, binaryImage=True)
    if m["m00"] <= 0.0:
        return None
    a = 0.5 * math.atan2(2.0 * m["mu11"], m["mu20"] - m["mu02"])
    e = np.array([math.cos(a), math.sin(a)])
    n = np.array([-e[1], e[0]])
    c = np.array([origin[0] + m["m10"] / m["m00"], origin[1] + m["m01"] / m["m00"]])
    rows, cols = np.nonzero(blob)
    along = (np.column_stack([cols + origin[0], rows + origin[1]]) - c) @ e
    h, w = image.shape
    levels = []
    for end in (along.max(), along.min()):  # the blob's extreme pixels on its axis
        sign = 1.0 if end > 0 else -1.0
        pts = c + (end + sign * _END_SAMPLES[:, :1]) * e + _END_SAMPLES[:, 1:] * n
        ij = np.rint(pts).astype(int)
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < w) & (ij[:, 1] >= 0) & (ij[:, 1] < h)
        if ok.any():
            levels.append(float(np.median(image[ij[ok, 1], ij[ok, 0]])))
    return max(levels) if levels else None


# --- the sensor ----------------------------------------------------------------------------


@dataclass
class StickCameraParams:
    width: int = param(512, unit="px", ge=16, le=4096, doc="image width")
    height: int = param(512, unit="px", ge=16, le=4096, doc="image height")
    position: list[float] = param(
        [0.0, 0.0, 1.0],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="optical centre (world); paper: 1 m above the table",
    )
    target: list[float] = param(
        [0.0, 0.0, 0.0],
        unit="m",
        length=3,
        ge=-100,
        le=100,
        doc="world point on the optical axis; default: straight down at the table centre",
    )
    up: list[float] = param(
        [0.0, 1.0, 0.0],
        unit="1",
        length=3,
        ge=-1e3,
        le=1e3,
        doc="world direction shown as 'up' in the image (not along the axis)",
    )
    fov_x: float = param(
        0.62,
        unit="rad",
        gt=0,
        lt=math.pi,
        doc="horizontal field of view, edge to edge; 0.62 rad (35.5 deg) from "
        "1 m: 0.640 m of table across 512 px, 1.25 mm per pixel",
    )
    noise_sigma: float = param(
        0.0,
        unit="grey level",
        ge=0,
        le=1000,
        doc="standard deviation of Gaussian pixel noise (0..255 scale)",
    )
    position_offset: list[float] = param(
        [0.0, 0.0],
        unit="m",
        length=2,
        ge=-10,
        le=10,
        doc="constant bias added to the measured (x, y)",
    )
    threshold: float = param(
        192.0,
        unit="grey level",
        ge=0,
        le=255,
        doc="pixels brighter than this are marker (white 255 vs stick)",
    )
    min_pixels: int = param(
        20,
        unit="px",
        ge=1,
        le=4096 * 4096,
        doc="smallest marker blob (pixels above threshold) accepted",
    )
    background: float = param(0.1, unit="1", ge=0, le=1, doc="albedo of the table (dark)")
    marker: str = param("marker", max_length=100, doc="name of the Box the camera tracks")
    log_images: bool = param(
        False,
        doc="write each whole frame to the log (PNG, /camera/SENSOR/image) at the camera rate; "
        "off by default: a 512 px frame costs ~1 ms to build and encode",
    )

    def __post_init__(self) -> None:
        try:
            look_at_rotation(self.position, self.target, self.up)
        except ValueError as exc:
            raise ParamError("target" if "coincide" in str(exc) else "up", str(exc)) from None


class StickCamera(Sensor):
    """Overhead camera measuring the stick's marker: ``/vision/stick`` (x, y, theta)."""

    Params = StickCameraParams
    topic = TOPIC_VISION_STICK
    description = (
        "overhead pinhole camera 1 m above the table; white-marker centroid and "
        "second moments -> stick x, y, theta (mod pi)"
    )

    def __init__(self, params: StickCameraParams, *, rng: np.random.Generator, spec=None) -> None:
        super().__init__(params, rng=rng, spec=spec)
        self.camera = self.make_camera(params)
        self._last = None

    # --- helpers usable without a sensor instance -------------------------------------------
    @staticmethod
    def make_camera(params: StickCameraParams) -> PinholeCamera:
        """The look-at pinhole of the params (square pixels, principal point at the centre);
        by default straight down from 1 m: image x = world x, image up = world +y."""
        return PinholeCamera.from_fov(
            params.width,
            params.height,
            params.fov_x,
            eye=params.position,
            target=params.target,
            up=params.up,
        )

    @staticmethod
    def render(
        scene: Scene,
        params: StickCameraParams | None = None,
        rng: np.random.Generator | None = None,
        window=None,
    ) -> np.ndarray:
        """The 8-bit image the camera would see (noise only if ``rng`` is given), or only its
        ``window`` (x0, y0, x1, y1)."""
        p = params if params is not None else StickCameraParams()
        img = render_scene(
            StickCamera.make_camera(p), scene, background=p.background, window=window
        )
        if rng is not None and p.noise_sigma > 0.0:
            img = img + np.float32(p.noise_sigma) * rng.standard_normal(img.shape, dtype=np.float32)
        return np.clip(np.rint(img), 0, 255).astype(np.uint8)

    @staticmethod
    def marker_moments(
        image: np.ndarray, params: StickCameraParams, origin: tuple[int, int] = (0, 0)
    ) -> dict | None:
        """Segment the marker in an 8-bit image; its weighted ``cv2.moments`` (in full-image
        pixel coordinates: ``u``, ``v`` centroid, ``angle`` of the long axis in the image,
        ``pixels`` above threshold), or None when there is no whole blob of enough pixels.
        ``image`` may be a window of the full image whose first pixel is ``origin``."""
        h, w = image.shape
        ox, oy = origin
        mask = (image > params.threshold).astype(np.uint8)
        bright = cv2.findNonZero(mask)
        if bright is None:
            return None
        cx, cy, cw, ch = cv2.boundingRect(bright)  # label only where it is bright
        n, labels, stats, _ = cv2.connectedComponentsWithStats(
            mask[cy : cy + ch, cx : cx + cw], connectivity=8
        )
        if n <= 1:
            return None
        i = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
        bx, by, bw, bh, area = (int(v) for v in stats[i])
        bx, by = bx + cx, by + cy
        if area < params.min_pixels:
            return None
        if (
            bx + ox == 0
            or by + oy == 0
            or bx + ox + bw == params.width
            or by + oy + bh == params.height
        ):
            return None  # cut by the image border
        x0, y0 = max(bx - 3, 0), max(by - 3, 0)
        x1, y1 = min(bx + bw + 3, w), min(by + bh + 3, h)
        roi = image[y0:y1, x0:x1].astype(np.float32)
        blob = np.zeros((y1 - y0, x1 - x0), np.uint8)
        lx0, ly0 = bx - cx, by - cy  # the blob's box in the crop
        blob[by - y0 : by - y0 + bh, bx - x0 : bx - x0 + bw] = (
            labels[ly0 : ly0 + bh, lx0 : lx0 + bw] == i
        )
        background = _background_beyond_ends(image, blob, (x0, y0))
        if background is None:
            return None
        region = cv2.dilate(blob, np.ones((5, 5), np.uint8)).astype(bool)
        weight = np.where(region, np.maximum(roi - np.float32(background), 0.0), 0.0)
        m = cv2.moments(weight.astype(np.float32))
        if m["m00"] <= 0.0:
            return None
        return {
            "u": ox + x0 + m["m10"] / m["m00"],
            "v": oy + y0 + m["m01"] / m["m00"],
            "angle": 0.5 * math.atan2(2.0 * m["mu11"], m["mu20"] - m["mu02"]),
            "pixels": area,
            "background": background,
            "moments": m,
        }

    # --- the sensor ---------------------------------------------------------------------------
    @property
    def last_image(self) -> np.ndarray | None:
        """The whole last frame (background outside the rendered window, without its noise)."""
        if self._last is None:
            return None
        crop, (x0, y0, x1, y1) = self._last
        p = self.params
        full = np.full((p.height, p.width), round(255.0 * p.background), np.uint8)
        full[y0:y1, x0:x1] = crop
        return full

    def frame_images(self) -> list[tuple[str, np.ndarray]]:
        """The last frame (:attr:`last_image`): ``[("image", uint8 HxW)]``."""
        image = self.last_image
        return [] if image is None else [("image", image)]

    def measure(self, t: float, scene: Scene) -> VisionStick | None:
        p = self.params
        # Only a window around the marker is rendered (and given noise): the moments use
        # nothing else, and the dark table elsewhere never passes the threshold.
        items = _projected_items(self.camera, scene)
        hull = next((h for _, _, h, name in items if name == p.marker), None)
        window = None if hull is None else hull_window(self.camera, hull)
        if window is None:  # no marker in view: the whole (rare) frame
            window = (0, 0, p.width, p.height)
        img = render_scene(self.camera, scene, background=p.background, window=window, items=items)
        if p.noise_sigma > 0.0:
            img = img + np.float32(p.noise_sigma) * self.rng.standard_normal(
                img.shape, dtype=np.float32
            )
        img = np.clip(np.rint(img), 0, 255).astype(np.uint8)
        self._last = (img, window)
        try:
            marker = scene.get(p.marker)
        except KeyError:
            return None
        found = self.marker_moments(img, p, origin=window[:2])
        if found is None:
            return None
        # The marker's silhouette seen from above is its top face swept down to its bottom face;
        # its centroid lies on the ray through the box's centre (exactly so for a thin box), so
        # the centroid is back-projected onto the horizontal plane through the marker's centre.
        z = float(marker.position[2])
        u, v, a = found["u"], found["v"], found["angle"]
        step = 10.0  # px along the axis, for its angle
        pts = self.camera.backproject_to_height(
            np.array([[u, v], [u + step * math.cos(a), v + step * math.sin(a)]]), z
        )
        if not np.all(np.isfinite(pts)):
            return None
        theta = wrap_half_pi(math.atan2(pts[1, 1] - pts[0, 1], pts[1, 0] - pts[0, 0]))
        return VisionStick(
            t=t,
            x=float(pts[0, 0]) + float(p.position_offset[0]),
            y=float(pts[0, 1]) + float(p.position_offset[1]),
            theta=theta,
        )
