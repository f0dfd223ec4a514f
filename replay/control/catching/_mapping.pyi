"""Types of the catching mapping's compiled kernel (replay/control/catching/_mapping.c)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous buffer (CatchGeometry._c, PolynomialB._powers_c, DirectMapping._A)

Vec3 = tuple[float, float, float]

def evaluate_one(
    geo: Buffer,
    powers: Buffer,
    A: Buffer,
    r: Sequence[float],
    rd: Sequence[float],
    rdd: Sequence[float],
) -> tuple[Vec3, Vec3, Vec3, Vec3, bool]: ...
