"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in Drake: physics only, the PyBullet
rig's contract (plants/bullet_arm/grasp_plant.py ``BulletGraspPlant``) on ``DrakeArmPlant``:

- the arm's 7 AC servos take velocity commands (``ServoCommand.arm``): the engine-free
  inertia-decoupled ``servo.VelocityServos`` on Drake's arm mass matrix (``CalcMassMatrix``),
  their torques applied as generalized forces; the hand's 14 DC servos (``ServoCommand.hand``)
  are the Drake plant's PD servos (Kp = 0) capped at ``hand_max_torque`` inside SAP's solve;
- the engine-free pan/tilt head (``head.HeadServo``) with the vision chip's camera;
- the wrist F/T sensor: Drake's reaction force of the palm's weld (``_wrist``);
- the human hand: the engine-free ``HumanPath``, its wrench applied to the object's centre of
  mass (``get_applied_spatial_force_input_port``);
- the same truth topics, events and ``outcome`` (``GraspRigTopics``, ``GraspVerdict``).

Besides the arm plant's (plant.py), the rig state this reads: ``arm_servos``, ``head_servo``,
``human``, ``_t``, ``_steps``, ``diverged``; it calls the rig's ``_servo_torques``,
``_read_servos``, ``_diverge`` and ``_judge_step``; it sets ``_wrench``, ``_obj_vel_before``,
``_head_pose`` (None a step) and advances ``_steps``/``_t``, as the MuJoCo grasp plant does.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydrake.multibody.math import SpatialForce
from pydrake.multibody.plant import ExternallyAppliedSpatialForce

from plants.arm_rig.grasp_topics import GraspRigTopics
from plants.arm_rig.grasp_verdict import GraspVerdict
from plants.arm_rig.human_path import HumanPath
from plants.drake_arm.params import GraspParams
from plants.drake_arm.plant import DrakeArmPlant
from plants.drake_arm.world import vec


class DrakeGraspPlant(GraspVerdict, GraspRigTopics, DrakeArmPlant):
    Params = GraspParams
    description = (
        "Drake WAM-7 + 14-joint hand on velocity servos, pan/tilt head, wrist F/T, "
        "an object moved by a human hand on a constraint plane"
    )

    def _grasp_engine_setup(self) -> None:
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
        self.arm_servos.preload((-g[self._arm_v_l]).tolist(), self.arm_mass_matrix())
        self._read_servos()
        self._palm_j = int(W.palm_joint.index())
        self._wrist()

    def _make_human(self, rng: np.random.Generator, args: dict) -> HumanPath:
        return HumanPath(rng, **args)

    # ------------------------------------------------------------------ state
    def arm_mass_matrix(self) -> np.ndarray:
        M: Any = self.mbp.CalcMassMatrix(self.ctx)
        return M[self._arm_block]

    def _wrist(self) -> None:
        """The wrist sensor's reading, as the PyBullet plant's (bullet_arm/ft_sensor.py): the
        force and torque the hand exerts on the flange, moment about the joint origin, palm
        frame [Fx, Fy, Fz, Mx, My, Mz]. Drake's reaction force F_CJc_Jc is the parent's (the
        flange's) on the child (the palm) at the joint's child frame (the palm's origin and
        axes): negated. Read before a step: that step's."""
        forces: Any = self.mbp.get_reaction_forces_output_port().Eval(self.ctx)
        F = forces[self._palm_j]
        self._wrench = (-F.translational()).tolist() + (-F.rotational()).tolist()

    # ------------------------------------------------------------------ command
    def _hand_velocity(self, hand) -> None:
        h = np.asarray(hand, float).reshape(-1)
        if h.shape != (len(self._hand_v_cmd),):
            raise ValueError(
                f"velocity command needs {len(self._hand_v_cmd)} values, got {h.shape[0]}"
            )
        self._hand_v_cmd = [x if np.isfinite(x) else 0.0 for x in h.tolist()]

    def _read_step(self) -> None:
        super()._read_step()
        self._wrist()  # the step's reaction

    def step(self) -> None:
        (_, qd), hand, obj = self._state()
        human = self.human
        human.drive(self._t, *obj)
        self._push.F_Bq_W = SpatialForce(vec(human.torque_l), vec(human.force_l))
        self._force_port.FixValue(self.ctx, [self._push])
        self._apply_torques(self._servo_torques(qd))
        self._drive_hand(self._hand_v_cmd, hand[1])
        self.head_servo.step()
        self._obj_vel_before = obj[2]
        diverged = self._advance()
        self._cache = None
        self._steps += 1
        self._t = self._steps * self.dt
        self._head_pose = None
        if diverged:
            self._diverge()
        if self.diverged:
            return
        self._read_servos()
        self._judge_step()
