"""Types of the stick camera's compiled frame (replay/sensors/_stick_frame.c documents it)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous buffer (a NumPy array of the dtype the kernel documents)

def measure(
    prims: Sequence[Any], shapes: dict, camera: tuple
) -> tuple[bytearray, tuple[int, int, int, int], tuple | None, tuple | None] | tuple | None: ...
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
