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

The accumulation runs compiled (``replay/sensors/_pixels.c``): it was a few dozen NumPy calls
on short arrays per frame, whose overhead, not their arithmetic, was the cost. It is exact:
equal to the reference to 1e-12 over random polygons and windows (test_raster.py).
"""

from __future__ import annotations

import numpy as np

from replay.sensors import _pixels


def _pack(polygons) -> tuple[np.ndarray, np.ndarray]:
    """Polygons as one (N, 2) float64 array of vertices and the start of each (n + 1,)."""
    sizes = [len(q) for q in polygons]
    starts = np.zeros(len(sizes) + 1, np.int64)
    starts[1:] = np.cumsum(sizes)
    if not sizes or starts[-1] == 0:
        return np.zeros((0, 2)), starts
    return np.ascontiguousarray(np.concatenate(polygons), dtype=np.float64), starts


def coverage(polygons, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """Exact covered area (0..1) of each polygon ((N, 2) vertices in pixels, either orientation)
    in each pixel of the ``h x w`` block whose first pixel is ``(x0, y0)``: shape (n, h, w)."""
    out = np.zeros((len(polygons), h, w))
    P, starts = _pack(polygons)
    for i in range(len(polygons)):
        if starts[i + 1] - starts[i] >= 3 and w > 0 and h > 0:
            _pixels.coverage(P[starts[i] : starts[i + 1]], x0, y0, out[i], w, h)
    return out


def composite(img: np.ndarray, polygons, greys, origin=(0, 0)) -> None:
    """Alpha-composite polygons (pixels of the full image) of grey levels ``greys`` onto a float32
    image in place, in the order given (far first), each pixel weighted by the area covered
    (``img += alpha (grey - img)``, alpha the coverage clipped to [0, 1], in float32).
    ``img`` may be a window of the full image whose first pixel is ``origin``."""
    if not len(polygons) or img.size == 0:
        return
    P, starts = _pack(polygons)
    h, w = img.shape
    g = np.asarray(greys, np.float64)
    _pixels.composite(P, starts, g, int(origin[0]), int(origin[1]), img, w, h)
