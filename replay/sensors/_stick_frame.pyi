"""Types of the stick camera's compiled frame (replay/sensors/_stick_frame.c documents it)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous buffer (a NumPy array of the dtype the kernel documents)

def frame(
    prims: Sequence[tuple[Buffer, Sequence[float], Sequence[float], float, float, float, Buffer]],
    marker: int,
    R: Buffer,
    o: Buffer,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    width: int,
    height: int,
    background: float,
    threshold: float,
    min_pixels: int,
) -> tuple[bytearray, tuple[int, int, int, int], tuple | None] | None: ...
def moments(
    img: Buffer,
    w: int,
    h: int,
    threshold: float,
    min_pixels: int,
    ox: int,
    oy: int,
    full_w: int,
    full_h: int,
) -> tuple | None: ...
