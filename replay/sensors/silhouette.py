"""Fast anti-aliased silhouettes of scene primitives through a pinhole camera.

A camera at 1 kHz cannot afford a 3-D renderer (PyBullet's TinyRenderer takes ~5 ms for 128 x 128);
a ball camera needs only silhouettes, which are known in closed form:

- **Sphere**: its perspective outline is an ellipse, the image of the cone of rays tangent to it
  (:func:`sphere_ellipse`, exact). With the sphere's centre at ``(X, Y, Z)`` in the camera frame,
  radius ``r``, ``E = Z^2 - r^2`` and ``D = X^2 + Y^2 + Z^2 - r^2``, in normalised image
  coordinates ``x = (x/z, y/z)`` the outline is ``(x - e)^T B (x - e) = 1`` with
  ``e = Z (X, Y) / E`` and ``B = (E / r^2) (I - u u^T / D)``, ``u = (X, Y)``. It exists (is a
  bounded ellipse) iff ``Z > r``. Note ``e`` is the projected centre ``(X, Y) / Z`` scaled by
  ``Z^2 / E``: the silhouette's centroid lies radially *outside* the projection of the sphere's
  centre, by ``r^2 / (Z^2 - r^2)`` of its distance from the principal point
  (:func:`sphere_centroid_bias`).
- **Box**: the convex hull of its 8 projected corners; **Cylinder**: the hull of two projected
  rims. Both are exact silhouettes of convex bodies entirely in front of the camera.

Rasterising: each silhouette is a convex polygon in pixels (a sphere's ellipse as an N-gon scaled
to the ellipse's area), composited far to near (painter's order by the distance of each
primitive's centre: right for a small ball in front of or behind a larger body, not for
interpenetrating or interleaved bodies) with each pixel weighted by the exact area the polygon
covers in it (:mod:`replay.sensors.raster`, the stick camera's rasteriser too). Primitives
reaching behind the camera's plane are not drawn. Image conventions are
:mod:`replay.sensors.pinhole`'s: integer pixel coordinates are pixel centres.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.scene import Box, Cylinder, Scene, Sphere
from replay.sensors.pinhole import PinholeCamera
from replay.spatial import quaternion_matrix
from replay.accel import accelerator
from replay.sensors.raster import composite

_pixels = accelerator("replay.sensors._pixels")

ELLIPSE_VERTICES = 48  # vertices of the polygon standing in for an ellipse
_NEAR = 1e-6  # m: nearest depth drawn
# an N-gon inscribed at equal parameter steps has N/2 sin(2 pi/N) / pi of the ellipse's area
_AREA_SCALE = math.sqrt(
    2.0 * math.pi / (ELLIPSE_VERTICES * math.sin(2.0 * math.pi / ELLIPSE_VERTICES))
)
_COS = np.cos(2.0 * math.pi * np.arange(ELLIPSE_VERTICES) / ELLIPSE_VERTICES)
_SIN = np.sin(2.0 * math.pi * np.arange(ELLIPSE_VERTICES) / ELLIPSE_VERTICES)


@dataclass(frozen=True)
class Ellipse:
    """An image ellipse in pixels: centre, semi-axes ``a >= b`` and the angle (rad) of the
    ``a`` axis from the image u axis (towards +v); ``depth`` is the sphere's centre depth Z (m)."""

    u: float
    v: float
    a: float
    b: float
    angle: float
    depth: float

    @property
    def area(self) -> float:
        return math.pi * self.a * self.b

    def polygon(self, inset: float = 0.0, area_exact: bool = True) -> np.ndarray:
        """(N, 2) vertices on the ellipse with both semi-axes reduced by ``inset`` px; scaled so
        that the polygon's area is the (reduced) ellipse's if ``area_exact``."""
        return self.polygon_and_box(inset, area_exact)[0]

    def polygon_and_box(self, inset: float = 0.0, area_exact: bool = True):
        """:meth:`polygon` and its box (umin, vmin, umax, vmax) (:func:`_ellipse_polygon`)."""
        return _ellipse_polygon(self.u, self.v, self.a, self.b, self.angle, inset, area_exact)


def _ellipse_polygon(u, v, a, b, angle, inset=0.0, area_exact=True):
    """:meth:`Ellipse.polygon_and_box` of an ellipse given by its fields (the accelerator's
    ``ellipse_polygon`` where built: the same operations)."""
    k = _AREA_SCALE if area_exact else 1.0
    a, b = max(a - inset, 0.05 * a) * k, max(b - inset, 0.05 * b) * k
    c, s = math.cos(angle), math.sin(angle)
    out = np.empty((ELLIPSE_VERTICES, 2))
    if _pixels is not None:
        box = _pixels.ellipse_polygon(_COS, _SIN, u, v, a, b, c, s, out)
        return out, box
    out[:, 0] = u + (a * c) * _COS - (b * s) * _SIN
    out[:, 1] = v + (a * s) * _COS + (b * c) * _SIN
    lo, hi = out.min(axis=0).tolist(), out.max(axis=0).tolist()
    return out, (lo[0], lo[1], hi[0], hi[1])


def sphere_ellipse(camera: PinholeCamera, centre, radius: float) -> Ellipse | None:
    """The exact outline of a sphere in the image, or None if the sphere is not entirely in
    front of the camera's plane (``Z <= r``: the outline is then unbounded or empty)."""
    e = _sphere_ellipse_fields(camera, centre, radius)
    return None if e is None else Ellipse(*e)


def _sphere_ellipse_fields(camera: PinholeCamera, centre, radius: float) -> tuple | None:
    """:func:`sphere_ellipse`'s fields (u, v, a, b, angle, depth) in floats, or None (the
    raster's per-frame path makes no :class:`Ellipse`)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = camera.rotation.tolist()
    o = camera.position.tolist()
    dx, dy, dz = float(centre[0]) - o[0], float(centre[1]) - o[1], float(centre[2]) - o[2]
    X = r00 * dx + r10 * dy + r20 * dz  # p_cam = R^T (p - o)
    Y = r01 * dx + r11 * dy + r21 * dz
    Z = r02 * dx + r12 * dy + r22 * dz
    r2 = float(radius) ** 2
    E = Z * Z - r2
    if radius <= 0.0 or Z <= float(radius) * (1.0 + 1e-9) or E <= 0.0:
        return None
    D = E + X * X + Y * Y
    k = camera.intrinsics
    fx, fy = k.fx, k.fy
    # B in pixels: S^-1 B_n S^-1 with S = diag(fx, fy)
    g = E / r2
    baa = g * (1.0 - X * X / D) / (fx * fx)
    bdd = g * (1.0 - Y * Y / D) / (fy * fy)
    bh = -g * X * Y / (D * fx * fy)
    mean = 0.5 * (baa + bdd)
    rad = math.hypot(0.5 * (baa - bdd), bh)
    lam_small, lam_big = mean - rad, mean + rad  # semi-axes 1/sqrt(lambda)
    angle = 0.5 * math.atan2(2.0 * bh, baa - bdd) + 0.5 * math.pi  # axis of lam_small
    return (
        fx * X * Z / E + k.cx,  # u
        fy * Y * Z / E + k.cy,  # v
        1.0 / math.sqrt(lam_small),  # a
        1.0 / math.sqrt(lam_big),  # b
        math.atan2(math.sin(angle), math.cos(angle)),  # angle
        Z,  # depth
    )


def sphere_centroid_bias(camera: PinholeCamera, centre, radius: float) -> np.ndarray:
    """Silhouette centroid minus projected centre (pixels) of a sphere: the radial offset
    ``(p - c) r^2 / (Z^2 - r^2)``, ``p`` the projected centre, ``c`` the principal point."""
    e = sphere_ellipse(camera, centre, radius)
    if e is None:
        return np.full(2, np.nan)
    return np.array([e.u, e.v]) - camera.project(np.asarray(centre, float))


def correct_sphere_centroid(camera: PinholeCamera, uv, depth: float, radius: float) -> np.ndarray:
    """The projection of a sphere's centre from its silhouette centroid ``uv`` (pixels), given
    the centre's depth ``depth`` (m, along the optical axis) and the radius (m)."""
    k = camera.intrinsics
    s = (depth * depth - radius * radius) / (depth * depth)
    return np.array([k.cx + (uv[0] - k.cx) * s, k.cy + (uv[1] - k.cy) * s])


# --- polygons of other primitives ---------------------------------------------------------

_BOX = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)
_RIM = np.column_stack(
    [np.cos(2 * np.pi * np.arange(32) / 32), np.sin(2 * np.pi * np.arange(32) / 32)]
)


_BODY: dict = {}  # body-frame outline points by shape (sizes do not change during a run)


def _body_points(prim: Box | Cylinder) -> np.ndarray:
    """Body-frame points whose projections' convex hull is a box's or cylinder's silhouette."""
    key = ("box", *prim.size) if isinstance(prim, Box) else ("cyl", prim.radius, prim.length)
    body = _BODY.get(key)
    if body is None:
        if isinstance(prim, Box):
            body = _BOX * (0.5 * np.asarray(prim.size, float))
        else:
            ring = prim.radius * _RIM
            body = np.vstack(
                [
                    np.column_stack([ring, np.full(len(ring), s * 0.5 * prim.length)])
                    for s in (-1.0, 1.0)
                ]
            )
        if len(_BODY) < 1024:
            _BODY[key] = body
    return body


def project_hull(camera: PinholeCamera, body: np.ndarray, orientation, position):
    """(convex hull (N, 2) in pixels, its box (umin, vmin, umax, vmax)) of body-frame points
    (n, 3) of a rigid body at ``position`` with quaternion ``orientation``, or None if a point
    is not in front of the camera (depth <= 1 um): the points projected with NumPy (world =
    body R^T + p, then (world - o) R), rounded to float32 as ``cv2.convexHull`` of float32
    points took them, and Andrew's monotone chain (counter-clockwise in image axes, no
    collinear vertices). The optional accelerator (``_pixels.project_hull``) computes the
    products as NumPy's matmul does (fused multiply-adds in ascending order: the same pixels
    to the bit, test_fast_cameras.py). ValueError for a pose whose projection is not finite."""
    k = camera.intrinsics
    if _pixels is not None:
        hull = np.empty((len(body), 2))
        found = _pixels.project_hull(
            body,
            orientation,
            position,
            np.ascontiguousarray(camera.rotation, dtype=np.float64),
            np.ascontiguousarray(camera.position, dtype=np.float64),
            k.fx,
            k.fy,
            k.cx,
            k.cy,
            hull,
        )
        if found is None:
            return None
        return hull[: found[0]], found[1:]
    if not any(orientation):
        raise ValueError("zero quaternion")
    world = np.asarray(body, dtype=float) @ quaternion_matrix(orientation).T + np.asarray(
        position, dtype=float
    )
    pc = (world - camera.position) @ camera.rotation
    z = pc[:, 2]
    if not (z > _NEAR).all():
        return None
    uv = np.empty((len(pc), 2), np.float32)
    uv[:, 0] = k.fx * pc[:, 0] / z + k.cx
    uv[:, 1] = k.fy * pc[:, 1] / z + k.cy
    if not np.isfinite(uv).all():
        raise ValueError(
            "project_hull: a body point projects to a pixel that is not finite (a non-finite "
            "or huge pose)"
        )
    pts = sorted(map(tuple, uv.astype(np.float64).tolist()))

    def cross(o, a, b) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    chain: list = []
    for p in pts:
        while len(chain) >= 2 and cross(chain[-2], chain[-1], p) <= 0.0:
            chain.pop()
        chain.append(p)
    lower = len(chain) + 1
    for p in reversed(pts[:-1]):
        while len(chain) >= lower and cross(chain[-2], chain[-1], p) <= 0.0:
            chain.pop()
        chain.append(p)
    if len(chain) > 1:
        chain.pop()  # the first point is repeated at the end
    hull = np.array(chain, dtype=np.float64).reshape(-1, 2)
    return hull, (*hull.min(axis=0).tolist(), *hull.max(axis=0).tolist())


def silhouette(
    camera: PinholeCamera, prim
) -> tuple[float, np.ndarray | Ellipse, tuple | None] | None:
    """(distance (m) from the optical centre to the primitive's centre, convex polygon (N, 2) in
    pixels, its box (umin, vmin, umax, vmax) or None for an ellipse) of a primitive, or None if
    it reaches behind the camera. Spheres give their ellipse."""
    distance = math.dist(prim.position, camera.position.tolist())
    if isinstance(prim, Sphere):
        e = sphere_ellipse(camera, prim.position, prim.radius)
        if e is None:
            return None
        return distance, e, None
    if isinstance(prim, (Box, Cylinder)):
        found = project_hull(camera, _body_points(prim), prim.orientation, prim.position)
        if found is None:
            return None
        return distance, found[0], found[1]
    raise TypeError(f"cannot render {type(prim).__name__}")


# --- raster --------------------------------------------------------------------------------


def sphere_polygon(camera: PinholeCamera, centre, radius: float):
    """(polygon (N, 2), box) of a sphere's silhouette, or None if it reaches behind the camera:
    :func:`sphere_ellipse` and :meth:`Ellipse.polygon_and_box`."""
    e = _sphere_ellipse_fields(camera, centre, radius)
    return None if e is None else _ellipse_polygon(*e[:5])


def drawables(camera: PinholeCamera, scene: Scene) -> list[tuple[np.ndarray, float, tuple]]:
    """(convex polygon in pixels, grey level, its box (umin, vmin, umax, vmax)) of each
    primitive drawn by ``camera``, far first (spheres by :func:`sphere_polygon`)."""
    items = []
    eye = None
    for i, prim in enumerate(scene.primitives):
        if isinstance(prim, Sphere):
            found = sphere_polygon(camera, prim.position, prim.radius)
            if found is not None:
                eye = camera.position.tolist() if eye is None else eye
                items.append((-math.dist(prim.position, eye), i, prim, found[0], found[1]))
            continue
        s = silhouette(camera, prim)
        if s is not None:
            items.append((-s[0], i, prim, s[1], s[2]))
    items.sort(key=lambda it: (it[0], it[1]))  # far first
    out = []
    for _, _, prim, shape, box in items:
        if isinstance(shape, Ellipse):
            poly, box = shape.polygon_and_box()
        elif len(shape) >= 3 and box is not None:
            poly = shape
        else:
            continue
        out.append((poly, 255.0 * float(prim.albedo), tuple(box)))
    return out


def render_views(cameras, scene: Scene, *, background: float = 0.1) -> list[np.ndarray]:
    """:func:`render` for several cameras."""
    return [render(camera, scene, background=background) for camera in cameras]


def render(
    camera: PinholeCamera, scene: Scene, *, background: float = 0.1, window=None
) -> np.ndarray:
    """A noiseless float32 grey image (0..255) of the scene's silhouettes, each at grey level
    ``255 * albedo``, on a uniform background of albedo ``background``; with ``window = (x0,
    y0, x1, y1)`` only that part of the image (pixel (x0, y0) is pixel (0, 0) of the result)."""
    k = camera.intrinsics
    x0, y0, x1, y1 = window if window is not None else (0, 0, k.width, k.height)
    img = np.full((y1 - y0, x1 - x0), 255.0 * background, np.float32)
    drawn = drawables(camera, scene)
    composite(img, [d[0] for d in drawn], [d[1] for d in drawn], origin=(x0, y0))
    return img
