"""Types of the catching controller's compiled torques (replay/control/catching/_torque.c)."""

from collections.abc import Sequence

def pd(
    ff: Sequence[float],
    kp: Sequence[float],
    q_d: Sequence[float],
    q: Sequence[float],
    kd: Sequence[float],
    qd_d: Sequence[float],
    qd: Sequence[float],
    limit: Sequence[float],
) -> list[float]: ...
