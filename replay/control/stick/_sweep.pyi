"""Types of the stick planners' compiled sweep checks (replay/control/stick/_sweep.c documents
each)."""

from typing import Any

Buffer = Any  # a C-contiguous float64 buffer (a NumPy array or array.array('d'))
MotionTuple = tuple[float, float, float, float, float, float, float, float, float, float, float]

def covered_index(
    motion: MotionTuple,
    t0: float,
    t1: float,
    n: int,
    px: float,
    py: float,
    half_length: float,
    half_width: float,
    grow: float,
    last: bool,
) -> tuple[int, float] | None: ...
def route_hit(
    motion: MotionTuple,
    t0: float,
    t1: float,
    n: int,
    segments: Buffer,
    speeds: tuple[float, float],
    geometry: tuple[float, float, float, float, float, float],
    k: int,
    t_guard: float,
    half_length: float,
    half_width: float,
    grow_active: float,
    check_idle: bool,
    arrival: float,
    grow_far: float,
) -> bool: ...
