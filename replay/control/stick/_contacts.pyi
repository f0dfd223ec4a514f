"""Types of the stick strategies' compiled contact solver (replay/control/stick/_contacts.c
documents it)."""

from collections.abc import Sequence

def options(
    m: float,
    inertia: float,
    e: float,
    theta: float,
    vx: float,
    vy: float,
    omega: float,
    target: float,
    is_speed: bool,
    speed: float,
    sides: Sequence[float],
) -> list[tuple[int, float, tuple[float, float, float], tuple[float, ...], float]]: ...
