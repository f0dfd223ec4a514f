"""Exact anti-aliased rasterising of polygons: each pixel gets the area the polygon covers in it.

Image conventions are :mod:`replay.sensors.pinhole`'s: integer pixel coordinates are pixel
centres, pixel ``(i, j)`` spans ``[i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]``.

Method: the signed-area accumulation of outline font rasterisers (libart, font-rs). Each edge is
cut where it crosses a pixel boundary, so every piece lies in one pixel; a piece rising ``dy``
at mean distance ``f`` from its pixel's left side adds ``dy (1 - f)`` to that pixel and ``dy f``
to the next one in its row, and the running sum along each row is then the covered area of each
pixel (the integral of the winding number over the pixel: exact, for any simple polygon, up to
rounding). Pieces left of the window count at its left edge, pieces right of it or outside its
rows are dropped, so a window of a large polygon is cut exactly. The cost grows with the
polygon's perimeter in pixels, not with its area times its number of edges as the closed-form
per-pixel coverage (kept as the reference in tests/test_raster.py) does.
"""

from __future__ import annotations

import numpy as np


def _cut(a: np.ndarray, b: np.ndarray, limit: int):
    """Cut segments running from coordinate ``a`` to ``b`` at every integer in [0, limit] they
    cross: (segment index, s0, s1) of the pieces, s the parameter along the segment (0 at a,
    1 at b), in order along each segment (no sort: crossings are generated in the direction
    the segment runs). Written for few NumPy calls: the arrays are short."""
    d = b - a
    first = np.minimum(np.maximum(np.ceil(np.minimum(a, b)), 0.0), limit)
    last = np.minimum(np.maximum(np.floor(np.maximum(a, b)), 0.0), limit)
    n = (np.maximum(last - first + 1.0, 0.0) * (d != 0.0)).astype(np.int64) + 2
    seg = np.arange(len(a)).repeat(n)
    j = np.arange(seg.size) - (n.cumsum() - n).repeat(n)          # 0 .. n - 1 on each segment
    ds, ns = d[seg], n[seg]
    k = np.where(ds > 0.0, first[seg] + (j - 1), last[seg] - (j - 1))
    s = np.minimum(np.maximum((k - a[seg]) / np.where(ds != 0.0, ds, 1.0), 0.0), 1.0)
    s[j == 0] = 0.0
    s[j == ns - 1] = 1.0
    inner = np.flatnonzero(j < ns - 1)                              # piece from s[i] to s[i + 1]
    return seg[inner], s[inner], s[inner + 1]


def coverage(polygons, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """Exact covered area (0..1) of each polygon ((N, 2) vertices in pixels, either orientation)
    in each pixel of the ``h x w`` block whose first pixel is ``(x0, y0)``: shape (n, h, w).
    All polygons' edges are cut and accumulated together (a few NumPy calls per block)."""
    n = len(polygons)
    stride = w + 1
    polys = [(i, np.asarray(q, dtype=float)) for i, q in enumerate(polygons) if len(q) >= 3]
    if not polys:
        return np.zeros((n, h, w))
    # window coordinates: pixel (c, r) spans [c, c + 1] x [r, r + 1]
    origin = np.array([x0 - 0.5, y0 - 0.5])
    if len(polys) == 1:
        owner_id, P = polys[0]
        P = P - origin
        Q = np.concatenate((P[1:], P[:1]))
        cross = P[:, 0] * Q[:, 1] - Q[:, 0] * P[:, 1]  # twice the polygon's signed area
        sign: float | np.ndarray = -1.0 if cross.sum() >= 0.0 else 1.0   # either orientation
        owner = None                                   # covers positively
    else:
        P = np.concatenate([q for _, q in polys]) - origin
        Q = np.concatenate([np.concatenate((q[1:], q[:1])) for _, q in polys]) - origin
        sizes = np.array([len(q) for _, q in polys], dtype=np.int64)
        cross = P[:, 0] * Q[:, 1] - Q[:, 0] * P[:, 1]
        signs = np.where(np.add.reduceat(cross, sizes.cumsum() - sizes) >= 0.0, -1.0, 1.0)
        owner = np.array([i for i, _ in polys]).repeat(sizes)
        sign = signs.repeat(sizes)
    # edges cut into pieces within one pixel row, then within one pixel
    e, s0, s1 = _cut(P[:, 1], Q[:, 1], h)
    Pe, de = P[e], Q[e] - P[e]
    ya = Pe[:, 1] + s0 * de[:, 1]
    yb = Pe[:, 1] + s1 * de[:, 1]
    xa = Pe[:, 0] + s0 * de[:, 0]
    xb = Pe[:, 0] + s1 * de[:, 0]
    row = np.floor(0.5 * (ya + yb))
    keep = np.flatnonzero((ya != yb) & (row >= 0) & (row < h))
    e, row, xa, xb, ya, yb = e[keep], row[keep], xa[keep], xb[keep], ya[keep], yb[keep]
    r, u0, u1 = _cut(xa, xb, w)
    xm = xa[r] + 0.5 * (u0 + u1) * (xb[r] - xa[r])
    dy = (u1 - u0) * (yb[r] - ya[r])
    dy = dy * (sign if isinstance(sign, float) else sign[e[r]])
    col = np.floor(xm)
    keep = np.flatnonzero(col < w)                     # right of the window: no effect in it
    r, xm, dy, col = r[keep], xm[keep], dy[keep], col[keep]
    left = col < 0                                     # left of the window: at its left edge
    f = xm - col
    f[left] = 0.0
    col[left] = 0.0
    base = row[r] if owner is None else owner[e[r]] * h + row[r]
    cell = (base * stride + col).astype(np.int64)
    size = n * h * stride
    acc = np.bincount(cell, weights=dy * (1.0 - f), minlength=size + 1)
    acc[1:] += np.bincount(cell + 1, weights=dy * f, minlength=size + 1)[1:]
    if owner is None and n > 1:                        # one drawable polygon among several
        out = np.zeros((n, h, w))
        out[owner_id] = acc[:size // n].reshape(h, stride).cumsum(axis=1)[:, :w]
        return out
    return acc[:size].reshape(n, h, stride).cumsum(axis=2)[:, :, :w]


def composite(img: np.ndarray, polygons, greys, origin=(0, 0)) -> None:
    """Alpha-composite polygons (pixels of the full image) of grey levels ``greys`` onto a float
    image in place, in the order given (far first), each pixel weighted by the area covered.
    ``img`` may be a window of the full image whose first pixel is ``origin``."""
    if not len(polygons):
        return
    h, w = img.shape
    cov = coverage(polygons, origin[0], origin[1], w, h)
    alpha = np.minimum(np.maximum(cov, 0.0), 1.0).astype(np.float32)
    for a, grey in zip(alpha, greys):
        img += a * (np.float32(grey) - img)
