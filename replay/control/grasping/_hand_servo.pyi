"""Types of the grasping hand task's compiled arithmetic (replay/control/grasping/_hand_servo.c
documents each)."""

from collections.abc import Sequence

def lowpass(load: Sequence[float], torque: Sequence[float], a: float) -> list[float]: ...
def eq4(
    pre: Sequence[float],
    grip: Sequence[float] | None,
    c: float,
    q: Sequence[float],
    qd: Sequence[float],
    load: Sequence[float],
    K_hg: float,
    K_hv: float,
    K_hf: float,
    vmax: float,
) -> tuple[list[float], list[float], float]: ...
