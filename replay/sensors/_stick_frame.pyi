"""Types of the stick camera's compiled frame (replay/sensors/_stick_frame.c documents it)."""

from collections.abc import Sequence
from typing import Any

from replay.sensors._pixels import marker_moments

def measure(
    prims: Sequence[Any], shapes: dict, camera: tuple
) -> tuple[bytearray, tuple[int, int, int, int], tuple | None, tuple | None] | tuple | None: ...

# marker_moments_fast: _pixels.marker_moments' arguments and result, with less work
moments = marker_moments
