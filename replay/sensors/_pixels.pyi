"""Types of the cameras' compiled kernels (replay/sensors/_pixels.c documents each)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous buffer (a NumPy array of the dtype the kernel documents)

def coverage(xy: Buffer, ox: int, oy: int, out: Buffer, w: int, h: int) -> None: ...
def composite(
    polygons: Sequence[Buffer],
    greys: Sequence[float],
    ox: int,
    oy: int,
    img: Buffer,
    w: int,
    h: int,
) -> None: ...
def quantise(img: Buffer, out: Buffer) -> None: ...
def project_hull(
    body: Buffer,
    q: Sequence[float],
    p: Sequence[float],
    R: Buffer,
    o: Buffer,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    out: Buffer,
) -> tuple[int, float, float, float, float] | None: ...
def pack_rows(bits: Buffer, w: int, h: int) -> tuple[list[int], int]: ...
def ellipse_polygon(
    cos: Buffer,
    sin: Buffer,
    u: float,
    v: float,
    a: float,
    b: float,
    c: float,
    s: float,
    out: Buffer,
) -> tuple[float, float, float, float]: ...
def triangulate(
    P0: Buffer, P1: Buffer, u0: float, v0: float, u1: float, v1: float
) -> tuple[float, float, float] | None: ...
def marker_moments(
    img: Buffer,
    w: int,
    h: int,
    threshold: float,
    min_pixels: int,
    ox: int,
    oy: int,
    full_w: int,
    full_h: int,
) -> tuple[float, float, float, int, float, float, float, float, float, float, float] | None: ...
def ball_blob(
    img: Buffer,
    w: int,
    h: int,
    threshold: float,
    min_pixels: int,
    binary: int,
    default_background: float,
    ox: int,
    oy: int,
    full_w: int,
    full_h: int,
) -> tuple[float, float, int, float] | None: ...
