"""Types of the grasping arm task's compiled kernels (replay/control/grasping/_arm_kinematics.c
documents each)."""

from collections.abc import Sequence
from typing import Any

Buffer = Any  # a C-contiguous float64 buffer (a NumPy array)

def chain(
    q: Sequence[float],
    n: int,
    consts: Buffer,
    base: Buffer,
    tool: Buffer,
    grasp_point: float,
    J: Buffer,
    Jg: Buffer,
) -> tuple[float, ...]: ...
def terms(
    Jg: Buffer,
    J: Buffer,
    n: int,
    lam2: float,
    b1: Sequence[float],
    b2: Sequence[float],
    qd: Sequence[float],
    F: Sequence[float],
    K_ap: float,
    K_av: float,
    K_af: float,
    vlim: Sequence[float],
) -> tuple[list[float], list[float], list[float], list[float], list[float]]: ...
def wrench(
    R: Sequence[float],
    force: Sequence[float],
    torque: Sequence[float],
    w_hand: Sequence[float],
    com: Sequence[float],
    bias: Sequence[float] | None,
    filtered: Sequence[float],
    a: float,
    deadband: float,
) -> tuple[list[float], list[float], list[float]]: ...
