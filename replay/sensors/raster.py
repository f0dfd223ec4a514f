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

:func:`accumulate` is the algorithm in Python; the optional accelerator ``_pixels.c``
(``replay.accel``) runs the same operations compiled (a frame's few polygons cost ~1-3 ms in
Python, ~10 us compiled). A NaN, infinite or huge (> 1e9 px) vertex is refused with ValueError
on both paths (the cut loops would never end on one).
"""

from __future__ import annotations

import math

import numpy as np

from replay.accel import accelerator

_pixels = accelerator("replay.sensors._pixels")
COORD_MAX = 1e9  # px: the largest |coordinate| a vertex may have


def _check(xy: np.ndarray) -> None:
    bad = ~(np.abs(xy) <= COORD_MAX)  # NaN too
    if bad.any():
        i, j = (int(k) for k in np.argwhere(bad)[0])
        raise ValueError(
            f"polygon vertex {i}: {'xy'[j]} = {float(xy[i, j])!r} is not a finite pixel "
            "coordinate within +-1e9"
        )


def accumulate(xy: np.ndarray, ox: int, oy: int, acc: np.ndarray, w: int, h: int):
    """The signed-area accumulation of one polygon (n vertices, pixels of the full image) into
    ``acc`` (h rows of w + 1) of the block whose first pixel is (ox, oy); (r0, r1, c0, c1): the
    rows and columns outside which it covers nothing in the block. (``_pixels.c``'s
    ``accumulate``, operation for operation.)"""
    _check(xy)
    pts = (np.asarray(xy, dtype=np.float64) - (ox - 0.5, oy - 0.5)).tolist()
    n = len(pts)
    area2, xmin, xmax = 0.0, math.inf, -math.inf
    for i in range(n):
        xi, yi = pts[i]
        xj, yj = pts[i + 1 if i + 1 < n else 0]
        area2 += xi * yj - xj * yi
        if xi < xmin:
            xmin = xi
        if xi > xmax:
            xmax = xi
    sign = -1.0 if area2 >= 0.0 else 1.0
    floor, ceil = math.floor, math.ceil
    rlo, rhi = h, 0
    for i in range(n):
        xa, ya = pts[i]
        xb, yb = pts[i + 1 if i + 1 < n else 0]
        if ya == yb:
            continue
        ylo, yhi = (ya, yb) if ya < yb else (yb, ya)
        if yhi <= 0.0 or ylo >= h:
            continue
        ra, rb = max(int(floor(ylo)), 0), min(int(ceil(yhi)), h)
        rlo, rhi = min(rlo, ra), max(rhi, rb)
        k = (xb - xa) / (yb - ya)
        up = yb > ya
        for r in range(ra, rb):
            row = acc[r]
            if up:
                ys = ya if ya > r else float(r)
                ye = yb if yb < r + 1.0 else r + 1.0
            else:
                ys = ya if ya < r + 1.0 else r + 1.0
                ye = yb if yb > r else float(r)
            if ys == ye:
                continue
            xs = xa if ys == ya else xa + (ys - ya) * k
            xe = xb if ye == yb else xa + (ye - ya) * k
            # cut at integer x walking from xs to xe: parts right of the block change nothing
            # in it, parts left of it all count at its left edge
            if xe > xs:
                step, c = 1, max(int(floor(xs)) + 1, 0)
            elif xe < xs:
                step, c = -1, min(int(ceil(xs)) - 1, w)
            else:
                step, c = 0, 0
            xp, yp = xs, ys
            while True:
                if (step == 1 and c < xe and c <= w) or (step == -1 and c > xe and c >= 0):
                    xq = float(c)
                else:
                    xq = xe
                yq = ye if xq == xe else ys + (xq - xs) * (ye - ys) / (xe - xs)
                dy = (yq - yp) * sign
                xm = 0.5 * (xp + xq)
                col = floor(xm)
                if col < 0:
                    row[0] += dy
                elif col < w:
                    f = xm - col
                    row[col] += dy * (1.0 - f)
                    row[col + 1] += dy * f
                if xq == xe:
                    break
                if step == 1 and xq >= w:
                    break  # the rest lies right of the block
                if step == -1 and xq <= 0.0:  # the rest lies left of it
                    row[0] += (ye - yq) * sign
                    break
                xp, yp = xq, yq
                c += step
    cl = min(max(int(floor(xmin)) - 1, 0), w)
    ch = min(int(ceil(xmax)) + 1, w)
    return rlo, rhi, cl, max(ch, cl)


def coverage(polygons, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """Exact covered area (0..1) of each polygon ((N, 2) vertices in pixels, either orientation)
    in each pixel of the ``h x w`` block whose first pixel is ``(x0, y0)``: shape (n, h, w)."""
    out = np.zeros((len(polygons), h, w))
    for i, q in enumerate(polygons):
        if len(q) >= 3 and w > 0 and h > 0:
            xy = np.ascontiguousarray(q, dtype=np.float64)
            if _pixels is not None:
                _pixels.coverage(xy, x0, y0, out[i], w, h)
                continue
            acc = np.zeros((h, w + 1))
            accumulate(xy, x0, y0, acc, w, h)
            out[i] = np.cumsum(acc[:, :w], axis=1)
    return out


def composite(img: np.ndarray, polygons, greys, origin=(0, 0)) -> None:
    """Alpha-composite polygons (pixels of the full image) of grey levels ``greys`` onto a float32
    image in place, in the order given (far first), each pixel weighted by the area covered
    (``img += alpha (grey - img)``, alpha the coverage clipped to [0, 1], in float32).
    ``img`` may be a window of the full image whose first pixel is ``origin``."""
    if not len(polygons) or img.size == 0:
        return
    h, w = img.shape
    polys = [np.ascontiguousarray(q, dtype=np.float64) for q in polygons]
    ox, oy = int(origin[0]), int(origin[1])
    if _pixels is not None:
        _pixels.composite(polys, [float(g) for g in greys], ox, oy, img, w, h)
        return
    for xy, grey in zip(polys, greys):
        if len(xy) < 3:
            continue
        acc = np.zeros((h, w + 1))
        r0, r1, c0, c1 = accumulate(xy, ox, oy, acc, w, h)
        if r0 >= r1 or c0 >= c1:
            continue
        # the running sum along each row (in order, as the kernel adds), clipped to [0, 1]
        s = np.cumsum(acc[r0:r1, c0:c1], axis=1)
        alpha = np.where(s > 0.0, np.minimum(s, 1.0), 0.0).astype(np.float32)
        block = img[r0:r1, c0:c1]
        block += alpha * (np.float32(grey) - block)


def quantise(img: np.ndarray) -> np.ndarray:
    """An 8-bit image of a float32 one: ``clip(rint(img), 0, 255)`` (NaN: 0)."""
    src = np.ascontiguousarray(img, dtype=np.float32)
    if _pixels is not None:
        out = np.empty(img.shape, np.uint8)
        _pixels.quantise(src, out)
        return out
    return np.clip(np.rint(np.nan_to_num(src, nan=0.0)), 0, 255).astype(np.uint8)
