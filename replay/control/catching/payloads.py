"""Log payloads of the catching method's own topics (beyond the contract's, replay/messages.py)."""

from __future__ import annotations

from dataclasses import dataclass

from replay.messages import Vec3


@dataclass
class CatchingState:
    """``/catching/state``: the mapping's inner quantities at a control step."""

    t: float
    r_o: Vec3  # used object position (m)
    r_o_velocity: Vec3  # estimated (m/s)
    q_o: list[float]  # l_c^-1(r_o), active joints (rad)
    velocity_desired: list[float]  # qd_d (rad/s), all arm joints
    in_domain: bool
    predicted_catch_time: float  # s, -1 if unknown
    hand_closing: bool
    holding: bool
