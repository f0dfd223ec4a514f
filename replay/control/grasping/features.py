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

:func:`blob_rows` gives the same features from the chip's packed rows (bit u of ``rows[v]`` =
pixel (u, v)) in one pass over the rows: each row's pixel count, sum of u and of u^2 from a
table, so the moments are exact integer sums; the extremes of a linear function over a row's
pixels are at its first and last pixel, so the extents and bounding boxes need only those two.
:func:`blob` (arrays) is its reference (a test holds them equal); the recognition task runs
:func:`blob_rows`.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from replay.messages import unpack_rows

_ANGLES = np.radians(np.arange(0.0, 90.0, 5.0))
_DIRS = np.stack([np.cos(_ANGLES), np.sin(_ANGLES)])  # (2, n)
_NORMALS = np.stack([-np.sin(_ANGLES), np.cos(_ANGLES)])
# a unit pixel square's extent along direction (c, s): |c| + |s|
_PIXEL_EXTENT = np.abs(_DIRS).sum(axis=0)


class Blob(NamedTuple):
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


_ROW_TABLE_MAX = 16  # px: the widest row the per-row tables cover (2^16 entries)
_ROW_TABLES: dict[int, tuple[list[int], list[int], list[int]]] = {}
_DIR_PAIRS = list(zip(_DIRS[0].tolist(), _DIRS[1].tolist(), _PIXEL_EXTENT.tolist()))


def _row_tables(width: int) -> tuple[list[int], list[int], list[int]]:
    """Per row value: (pixels, sum of u, sum of u^2)."""
    t = _ROW_TABLES.get(width)
    if t is None:
        u = np.arange(width, dtype=np.int64)
        bits = (np.arange(1 << width, dtype=np.int64)[:, None] >> u) & 1
        t = _ROW_TABLES[width] = (
            bits.sum(axis=1).tolist(),
            (bits @ u).tolist(),
            (bits @ (u * u)).tolist(),
        )
    return t


def blob_rows(rows: list[int], width: int, fill: bool = True) -> Blob | None:
    """:func:`blob` of the binary image packed as rows (bit u of ``rows[v]`` = pixel (u, v))."""
    if width > _ROW_TABLE_MAX:
        return blob(unpack_rows(rows, width), fill)
    C, S, Q = _row_tables(width)
    n = su = sv = suu = svv = suv = 0
    ends = []  # (v, first u, last u) of each non-empty row
    ors = 0  # the rows ORed: which columns hold a pixel
    for v, r in enumerate(rows):
        if r:
            cnt, sm = C[r], S[r]
            n += cnt
            su += sm
            suu += Q[r]
            sv += v * cnt
            svv += v * v * cnt
            suv += v * sm
            ors |= r
            ends.append((v, (r & -r).bit_length() - 1, r.bit_length() - 1))
    if n == 0:
        return None
    u0, v0 = su / n, sv / n
    nn = n * n  # central moments from exact sums: sum (u - u0)^2 / n = (n Suu - Su^2) / n^2
    mu20, mu02, mu11 = (n * suu - su * su) / nn, (n * svv - sv * sv) / nn, (n * suv - su * sv) / nn
    phi = 0.5 * math.atan2(2.0 * mu11, mu20 - mu02)
    mean, rad = 0.5 * (mu20 + mu02), math.hypot(0.5 * (mu20 - mu02), mu11)
    lam1, lam2 = mean + rad + 1.0 / 12.0, mean - rad + 1.0 / 12.0  # + a pixel square's own
    c, s = math.cos(phi), math.sin(phi)
    pts = []  # (du, dv) of each row's first and last pixel: the extremes' candidates
    for v, lo, hi in ends:
        dv = v - v0
        pts.append((lo - u0, dv))
        if hi != lo:
            pts.append((hi - u0, dv))
    along = [du * c + dv * s for du, dv in pts]
    across = [-du * s + dv * c for du, dv in pts]
    ext = abs(c) + abs(s)
    fill_ratio = math.nan
    if fill:
        best = math.inf
        for dc, ds, e in _DIR_PAIRS:
            pa = [du * dc + dv * ds for du, dv in pts]
            pn = [du * -ds + dv * dc for du, dv in pts]
            box = (max(pa) - min(pa) + e) * (max(pn) - min(pn) + e)
            if box < best:
                best = box
        fill_ratio = n / best
    border = bool(
        ors & 1 or ors >> (width - 1) & 1 or ends[0][0] == 0 or ends[-1][0] == len(rows) - 1
    )
    return Blob(
        area=n,
        u=u0,
        v=v0,
        phi=phi,
        elongation=math.sqrt(lam1 / max(lam2, 1e-12)),
        length=max(along) - min(along) + ext,
        width=max(across) - min(across) + ext,
        fill=fill_ratio,
        touches_border=border,
    )
