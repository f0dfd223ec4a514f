"""Synthetic overhead vision for the stick-capture experiment (Higashimori et al., Sec. IV-A).

The paper's high-speed vision sits 1 m above the air table and measures the stick's position and
orientation at 300 fps from a white rectangular marker on the stick. This sensor does the same
with images: it renders the scene through a :class:`~replay.sensors.pinhole.PinholeCamera` looking
straight down at the table, adds pixel noise, segments the marker by a grey-level threshold and
takes image moments:

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

Cost: a frame renders only the window around the marker's silhouette (plus 8 px; the rest of
the image is exactly the dark table, which never passes the threshold, and is filled in only
when the whole image is asked for, :attr:`StickCamera.last_image`), draws only the primitives
whose bounding sphere's image meets that window, and does the per-pixel work in compiled
kernels where the optional accelerator is built (``_pixels.c``: outline projection and hull,
exact-coverage compositing, 8-bit quantising, segmentation and moments in one pass; without
it the same algorithms in NumPy/OpenCV, held together in tests/replay/sensors/
test_fast_cameras.py and test_raster.py): ~0.2 ms a frame of stick_3step, ~1 ms in Python
(docs/DESIGN.md, "Compiled code"), measurements equal to 1e-14 m either way.

Accuracy (test_fast_cameras.py, noise-free, 200 random poses of the stick_3step geometry, 1.8 mm
per pixel, no fingertips), the same before and after the kernels: bias (mean error) x -0.17,
y +0.39 um, theta +0.0017 deg; scatter (std) x 7.6, y 8.7 um, theta 0.012 deg; worst 43 um
(1/40 px), 0.097 deg.

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

import numpy as np

from replay.foxglove.image import WindowedImage
from replay.interfaces import Sensor
from replay.messages import TOPIC_VISION_STICK, VisionStick
from replay.params import ParamError, param
from replay.scene import Box, Cylinder, Scene, Sphere
from replay.spatial import quaternion_matrix, wrap_half_pi
from replay.sensors.pinhole import PinholeCamera, check_image_size, look_at_rotation
from replay.accel import accelerator
from replay.sensors.silhouette import project_hull
from replay.sensors.raster import composite, quantise

import cv2  # (the moments' pure-Python path: the OpenCV pipeline the accelerator replaced)

_pixels = accelerator("replay.sensors._pixels")

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
    return _body_points(box) @ quaternion_matrix(box.orientation).T + np.asarray(
        box.position, dtype=float
    )


def _circle(n: int) -> np.ndarray:
    """An n-gon with the unit circle's area (its vertices a little outside the circle)."""
    a = 2.0 * math.pi * np.arange(n) / n
    scale = math.sqrt(2.0 * math.pi / (n * math.sin(2.0 * math.pi / n)))
    return scale * np.column_stack([np.cos(a), np.sin(a)])


_CIRCLE = _circle(_RIM)
_BODY: dict = {}  # body-frame outline points by shape (sizes do not change during a run)


def _body_points(prim: Box | Cylinder) -> np.ndarray:
    """Body-frame points whose projections' convex hull is a box's or cylinder's silhouette."""
    if isinstance(prim, Box):
        key: tuple = ("box", *prim.size)
    else:
        key = ("cylinder", prim.radius, prim.length)
    pts = _BODY.get(key)
    if pts is None:
        if isinstance(prim, Box):
            pts = _BOX_SIGNS * np.array([0.5 * float(s) for s in prim.size])
        else:
            ring = prim.radius * _CIRCLE
            pts = np.vstack(
                [np.column_stack([ring, np.full(_RIM, s * prim.length / 2.0)]) for s in (-1, 1)]
            )
        if len(_BODY) < 1024:
            _BODY[key] = pts
    return pts


def _outline_points(camera: PinholeCamera, prim) -> np.ndarray:
    """World points whose projections' convex hull is the primitive's silhouette."""
    if isinstance(prim, (Box, Cylinder)):
        R = quaternion_matrix(prim.orientation)
        return _body_points(prim) @ R.T + np.asarray(prim.position, dtype=float)
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


def _silhouette(camera: PinholeCamera, prim, origin: tuple | None = None):
    """(distance of its centre from the camera, albedo, convex hull in pixels, name, pixel box
    (umin, vmin, umax, vmax)) of a primitive, or None if it reaches behind the camera (or has
    no area). The outline's projection and hull: :func:`~replay.sensors.silhouette.project_hull`
    (the same float32 pixels as NumPy's projection and ``cv2.convexHull`` gave). ``origin``: the
    camera's position as a tuple of floats, if already made."""
    if isinstance(prim, (Box, Cylinder)):
        body, q, pos = _body_points(prim), prim.orientation, prim.position
    else:
        body, q, pos = _outline_points(camera, prim), (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0)
        if not len(body):
            return None
    found = project_hull(camera, body, q, pos)
    if found is None or len(found[0]) < 3:
        return None
    distance = math.dist(prim.position, camera.position.tolist() if origin is None else origin)
    return (distance, prim.albedo, found[0], prim.name, found[1])


def _misses(camera: PinholeCamera, prim, window, R, o) -> bool:
    """Whether a primitive certainly draws nothing in ``window`` (x0, y0, x1, y1): the image of
    its bounding sphere (centre c, radius rb) lies within ``f rb (Z + |X|) / ((Z - rb) Z)`` px
    of c's projection along each image axis (|x/z - X/Z| for |x - X|, |z - Z| <= rb), plus a
    pixel, and that box misses the window. ``R``, ``o``: the camera's rotation and position as
    nested tuples of floats."""
    if isinstance(prim, Box):
        sx, sy, sz = prim.size
        rb = 0.5 * math.sqrt(sx * sx + sy * sy + sz * sz)
    elif isinstance(prim, Cylinder):
        rb = math.hypot(prim.radius, 0.5 * prim.length)
    else:
        rb = float(prim.radius)
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = R
    px, py, pz = prim.position
    dx, dy, dz = px - o[0], py - o[1], pz - o[2]
    X = r00 * dx + r10 * dy + r20 * dz  # R^T d
    Y = r01 * dx + r11 * dy + r21 * dz
    Z = r02 * dx + r12 * dy + r22 * dz
    if Z - rb <= 1e-6:
        return False
    k = camera.intrinsics
    u, v = k.fx * X / Z + k.cx, k.fy * Y / Z + k.cy
    g = rb / ((Z - rb) * Z)
    bu, bv = k.fx * g * (Z + abs(X)) + 1.0, k.fy * g * (Z + abs(Y)) + 1.0
    x0, y0, x1, y1 = window
    return u + bu < x0 - 1 or v + bv < y0 - 1 or u - bu > x1 or v - bv > y1


def _by_distance(items: list) -> list:
    """Far ones first (painter's order by the distance of each primitive's centre from the
    camera: a marker lying on a stick, centred above the stick's centre, is nearer to any
    camera above the table; nearest depth fails for oblique views of such stacks)."""
    items.sort(key=lambda it: -it[0])
    return items


def _projected_items(camera: PinholeCamera, scene: Scene) -> list:
    """:func:`_silhouette` of each drawable primitive, far ones first (:func:`_by_distance`).
    Primitives reaching behind the camera are not drawn."""
    return _by_distance(
        [it for it in map(lambda q: _silhouette(camera, q), scene.primitives) if it]
    )


def hull_window(camera: PinholeCamera, box, margin: int = 8):
    """The pixel box (x0, y0, x1, y1) around a silhouette's box (umin, vmin, umax, vmax) plus
    ``margin``, clipped to the image (None if it is off the image)."""
    k = camera.intrinsics
    x0 = max(int(math.floor(box[0])) - margin, 0)
    y0 = max(int(math.floor(box[1])) - margin, 0)
    x1 = min(int(math.ceil(box[2])) + margin + 1, k.width)
    y1 = min(int(math.ceil(box[3])) + margin + 1, k.height)
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
    for _, albedo, hull, _, (ulo, vlo, uhi, vhi) in (
        items if items is not None else _projected_items(camera, scene)
    ):
        if uhi < x0 - 1 or vhi < y0 - 1 or ulo > x1 or vlo > y1:
            continue  # wholly outside the window
        polys.append(hull)
        greys.append(255.0 * albedo)
    composite(img, polys, greys, origin=(x0, y0))
    return img


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
        doc="write each whole frame to the log (RawImage mono8, /camera/SENSOR/image) at the camera rate; "
        "off by default: a 512 px frame costs ~1 ms to build and encode",
    )

    def __post_init__(self) -> None:
        check_image_size(self.width, self.height)
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
        self._R = tuple(tuple(float(v) for v in row) for row in self.camera.rotation)
        self._o = tuple(float(v) for v in self.camera.position)
        self._last: tuple[np.ndarray, tuple[int, int, int, int]] | None = None  # (crop, window)
        # by name: (the primitive, its _silhouette): a primitive object seen again (a frozen
        # one the plant keeps while it does not move, e.g. a still fingertip) is not projected
        # again (the camera does not move either)
        self._seen: dict[str, tuple] = {}

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
        return quantise(img)

    @staticmethod
    def marker_moments(
        image: np.ndarray, params: StickCameraParams, origin: tuple[int, int] = (0, 0)
    ) -> dict | None:
        """Segment the marker in an 8-bit image; its weighted moments (in full-image pixel
        coordinates: ``u``, ``v`` centroid, ``angle`` of the long axis in the image, ``pixels``
        above threshold, ``background``, ``moments`` about the blob's box), or None when there
        is no whole blob of enough pixels. ``image`` may be a window of the full image whose
        first pixel is ``origin``.

        The marker is the largest 8-connected blob above ``threshold`` (None if it touches the
        image border). Moments weigh pixels by ``grey - background`` within the blob dilated by
        2 px (5 x 5), which is linear in a pixel's coverage only if ``background`` is the grey
        level actually under the marker's edge (a floor set higher biases the centroid by up to
        half a pixel along the axis): the level is the median of 9 pixels 2-4 px beyond each end
        of the blob along its long axis (so the stick must extend that far beyond the marker,
        ~5 mm at 1.25 mm/px), the brighter end winning (a dark fingertip may cover one end).
        Computed in one pass by the optional accelerator (``_pixels.marker_moments``), else by
        the OpenCV pipeline it replaced (:func:`_moments_opencv`)."""
        found = StickCamera._moments(image, params, origin)
        if found is None:
            return None
        u, v, angle, pixels, background, *m = found
        return {
            "u": u,
            "v": v,
            "angle": angle,
            "pixels": pixels,
            "background": background,
            "moments": dict(zip(("m00", "m10", "m01", "mu20", "mu11", "mu02"), m)),
        }

    @staticmethod
    def _moments(image: np.ndarray, params: StickCameraParams, origin: tuple[int, int]):
        """:meth:`marker_moments` as a tuple: (u, v, angle, pixels, background, m00, m10, m01,
        mu20, mu11, mu02) or None. The accelerator (``_pixels.marker_moments``, one pass) where
        built, else the OpenCV pipeline it replaced (equal to 1e-9 px: test_fast_cameras.py)."""
        img = np.ascontiguousarray(image, dtype=np.uint8)
        h, w = img.shape
        if _pixels is not None:
            return _pixels.marker_moments(
                img,
                w,
                h,
                float(params.threshold),
                int(params.min_pixels),
                int(origin[0]),
                int(origin[1]),
                int(params.width),
                int(params.height),
            )
        return _moments_opencv(img, params, origin)

    # --- the sensor ---------------------------------------------------------------------------
    @property
    def last_image(self) -> np.ndarray | None:
        """The whole last frame (background outside the rendered window, without its noise)."""
        frames = self.frame_images()
        return frames[0][1].full() if frames else None

    def frame_images(self) -> list[tuple[str, WindowedImage]]:
        """The last frame (:attr:`last_image`, as its rendered window in the background):
        ``[("image", WindowedImage)]``."""
        if self._last is None:
            return []
        crop, window = self._last
        p = self.params
        return [
            ("image", WindowedImage(p.height, p.width, round(255.0 * p.background), window, crop))
        ]

    def measure(self, t: float, scene: Scene) -> VisionStick | None:
        """The marker's pose in a frame of ``scene`` (the module doc's pipeline)."""
        p = self.params
        cam = self.camera
        # Only a window around the marker is rendered (and given noise): the moments use
        # nothing else, and the dark table elsewhere never passes the threshold. Only the
        # primitives that may draw in it are projected.
        try:
            marker = scene.get(p.marker)
        except KeyError:
            marker = None
        seen = _silhouette(cam, marker, self._o) if marker is not None else None
        window = None if seen is None else hull_window(cam, seen[4])
        if window is None:  # no marker in view: the whole (rare) frame
            window = (0, 0, p.width, p.height)
            items = _projected_items(cam, scene)
        else:
            items = []
            for prim in scene.primitives:
                if prim is marker:
                    items.append(seen)
                elif not _misses(cam, prim, window, self._R, self._o):
                    kept = self._seen.get(prim.name)
                    if kept is None or kept[0] is not prim:
                        kept = self._seen[prim.name] = (prim, _silhouette(cam, prim, self._o))
                    if kept[1] is not None:
                        items.append(kept[1])
            _by_distance(items)
        img = render_scene(cam, scene, background=p.background, window=window, items=items)
        if p.noise_sigma > 0.0:
            img = img + np.float32(p.noise_sigma) * self.rng.standard_normal(
                img.shape, dtype=np.float32
            )
        img = quantise(img)
        self._last = (img, window)
        if marker is None:
            return None
        found = self._moments(img, p, window[:2])  # (marker_moments without its dict)
        return self._pose(t, marker, found)

    def _pose(self, t: float, marker: Box, found: tuple | None) -> VisionStick | None:
        """The measurement from the marker's moments (``_pixels.marker_moments``), or None."""
        if found is None:
            return None
        p = self.params
        # The marker's silhouette seen from above is its top face swept down to its bottom face;
        # its centroid lies on the ray through the box's centre (exactly so for a thin box), so
        # the centroid is back-projected onto the horizontal plane through the marker's centre.
        z = float(marker.position[2])
        u, v, a = found[0], found[1], found[2]
        step = 10.0  # px along the axis, for its angle
        p0 = self._to_height(u, v, z)
        p1 = self._to_height(u + step * math.cos(a), v + step * math.sin(a), z)
        if p0 is None or p1 is None:
            return None
        theta = wrap_half_pi(math.atan2(p1[1] - p0[1], p1[0] - p0[0]))
        return VisionStick(
            t=t,
            x=p0[0] + float(p.position_offset[0]),
            y=p0[1] + float(p.position_offset[1]),
            theta=theta,
        )

    def _to_height(self, u: float, v: float, z: float) -> tuple[float, float] | None:
        """World (x, y) where pixel (u, v)'s ray meets the plane at height ``z``, or None
        (:meth:`PinholeCamera.backproject_to_height` for one pixel, in scalars)."""
        k = self.camera.intrinsics
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = self._R
        a, b = (u - k.cx) / k.fx, (v - k.cy) / k.fy
        dx, dy, dz = r00 * a + r01 * b + r02, r10 * a + r11 * b + r12, r20 * a + r21 * b + r22
        n = math.sqrt(dx * dx + dy * dy + dz * dz)
        ox, oy, oz = self._o
        s = (z - oz) / dz if dz != 0.0 else math.nan
        if not (abs(dz / n) > 1e-12 and s > 0.0):
            return None
        return ox + s * dx, oy + s * dy


# --- the marker's moments without the accelerator: OpenCV -----------------------------------

_END_SAMPLES = np.array([[s, o] for s in (2.0, 3.0, 4.0) for o in (-1.0, 0.0, 1.0)])


def _background_beyond_ends(image: np.ndarray, blob: np.ndarray, origin) -> float | None:
    """The median of 9 pixels 2-4 px beyond each end of the blob along its long axis, the
    brighter end's (:meth:`StickCamera.marker_moments`)."""
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
    for end in (along.max(), along.min()):
        sign = 1.0 if end > 0 else -1.0
        pts = c + (end + sign * _END_SAMPLES[:, :1]) * e + _END_SAMPLES[:, 1:] * n
        ij = np.rint(pts).astype(int)
        ok = (ij[:, 0] >= 0) & (ij[:, 0] < w) & (ij[:, 1] >= 0) & (ij[:, 1] < h)
        if ok.any():
            levels.append(float(np.median(image[ij[ok, 1], ij[ok, 0]])))
    return max(levels) if levels else None


def _moments_opencv(image: np.ndarray, params: StickCameraParams, origin) -> tuple | None:
    """:meth:`StickCamera._moments` with OpenCV: threshold, the largest 8-connected blob (none
    touching the image's border), the background beyond its ends, grey-level moments over the
    blob dilated by 2 px."""
    h, w = image.shape
    ox, oy = int(origin[0]), int(origin[1])
    mask = (image > params.threshold).astype(np.uint8)
    bright = cv2.findNonZero(mask)
    if bright is None:
        return None
    cx, cy, cw, ch = cv2.boundingRect(bright)
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
        return None
    x0, y0 = max(bx - 3, 0), max(by - 3, 0)
    x1, y1 = min(bx + bw + 3, w), min(by + bh + 3, h)
    roi = image[y0:y1, x0:x1].astype(np.float32)
    blob = np.zeros((y1 - y0, x1 - x0), np.uint8)
    lx0, ly0 = bx - cx, by - cy
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
    return (
        ox + x0 + m["m10"] / m["m00"],
        oy + y0 + m["m01"] / m["m00"],
        0.5 * math.atan2(2.0 * m["mu11"], m["mu20"] - m["mu02"]),
        area,
        background,
        m["m00"],
        m["m10"],
        m["m01"],
        m["mu20"],
        m["mu11"],
        m["mu02"],
    )
