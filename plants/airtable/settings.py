"""The air table's settings worked out from its ``Params``: the nominal spec a method may know
(hand kinematics and limits, the stick without its friction). One resolver, used by the plant
(``spec()``), the viewer (finger geometry) and analysis. No simulator.
"""

from __future__ import annotations

from plants.airtable.params import Params
from replay.robot.hand2d import AirTableSpec, HandSpec, StickSpec, root_distance


def _pair(v) -> tuple[float, float]:
    return (float(v[0]), float(v[1]))


def hand_spec(p: Params) -> HandSpec:
    h = p.hand
    return HandSpec(
        root_offsets=(_pair(h.root_offset0), _pair(h.root_offset1)),
        link_lengths=_pair(h.link_lengths),
        joint_limits=(_pair(h.q1_limits), _pair(h.q2_limits)),
        joint_speed=float(h.joint_speed),
        base_limits=(_pair(h.base_x_limits), _pair(h.base_y_limits)),
        base_speed=float(h.base_speed),
        tip_radius=float(h.tip_radius),
        start_base=_pair(h.base),
        start_joints=(_pair(h.joints0), _pair(h.joints1)),
    )


def spec(p: Params, hand: HandSpec | None = None) -> AirTableSpec:
    """Nominal values only: the method must not need mu (Assumption 10 and the paper's point).
    The width is the one the fingertips collide with (it sets where contact happens)."""
    st = p.stick
    return AirTableSpec(
        hand=hand if hand is not None else hand_spec(p),
        stick=StickSpec(
            mass=st.mass,
            inertia=st.inertia,
            length=st.length,
            width=st.collision_width,
            restitution=st.restitution,
        ),
    )


def in_reach(hand: HandSpec, length: float, xy) -> bool:
    """The stick's centre ``xy`` within finger reach (l1 + l2, joint limits ignored) plus L/2 of
    a finger root anywhere on the slider's range: a loose, purely geometric bound."""
    reach = sum(hand.link_lengths) + hand.tip_radius + 0.5 * length
    return root_distance(hand, xy) <= reach
