"""Compiled per-pixel kernels of the cameras (Numba): exact-coverage compositing and blob moments.

The algorithms are those the NumPy code used (and the tests keep as references); compiling them
removes the per-call overhead of dozens of small NumPy/OpenCV calls a frame, which was nearly
all of a camera's cost (a 512 px stick frame: ~1.9 ms; a stereo pair: ~0.9 ms; a 16 x 16 chip
frame: ~0.5 ms). Kernels are compiled on first use and cached beside this file
(``__pycache__``), so only the first process after a change pays the compilation.

Conventions (:mod:`replay.sensors.pinhole`'s): integer pixel coordinates are pixel centres, pixel
``(i, j)`` spans ``[i - 0.5, i + 0.5] x [j - 0.5, j + 0.5]``.
"""

from __future__ import annotations

import math

import numba
import numpy as np

_jit = numba.njit(cache=True, nogil=True)


@_jit
def _accumulate(P, start, end, ox, oy, acc, w, h):
    """Signed-area accumulation of polygon ``P[start:end]`` (pixels of the full image) into
    ``acc`` (h, w + 1) of the block whose first pixel is ``(ox, oy)``: the exact coverage of
    each pixel is then the running sum of ``acc`` along its row (replay/sensors/raster.py).

    Each edge is cut where it crosses a pixel boundary, so every piece lies in one pixel; a
    piece rising ``dy`` at mean distance ``f`` from its pixel's left side adds ``dy (1 - f)`` to
    that pixel and ``dy f`` to the next one in its row. Pieces left of the block count at its
    left edge, pieces right of it or outside its rows are dropped. Returns the rows (r0, r1)
    and the columns (c0, c1) outside which the polygon covers nothing in the block."""
    n = end - start
    bx, by = ox - 0.5, oy - 0.5  # block coordinates: pixel (c, r) spans [c, c+1] x [r, r+1]
    area2 = 0.0
    xmin, xmax = np.inf, -np.inf
    for i in range(n):
        xmin, xmax = min(xmin, P[start + i, 0] - bx), max(xmax, P[start + i, 0] - bx)
        j = i + 1 if i + 1 < n else 0
        area2 += (P[start + i, 0] - bx) * (P[start + j, 1] - by) - (P[start + j, 0] - bx) * (
            P[start + i, 1] - by
        )
    sign = -1.0 if area2 >= 0.0 else 1.0
    r_lo, r_hi = h, 0
    for i in range(n):
        j = i + 1 if i + 1 < n else 0
        xa, ya = P[start + i, 0] - bx, P[start + i, 1] - by
        xb, yb = P[start + j, 0] - bx, P[start + j, 1] - by
        if ya == yb:
            continue
        ylo, yhi = min(ya, yb), max(ya, yb)
        if yhi <= 0.0 or ylo >= h:
            continue
        ra = max(int(math.floor(ylo)), 0)
        rb = min(int(math.ceil(yhi)), h)
        r_lo, r_hi = min(r_lo, ra), max(r_hi, rb)
        k = (xb - xa) / (yb - ya)
        up = yb > ya
        for r in range(ra, rb):
            # the edge's part in row band [r, r + 1], in the edge's direction
            if up:
                ys, ye = max(ya, float(r)), min(yb, r + 1.0)
            else:
                ys, ye = min(ya, r + 1.0), max(yb, float(r))
            if ys == ye:
                continue
            xs = xa if ys == ya else xa + (ys - ya) * k
            xe = xb if ye == yb else xa + (ye - ya) * k
            # cut at integer x, walking from xs to xe; the parts beyond the block's right side
            # change nothing in it, the parts left of it all count at its left edge
            xp, yp = xs, ys
            if xe > xs:
                c = max(int(math.floor(xs)) + 1, 0)
                step = 1
            elif xe < xs:
                c = min(int(math.ceil(xs)) - 1, w)
                step = -1
            else:
                c, step = 0, 0
            while True:
                if step == 1 and c < xe and c <= w:
                    xq = float(c)
                elif step == -1 and c > xe and c >= 0:
                    xq = float(c)
                else:
                    xq = xe
                yq = ye if xq == xe else ys + (xq - xs) * (ye - ys) / (xe - xs)
                dy = (yq - yp) * sign
                xm = 0.5 * (xp + xq)
                col = math.floor(xm)
                if col < 0.0:
                    acc[r, 0] += dy
                elif col < w:
                    ci = int(col)
                    f = xm - col
                    acc[r, ci] += dy * (1.0 - f)
                    acc[r, ci + 1] += dy * f
                if xq == xe:
                    break
                if step == 1 and xq >= w:
                    break  # the rest lies right of the block
                if step == -1 and xq <= 0.0:
                    acc[r, 0] += (ye - yq) * sign  # the rest lies left of it
                    break
                xp, yp = xq, yq
                c += step
    c0 = min(max(int(math.floor(xmin)) - 1, 0), w)
    return r_lo, r_hi, c0, max(min(int(math.ceil(xmax)) + 1, w), c0)


@_jit
def coverage_into(P, start, end, ox, oy, out):
    """Exact covered area (0..1, to rounding) of polygon ``P[start:end]`` in each pixel of
    ``out`` (h, w), the block whose first pixel is ``(ox, oy)``."""
    h, w = out.shape
    acc = np.zeros((h, w + 1))
    _accumulate(P, start, end, ox, oy, acc, w, h)
    for r in range(h):
        s = 0.0
        for c in range(w):
            s += acc[r, c]
            out[r, c] = s


@_jit
def composite(P, starts, greys, ox, oy, img):
    """Alpha-composite polygons ``P[starts[i]:starts[i + 1]]`` (pixels of the full image) of
    grey levels ``greys`` onto the float32 image ``img`` (whose first pixel is ``(ox, oy)`` of
    the full image) in place, far first: ``img += alpha (grey - img)``, alpha each pixel's exact
    covered area clipped to [0, 1] (in float32, as NumPy's compositing did)."""
    h, w = img.shape
    acc = np.zeros((h, w + 1))
    for i in range(len(starts) - 1):
        if starts[i + 1] - starts[i] < 3:
            continue
        r0, r1, c0, c1 = _accumulate(P, starts[i], starts[i + 1], ox, oy, acc, w, h)
        grey = np.float32(greys[i])
        for r in range(r0, r1):
            s = 0.0
            for c in range(c0, c1):
                s += acc[r, c]
                acc[r, c] = 0.0
                if s > 0.0:
                    a = np.float32(min(s, 1.0))
                    img[r, c] += a * (grey - img[r, c])
            acc[r, c1] = 0.0  # the last column _accumulate writes
