"""A calibrated pinhole camera (no lens distortion), in OpenCV's conventions.

Camera frame: x right, y down, z forward (the optical axis). Pixel (u, v): u along the image x
axis, v along y, and integer coordinates are pixel *centres* (as ``cv2.moments`` and
``cv2.fillConvexPoly`` count them): the image covers ``-0.5 <= u < width - 0.5``.

Pose: ``rotation`` is camera-to-world (its columns are the camera's x, y, z axes in world
coordinates) and ``position`` is the optical centre in world coordinates, so that
``p_world = rotation @ p_cam + position``. Everything is SI (m, rad); pixels are pixels.

The model knows nothing of what it looks at: cameras of particular experiments build on it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.params import check_limit


@dataclass(frozen=True)
class Intrinsics:
    """Focal lengths and principal point in pixels, image size in pixels."""

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    @property
    def K(self) -> np.ndarray:
        """The 3x3 camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @classmethod
    def from_fov(
        cls, width: int, height: int, fov_x: float, fov_y: float | None = None
    ) -> Intrinsics:
        """Intrinsics from the full horizontal field of view ``fov_x`` (rad), edge to edge.

        ``fov_y`` defaults to square pixels (fy = fx). The principal point is the image centre.
        """
        if not 0.0 < fov_x < math.pi:
            raise ValueError(f"fov_x must be in (0, pi) rad, got {fov_x}")
        fx = (width / 2.0) / math.tan(fov_x / 2.0)
        if fov_y is None:
            fy = fx
        else:
            if not 0.0 < fov_y < math.pi:
                raise ValueError(f"fov_y must be in (0, pi) rad, got {fov_y}")
            fy = (height / 2.0) / math.tan(fov_y / 2.0)
        return cls(
            fx=fx,
            fy=fy,
            cx=(width - 1) / 2.0,
            cy=(height - 1) / 2.0,
            width=int(width),
            height=int(height),
        )


def look_at_rotation(eye, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Camera-to-world rotation of a camera at ``eye`` looking at ``target``.

    The image's "up" (-y of the camera) points as close to the world direction ``up`` as possible.
    """
    eye, target, up = (np.asarray(v, dtype=float) for v in (eye, target, up))
    z = target - eye
    n = np.linalg.norm(z)
    if n == 0.0:
        raise ValueError("look_at: eye and target coincide")
    z = z / n
    x = np.cross(-up, z)
    nx = np.linalg.norm(x)
    if nx < 1e-9 * max(float(np.linalg.norm(up)), 1e-300):
        raise ValueError("look_at: 'up' is parallel to the viewing direction; choose another 'up'")
    x = x / nx
    y = np.cross(z, x)
    return np.column_stack([x, y, z])


class PinholeCamera:
    """Projection and back-projection through an ideal pinhole.

    ``project`` maps world points to pixels; ``ray`` and ``backproject_to_plane`` go back.
    ``projection_matrix()`` is the 3x4 ``P = K [R | t]`` (world to pixels, homogeneous) that
    ``cv2.triangulatePoints`` expects.
    """

    def __init__(self, intrinsics: Intrinsics, rotation=None, position=(0.0, 0.0, 0.0)) -> None:
        # C-contiguous: the optional accelerator reads them as buffers
        R = np.eye(3) if rotation is None else np.ascontiguousarray(rotation, dtype=float)
        if (
            R.shape != (3, 3)
            or not np.allclose(R.T @ R, np.eye(3), atol=1e-9)
            or np.linalg.det(R) < 0.0
        ):
            raise ValueError("rotation must be a proper 3x3 rotation matrix (camera-to-world)")
        self.intrinsics = intrinsics
        self.rotation = R
        self.position = np.ascontiguousarray(position, dtype=float).reshape(3)

    # --- construction --------------------------------------------------------------------
    @classmethod
    def look_at(cls, intrinsics: Intrinsics, eye, target, up=(0.0, 0.0, 1.0)) -> PinholeCamera:
        """A camera at ``eye`` whose optical axis passes through ``target``."""
        return cls(intrinsics, look_at_rotation(eye, target, up), eye)

    @classmethod
    def from_fov(
        cls,
        width: int,
        height: int,
        fov_x: float,
        eye,
        target,
        up=(0.0, 0.0, 1.0),
        fov_y: float | None = None,
    ) -> PinholeCamera:
        """A look-at camera with intrinsics from the horizontal field of view (rad)."""
        return cls.look_at(Intrinsics.from_fov(width, height, fov_x, fov_y), eye, target, up)

    # --- frames ----------------------------------------------------------------------------
    def extrinsics(self) -> tuple[np.ndarray, np.ndarray]:
        """World-to-camera ``(R, t)``: ``p_cam = R @ p_world + t`` (OpenCV's rvec/tvec pair)."""
        R = self.rotation.T
        return R, -R @ self.position

    def to_camera(self, points_world) -> np.ndarray:
        """World points (N, 3) or (3,) in the camera frame."""
        p = np.asarray(points_world, dtype=float)
        return (p - self.position) @ self.rotation

    def projection_matrix(self) -> np.ndarray:
        """The 3x4 matrix ``K [R | t]`` mapping homogeneous world points to homogeneous pixels."""
        R, t = self.extrinsics()
        return self.intrinsics.K @ np.column_stack([R, t])

    # --- forward ---------------------------------------------------------------------------
    def project(self, points_world) -> np.ndarray:
        """Pixels (N, 2) (or (2,)) of world points; NaN for points not in front of the camera."""
        pc = self.to_camera(points_world)
        z = pc[..., 2]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = self.intrinsics.fx * pc[..., 0] / z + self.intrinsics.cx
            v = self.intrinsics.fy * pc[..., 1] / z + self.intrinsics.cy
        uv = np.stack([u, v], axis=-1)
        uv[z <= 0.0] = np.nan
        return uv

    # --- backward --------------------------------------------------------------------------
    def ray(self, pixels) -> tuple[np.ndarray, np.ndarray]:
        """The viewing ray(s) of pixel(s): ``(origin (3,), unit directions (N, 3) or (3,))``."""
        uv = np.asarray(pixels, dtype=float)
        k = self.intrinsics
        d_cam = np.stack(
            [(uv[..., 0] - k.cx) / k.fx, (uv[..., 1] - k.cy) / k.fy, np.ones(uv.shape[:-1])],
            axis=-1,
        )
        d = d_cam @ self.rotation.T
        d = d / np.linalg.norm(d, axis=-1, keepdims=True)
        return self.position.copy(), d

    def backproject_to_plane(
        self, pixels, point=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0)
    ) -> np.ndarray:
        """World points (N, 3) or (3,) where the pixels' rays meet the plane through ``point``
        with ``normal``; NaN where a ray is parallel to the plane or meets it behind the camera."""
        o, d = self.ray(pixels)
        n = np.asarray(normal, dtype=float)
        q = np.asarray(point, dtype=float)
        denom = d @ n
        with np.errstate(divide="ignore", invalid="ignore"):
            s = ((q - o) @ n) / denom
        s = np.where((np.abs(denom) > 1e-12) & (s > 0.0), s, np.nan)
        return o + s[..., None] * d

    def backproject_to_height(self, pixels, z: float = 0.0) -> np.ndarray:
        """World points where the pixels' rays meet the horizontal plane at height ``z`` (m)."""
        return self.backproject_to_plane(pixels, point=(0.0, 0.0, z), normal=(0.0, 0.0, 1.0))


def check_image_size(width: int, height: int) -> None:
    """A camera's ``Params.__post_init__``: its image under the ``camera_pixels`` limit (a
    ParamError at ``width``, checked before any frame is allocated; docs/security.md)."""
    check_limit("camera_pixels", width * height, "width", f"a {width} x {height} image")
