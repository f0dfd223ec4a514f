"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in Drake: physics only, the
engine-free grasping rig's (plants/arm_rig/grasp_rig.py ``GraspRig``) engine questions answered
by the Drake adapter (``DrakeGraspEngine``, widening ``DrakeEngine``):

- the arm's servos' mass matrix: Drake's (``CalcMassMatrix``), their torques applied as
  generalized forces; the hand's 14 DC servos (``ServoCommand.hand``) are the Drake world's PD
  servos (Kp = 0) capped at ``hand_max_torque`` inside SAP's solve;
- the wrist F/T sensor: Drake's reaction force of the palm's weld (``_wrist``);
- the human hand: the engine-free ``HumanPath``, its wrench applied to the object's centre of
  mass (``get_applied_spatial_force_input_port``).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce

from plants.arm_rig.grasp_rig import hand_speeds
from plants.arm_rig.human_path import HumanPath
from plants.drake_arm.plant import DrakeEngine
from plants.drake_arm.world import vec


class DrakeGraspEngine(DrakeEngine):
    """The Drake adapter widened by the grasping rig's engine questions
    (grasp_rig.py ``GraspEngine``): the hand servos' command, the wrist's F/T sensor, the arm's
    mass matrix and the human's forces."""

    def grasp_setup(self) -> tuple[list, np.ndarray]:
        p, ctx, W = self.mbp, self.ctx, self.world
        self._arm_v_l = [b for _, _, b in self._arm_slots]
        self._arm_block = np.ix_(self._arm_v_l, self._arm_v_l)
        self._hand_v_cmd = [0.0] * len(W.hand_v)
        self._push = ExternallyAppliedSpatialForce()
        self._push.body_index = W.object_body.index()
        self._force_port = p.get_applied_spatial_force_input_port()
        self._force_port.FixValue(ctx, [self._push])
        # held still before t = 0: the integrals carry the static (gravity) torques at the
        # initial posture (Drake's gravity forces are the generalized forces gravity applies)
        g: Any = p.CalcGravityGeneralizedForces(ctx)
        static = (-g[self._arm_v_l]).tolist()
        M = self.arm_mass_matrix()
        self._palm_j = int(W.palm_joint.index())
        self._wrist()
        return static, M

    def make_human(self, rng: np.random.Generator, args: dict) -> HumanPath:
        return HumanPath(rng, **args)

    def drive_human(self, human: HumanPath, t: float, obj: tuple) -> None:
        human.drive(t, *obj)
        self._push.F_Bq_W = SpatialForce(vec(human.torque_l), vec(human.force_l))
        self._force_port.FixValue(self.ctx, [self._push])

    # ------------------------------------------------------------------ state
    def arm_mass_matrix(self) -> np.ndarray:
        M: Any = self.mbp.CalcMassMatrix(self.ctx)
        return M[self._arm_block]

    def _wrist(self) -> None:
        """The wrist sensor's reading, as the PyBullet adapter's (bullet_arm/ft_sensor.py): the
        force and torque the hand exerts on the flange, moment about the joint origin, palm
        frame [Fx, Fy, Fz, Mx, My, Mz]. Drake's reaction force F_CJc_Jc is the parent's (the
        flange's) on the child (the palm) at the joint's child frame (the palm's origin and
        axes): negated. Read before a step: that step's."""
        forces: Any = self.mbp.get_reaction_forces_output_port().Eval(self.ctx)
        F = forces[self._palm_j]
        self.wrench = (-F.translational()).tolist() + (-F.rotational()).tolist()

    def _read_step(self) -> None:
        super()._read_step()
        self._wrist()  # the step's reaction

    # ------------------------------------------------------------------ command
    def hand_velocity(self, hand) -> None:
        self._hand_v_cmd = hand_speeds(hand, len(self._hand_v_cmd))

    def drive_hand_servos(self, qd: list) -> None:
        self.drive_hand(self._hand_v_cmd, qd)
