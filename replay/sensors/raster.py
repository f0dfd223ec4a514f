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
per-pixel coverage (kept as the reference in tests/replay/sensors/test_raster.py) does.
"""

from __future__ import annotations

import numpy as np


def _cut(a: np.ndarray, b: np.ndarray, limit):
    """Cut segments running from coordinate ``a`` to ``b`` at every integer in [0, limit] they
    cross (``limit`` one number or one per segment): (segment index, s0, s1) of the pieces, s
    the parameter along the segment (0 at a, 1 at b), in order along each segment (no sort:
    crossings are generated in the direction the segment runs). Written for few NumPy calls:
    the arrays are short."""
    d = b - a
    first = np.minimum(np.maximum(np.ceil(np.minimum(a, b)), 0.0), limit)
    last = np.minimum(np.maximum(np.floor(np.maximum(a, b)), 0.0), limit)
    n = (np.maximum(last - first + 1.0, 0.0) * (d != 0.0)).astype(np.int64) + 2
    seg = np.arange(len(a)).repeat(n)
    j = np.arange(seg.size) - (n.cumsum() - n).repeat(n)  # 0 .. n - 1 on each segment
    ds, ns = d[seg], n[seg]
    k = np.where(ds > 0.0, first[seg] + (j - 1), last[seg] - (j - 1))
    s = np.minimum(np.maximum((k - a[seg]) / np.where(ds != 0.0, ds, 1.0), 0.0), 1.0)
    s[j == 0] = 0.0
    s[j == ns - 1] = 1.0
    inner = np.flatnonzero(j < ns - 1)  # piece from s[i] to s[i + 1]
    return seg[inner], s[inner], s[inner + 1]


def coverage_blocks(polygons, blocks) -> list[np.ndarray]:
    """Exact covered area (0..1) of each polygon ((N, 2) vertices in pixels, either orientation)
    in each pixel of its own block ``(x0, y0, w, h)`` (the ``h x w`` pixels whose first is
    ``(x0, y0)``): a list of (h, w) arrays. All polygons' edges are cut and accumulated together,
    so the cost (a few dozen NumPy calls on short arrays) is shared by every polygon and block,
    e.g. the same ball seen by two cameras."""
    out = [np.zeros((int(b[3]), int(b[2]))) for b in blocks]
    todo = [
        i for i, q in enumerate(polygons) if len(q) >= 3 and blocks[i][2] > 0 and blocks[i][3] > 0
    ]
    if not todo:
        return out
    # window coordinates: pixel (c, r) of a block spans [c, c + 1] x [r, r + 1]
    Ps, Qs, sizes = [], [], []
    for i in todo:
        x0, y0 = blocks[i][0], blocks[i][1]
        P = np.asarray(polygons[i], dtype=float) - (x0 - 0.5, y0 - 0.5)
        Ps.append(P)
        Qs.append(np.concatenate((P[1:], P[:1])))
        sizes.append(len(P))
    P, Q = np.concatenate(Ps), np.concatenate(Qs)
    size = np.array(sizes, dtype=np.int64)
    ws = np.array([blocks[i][2] for i in todo], dtype=np.int64)
    hs = np.array([blocks[i][3] for i in todo], dtype=np.int64)
    strides = ws + 1
    offsets = np.concatenate(([0], (hs * strides).cumsum()))
    cross = P[:, 0] * Q[:, 1] - Q[:, 0] * P[:, 1]  # twice each polygon's signed area
    signs = np.where(np.add.reduceat(cross, size.cumsum() - size) >= 0.0, -1.0, 1.0)
    owner = np.arange(len(todo)).repeat(size)  # edge -> polygon (in ``todo``)
    # edges cut into pieces within one pixel row, then within one pixel
    e, s0, s1 = _cut(P[:, 1], Q[:, 1], hs[owner])
    Pe, de = P[e], Q[e] - P[e]
    ya = Pe[:, 1] + s0 * de[:, 1]
    yb = Pe[:, 1] + s1 * de[:, 1]
    xa = Pe[:, 0] + s0 * de[:, 0]
    xb = Pe[:, 0] + s1 * de[:, 0]
    row = np.floor(0.5 * (ya + yb))
    oe = owner[e]
    keep = np.flatnonzero((ya != yb) & (row >= 0) & (row < hs[oe]))
    oe, row, xa, xb, ya, yb = oe[keep], row[keep], xa[keep], xb[keep], ya[keep], yb[keep]
    r, u0, u1 = _cut(xa, xb, ws[oe])
    o = oe[r]
    xm = xa[r] + 0.5 * (u0 + u1) * (xb[r] - xa[r])
    dy = (u1 - u0) * (yb[r] - ya[r]) * signs[o]
    col = np.floor(xm)
    keep = np.flatnonzero(col < ws[o])  # right of the block: no effect in it
    o, r, xm, dy, col = o[keep], r[keep], xm[keep], dy[keep], col[keep]
    left = col < 0  # left of the block: at its left edge
    f = xm - col
    f[left] = 0.0
    col[left] = 0.0
    cell = (offsets[o] + row[r] * strides[o] + col).astype(np.int64)
    total = int(offsets[-1])
    acc = np.bincount(cell, weights=dy * (1.0 - f), minlength=total + 1)
    acc[1:] += np.bincount(cell + 1, weights=dy * f, minlength=total + 1)[1:]
    for k, i in enumerate(todo):
        h, w, st = int(hs[k]), int(ws[k]), int(strides[k])
        out[i] = acc[offsets[k] : offsets[k] + h * st].reshape(h, st).cumsum(axis=1)[:, :w]
    return out


def coverage(polygons, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """Exact covered area (0..1) of each polygon in each pixel of the ``h x w`` block whose first
    pixel is ``(x0, y0)``: shape (n, h, w) (:func:`coverage_blocks` with one block)."""
    if not len(polygons):
        return np.zeros((0, h, w))
    return np.stack(coverage_blocks(polygons, [(x0, y0, w, h)] * len(polygons)))


def composite(img: np.ndarray, polygons, greys, origin=(0, 0)) -> None:
    """Alpha-composite polygons (pixels of the full image) of grey levels ``greys`` onto a float
    image in place, in the order given (far first), each pixel weighted by the area covered.
    ``img`` may be a window of the full image whose first pixel is ``origin``."""
    if not len(polygons):
        return
    h, w = img.shape
    for cov, grey in zip(coverage(polygons, origin[0], origin[1], w, h), greys):
        paint(img, cov, grey)


def paint(img: np.ndarray, cov: np.ndarray, grey: float) -> None:
    """``img += alpha (grey - img)`` in place, alpha the coverage clipped to [0, 1] (float32)."""
    alpha = np.minimum(np.maximum(cov, 0.0), 1.0).astype(np.float32)
    img += alpha * (np.float32(grey) - img)
