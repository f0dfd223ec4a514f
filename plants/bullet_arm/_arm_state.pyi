"""Types of the arm plant's compiled state arithmetic (plants/bullet_arm/_arm_state.c documents
each; plants/bullet_arm/arm_state.py and outcome.py keep their Python references)."""

from collections.abc import Sequence

def joint_state(
    states: tuple, na: int, pick: tuple[int, ...], locked: list[float]
) -> tuple[tuple[list[float], list[float]], tuple[list[float], list[float], list[float]]]: ...
def limit_flags(
    q: Sequence[float],
    qd: Sequence[float],
    pos: Sequence[float] | None,
    v: Sequence[float] | None,
    vlim: Sequence[float],
    lower: Sequence[float],
    upper: Sequence[float],
    over0: list[bool],
    at0: list[bool],
) -> tuple[bool, list[bool] | None, list[bool] | None] | None: ...
def palm_frame(
    obj_pos: Sequence[float],
    obj_vel: Sequence[float],
    palm_pos: Sequence[float],
    palm_quat: Sequence[float],
    palm_vel: Sequence[float],
    palm_omega: Sequence[float],
    thickness: float,
) -> tuple[float, float, float, float, float, tuple[float, float, float], float]: ...
