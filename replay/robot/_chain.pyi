"""Types of the serial chain's compiled kernels (replay/robot/_chain.c documents each)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous float64 buffer (SerialChain._rows_c, _base_c)

def point(
    rows: Buffer, base: Buffer, q: Sequence[float], p: Sequence[float]
) -> tuple[float, float, float]: ...
def rnea(
    rows: Buffer,
    base: Buffer,
    q: Sequence[float],
    qd: Sequence[float],
    qdd: Sequence[float],
    g: Sequence[float],
) -> tuple[float, ...]: ...
