"""Types of the stick estimator's compiled sums and fit (replay/control/stick/_fit.c documents
each)."""

from typing import Any

Buffer = Any  # the running sums: array('d') of 12

def add(
    sums: Buffer,
    anchor: tuple[float, float, float, float],
    sample: tuple[float, float, float, float],
    sign: float,
) -> None: ...
def fit(
    sums: Buffer, anchor: tuple[float, float, float, float], n: int, t_ref: float
) -> tuple[float, float, float, float, float, float, float, float]: ...
