"""Types of the ballistic estimator's compiled kernel (replay/control/catching/_ballistic.c)."""

from collections.abc import Sequence

def time_to_radius(
    t: float,
    t_last: float,
    r0: Sequence[float],
    v: Sequence[float],
    g: Sequence[float],
    origin: Sequence[float],
    radius: float,
) -> float | None: ...
