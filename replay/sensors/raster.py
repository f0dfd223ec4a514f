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


def coverage(polygons, x0: int, y0: int, w: int, h: int) -> np.ndarray:
    """Exact covered area (0..1) of each polygon ((N, 2) vertices in pixels, either orientation)
    in each pixel of the ``h x w`` block whose first pixel is ``(x0, y0)``: shape (n, h, w)."""
    out = np.zeros((len(polygons), h, w))
    for i, q in enumerate(polygons):
        if len(q) >= 3 and w > 0 and h > 0:
            _pixels.coverage(np.ascontiguousarray(q, dtype=np.float64), x0, y0, out[i], w, h)
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
    _pixels.composite(polys, [float(g) for g in greys], int(origin[0]), int(origin[1]), img, w, h)


def quantise(img: np.ndarray) -> np.ndarray:
    """An 8-bit image of a float32 one: ``clip(rint(img), 0, 255)``."""
    out = np.empty(img.shape, np.uint8)
    _pixels.quantise(np.ascontiguousarray(img, dtype=np.float32), out)
    return out
