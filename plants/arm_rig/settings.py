"""The arm plant's settings worked out from its ``Params``: the one place that knows what an empty
list or a negative ``tool_d`` means. Used by the plant, the viewer (its URDF) and analysis (the arm
model a run's scenario describes), so none of them retypes a default. No simulator.

    settings = resolve(params)        # typed Params, e.g. rebuilt from a log's /scenario
    settings.arm_model().write()      # the URDF the plant loads (cached by content)
    settings.chain()                  # the nominal SerialChain (hand as payload)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plants.arm_rig.params import Params
from plants.models.arm import ArmModel, build_arm
from replay.robot.hand import HANDS, HandTable, hand_body
from replay.robot.serial_chain import SerialChain
from replay.robot.wam import (
    DEFAULT_VELOCITY_LIMIT,
    TORQUE_LIMIT_SETS,
    default_tool_d,
    load_wam_table,
    wam_chain,
    wam_joint_limits,
)

DOF = {"wam4": 4, "wam7": 7}


@dataclass(frozen=True, eq=False)
class ArmSettings:
    """Every value the plant derives from its ``Params`` before it builds a world."""

    params: Params
    table: dict  # the WAM parameter table (data/robots/wam.yaml)
    dof: int
    joint_names: tuple[str, ...]
    tool_d: float  # m, the tool frame along the last DH z axis
    hand: HandTable | None
    initial_q: np.ndarray  # rad, every arm joint
    initial_qd: np.ndarray  # rad/s; zero for locked joints
    torque_limits: np.ndarray  # N*m
    velocity_limits: np.ndarray  # rad/s
    locked: dict[str, float]  # joint -> the angle it is held at
    lower: np.ndarray  # rad, joint limits (the manual's)
    upper: np.ndarray
    hand_initial: np.ndarray  # rad, every hand joint (empty without a hand)

    @property
    def active(self) -> tuple[int, ...]:
        """Indices of the joints that are not locked."""
        return tuple(i for i, n in enumerate(self.joint_names) if n not in self.locked)

    def arm_model(self) -> ArmModel:
        """The URDF model the plant loads (``.write()`` gives its cached path)."""
        return build_arm(
            self.dof,
            tool_d=self.tool_d,
            hand=self.hand,
            locked=self.locked,
            torque_limits=self.torque_limits,
            velocity_limits=self.velocity_limits,
            table=self.table,
        )

    def chain(self, hand_q=None) -> SerialChain:
        """The nominal kinematics and dynamics, the hand (at ``hand_q``, default its initial
        posture) carried as the last link's payload."""
        P = self.params
        ht = self.hand
        q = self.hand_initial if hand_q is None else hand_q
        payload = hand_body(ht, q) if ht is not None else None
        return wam_chain(
            self.dof,
            tool_d=self.tool_d,
            base_position=P.base_position,
            base_rpy=P.base_rpy,
            gravity=P.gravity,
            payload=payload,
            table=self.table,
        )


def resolve(params: Params) -> ArmSettings:
    """``params`` -> the settings; a ``ValueError`` names the field that does not fit the arm."""
    P = params
    dof = DOF[P.arm]
    table = load_wam_table()
    tool_d = default_tool_d(dof, table) if P.tool_d < 0 else float(P.tool_d)
    hand = HANDS.get(P.hand) if P.hand != "none" else None
    q0 = np.zeros(dof) if not P.initial_q else np.asarray(P.initial_q, float)
    qd0 = np.zeros(dof) if not P.initial_qd else np.asarray(P.initial_qd, float)
    if q0.shape != (dof,) or qd0.shape != (dof,):
        raise ValueError(f"initial_q/initial_qd need {dof} values for {P.arm}")
    torque = (
        np.asarray(P.torque_limits, float)
        if P.torque_limits
        else np.asarray(TORQUE_LIMIT_SETS[P.torque_limit_set][:dof])
    )
    velocity = (
        np.asarray(P.velocity_limits, float)
        if P.velocity_limits
        else np.full(dof, DEFAULT_VELOCITY_LIMIT)
    )
    if torque.shape != (dof,) or velocity.shape != (dof,):
        raise ValueError(f"torque_limits/velocity_limits need {dof} values for {P.arm}")
    names = tuple(r["joint"] for r in table["dh"][:dof])
    for n in P.locked_joints:
        if n not in names:
            raise ValueError(f"locked_joints: unknown joint {n!r} (joints: {names})")
    locked = {n: float(q0[names.index(n)]) for n in P.locked_joints}
    qd0[[names.index(n) for n in locked]] = 0.0
    lower, upper = wam_joint_limits(dof, table)
    n_hand = len(hand.joint_names) if hand is not None else 0
    h0 = (
        np.asarray(P.hand_initial, float)
        if P.hand_initial
        else (hand.open_posture if hand is not None else np.zeros(0))
    )
    if h0.shape != (n_hand,):
        raise ValueError(f"hand_initial needs {n_hand} values")
    return ArmSettings(
        params=P,
        table=table,
        dof=dof,
        joint_names=names,
        tool_d=tool_d,
        hand=hand,
        initial_q=q0,
        initial_qd=qd0,
        torque_limits=torque,
        velocity_limits=velocity,
        locked=locked,
        lower=lower,
        upper=upper,
        hand_initial=h0,
    )
