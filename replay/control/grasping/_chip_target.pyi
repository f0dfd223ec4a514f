"""Types of the recognition task's compiled per-frame pass (replay/control/grasping/
_chip_target.c documents it)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous float64 buffer (a NumPy array)

def target_blob(
    previous: Sequence[int] | None, rows: Sequence[int], width: int, fill: bool, dirs: Buffer
) -> tuple[
    list[int],
    bool,
    tuple[int, float, float, float, float, float, float, float, bool] | None,
]: ...
def plane_geometry(
    yaw: float,
    pan: float,
    tilt: float,
    head: Sequence[float],
    offset: float,
    f: float,
    cx: float,
    cy: float,
    P: Sequence[float],
    n: Sequence[float],
    pu: Sequence[float],
    pv: Sequence[float],
    u: float,
    v: float,
    phi: float,
) -> tuple[float, float, float, float, float, float, float, float, float] | None: ...
