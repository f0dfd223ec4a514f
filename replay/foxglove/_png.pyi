"""Types of the PNG encoder's compiled kernel (replay/foxglove/_png.c documents it)."""

from typing import Any

Buffer = Any  # a C-contiguous uint8 (or bool) buffer

def png(
    pixels: Buffer, background: int, x0: int, y0: int, x1: int, y1: int, w: int, h: int, binary: int
) -> bytes: ...
def message(
    prefix: bytes,
    suffix: bytes,
    pixels: Buffer,
    background: int,
    x0: int,
    y0: int,
    x1: int,
    y1: int,
    w: int,
    h: int,
    binary: int,
) -> bytes: ...
