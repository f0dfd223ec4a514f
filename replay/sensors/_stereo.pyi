"""Types of the stereo ball camera's compiled per-frame steps (replay/sensors/_stereo.c)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous buffer (a NumPy array of the dtype the kernel documents)

def frame(
    polygons: Sequence[Buffer],
    greys: Sequence[float],
    boxes: Sequence[Sequence[float]],
    grey: float,
    W: int,
    H: int,
    threshold: float,
    min_pixels: int,
    binary: int,
    default_background: float,
) -> tuple[bytearray, tuple[int, int, int, int], tuple[float, float, int, float] | None]: ...
def locate(
    P0: Buffer,
    P1: Buffer,
    u0: float,
    v0: float,
    u1: float,
    v1: float,
    radius: float,
    axes: Buffer,
    centres: Buffer,
) -> tuple[float, float, float] | None: ...
def measure(
    prims: Sequence[Any],
    sphere: type,
    locate: bool,
    radius: float,
    cams: Buffer,
    cos: Buffer,
    sin: Buffer,
    scale: float,
    grey: float,
    W: int,
    H: int,
    threshold: float,
    min_pixels: int,
    binary: int,
    default_background: float,
    P0: Buffer,
    P1: Buffer,
    axes: Buffer,
    centres: Buffer,
) -> (
    tuple[
        bytearray,
        tuple[int, int, int, int],
        tuple[float, float, int, float] | None,
        bytearray,
        tuple[int, int, int, int],
        tuple[float, float, int, float] | None,
        tuple[float, float, float] | None,
    ]
    | None
): ...
