"""Types of the sphere silhouette's compiled kernel (replay/sensors/_silhouette.c)."""

from typing import Any

Buffer = Any  # a C-contiguous float64 buffer

def sphere_polygon(
    R: Buffer,
    o: Buffer,
    fx: float,
    fy: float,
    cx: float,
    cy: float,
    x: float,
    y: float,
    z: float,
    radius: float,
    cos: Buffer,
    sin: Buffer,
    scale: float,
    out: Buffer,
) -> tuple[float, float, float, float] | None: ...
