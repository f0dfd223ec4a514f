"""Image features of a binary target (Namiki et al. 1999, Sec. 4.1.1), pure NumPy: its moments
give the centre xi and rotation phi; its extents and fill the object's size and shape.

- ``xi = (m10 / m00, m01 / m00)`` (pixels; u right, v down, integer coordinates = pixel centres);
- ``phi = atan2(2 mu11, mu20 - mu02) / 2``, the angle of the principal axis from the u axis
  towards +v (defined modulo pi; meaningless for an isotropic blob: see ``elongation``);
- ``elongation = sqrt(lambda_1 / lambda_2)`` of the second-moment matrix;
- ``fill`` = pixels / area of the smallest bounding box over orientations (5 deg steps, pixel
  squares counted whole): a rectangle fills its box (~1), a disc pi/4 of it (~0.79); at
  16 x 16 a rolled rectangle's jagged outline fills only ~0.75, so the shape decision
  (``recognition.shape_of``) uses the elongation as well.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

_ANGLES = np.radians(np.arange(0.0, 90.0, 5.0))
_DIRS = np.stack([np.cos(_ANGLES), np.sin(_ANGLES)])  # (2, n)
_NORMALS = np.stack([-np.sin(_ANGLES), np.cos(_ANGLES)])
# a unit pixel square's extent along direction (c, s): |c| + |s|
_PIXEL_EXTENT = np.abs(_DIRS).sum(axis=0)


@dataclass(frozen=True)
class Blob:
    area: int
    u: float
    v: float
    phi: float  # rad, principal axis from +u towards +v
    elongation: float  # sqrt(lambda_max / lambda_min) (>= 1)
    length: float  # px, extent along the principal axis (pixel squares)
    width: float  # px, extent across it
    fill: float  # area / smallest bounding box area
    touches_border: bool


def blob(target: np.ndarray, fill: bool = True) -> Blob | None:
    """The features of a binary target image, or None if it is empty (``fill=False``: skip the
    bounding-box search, ``fill`` is then NaN)."""
    vs, us = np.nonzero(target)
    n = len(us)
    if n == 0:
        return None
    # means as sum / n: the reduction and the division np.mean does, without its bookkeeping
    u0, v0 = us.sum() / n, vs.sum() / n
    du, dv = us - u0, vs - v0
    mu20, mu02, mu11 = (du * du).sum() / n, (dv * dv).sum() / n, (du * dv).sum() / n
    phi = 0.5 * math.atan2(2.0 * mu11, mu20 - mu02)
    mean, rad = 0.5 * (mu20 + mu02), math.hypot(0.5 * (mu20 - mu02), mu11)
    lam1, lam2 = mean + rad + 1.0 / 12.0, mean - rad + 1.0 / 12.0  # + a pixel square's own
    c, s = math.cos(phi), math.sin(phi)
    along, across = du * c + dv * s, -du * s + dv * c
    ext = abs(c) + abs(s)
    length = float(along.max() - along.min() + ext)
    width = float(across.max() - across.min() + ext)
    fill_ratio = math.nan
    if fill:
        pts = np.stack([du, dv], axis=1)
        pa, pn = pts @ _DIRS, pts @ _NORMALS  # (n, angles)
        boxes = (pa.max(0) - pa.min(0) + _PIXEL_EXTENT) * (pn.max(0) - pn.min(0) + _PIXEL_EXTENT)
        fill_ratio = float(n / boxes.min())
    h, w = target.shape
    border = bool(us.min() == 0 or vs.min() == 0 or us.max() == w - 1 or vs.max() == h - 1)
    return Blob(
        area=n,
        u=float(u0),
        v=float(v0),
        phi=phi,
        elongation=math.sqrt(lam1 / max(lam2, 1e-12)),
        length=length,
        width=width,
        fill=fill_ratio,
        touches_border=border,
    )
