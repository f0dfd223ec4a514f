"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in PyBullet: physics only.

The engine-free rig (plants/arm_rig/grasp_rig.py ``GraspRig``, with its topics and verdict) on
the PyBullet adapter (``PybulletGraspEngine``); this module holds its PyBullet drives, sensor
and human. The rig:

- the arm's 7 AC servos and the hand's 14 DC servos take **velocity commands**
  (:class:`ServoCommand`; eq. 2's and eq. 4's outputs) with their torque limits
  (``servo.VelocityServos``); the motors' torques are read back (the hand's are its strain
  gauges' F^h);
- a 2-axis pan/tilt **head** (``head.HeadServo``) carrying the vision chip's camera;
- the wrist's 6-axis **force/torque sensor** on the fixed flange-palm joint (``ft_sensor``);
- a **human hand** moving the object on its constraint plane, a compliant spring-damper coupling
  to its seeded path (``human_hand``);
- events ``grasp`` (the base's hold event under this name), ``release`` (with how long it was
  held), ``slip``, and the run's outcome: grasped, held while the human kept moving the object.

One ``getJointStates`` per step reads the arm, the hand and the palm joint together; the base's
state readers use that cache, and its one ``getLinkStates`` a step (tool and palm frames) gives the
effector's motion, the grasp point and the palm's point velocity.
"""

from __future__ import annotations

import numpy as np
from plants.bullet_arm.engine import pybullet as p

from plants.arm_rig.arm_state import joint_state
from plants.bullet_arm.ft_sensor import WristFT
from plants.bullet_arm.human_hand import HumanHand
from plants.bullet_arm.motors import VelocityMotors
from plants.bullet_arm.plant import PybulletEngine
from replay.robot.hand import palm_body


class PybulletGraspEngine(PybulletEngine):
    """The PyBullet adapter widened by the grasping rig's engine questions
    (grasp_rig.py ``GraspEngine``): the hand's velocity motors, the wrist's F/T sensor, the
    arm's mass matrix and the human's forces."""

    def grasp_setup(self) -> tuple[list, np.ndarray]:
        bc = self.bc
        self._palm_j = self.jidx["palm_joint"]
        assert self.hand_table is not None
        self.ft = WristFT(bc, self.robot, self._palm_j, palm_body(self.hand_table).com)
        self._all_j = self.arm_j + self.hand_j + [self._palm_j]
        # the hand joints: no PyBullet default motor (their VelocityMotors drive them)
        bc.setJointMotorControlArray(
            self.robot, self.hand_j, p.VELOCITY_CONTROL, forces=[0.0] * len(self.hand_j)
        )
        # the servos are inertia-decoupled (servo.VelocityServos): the arm joints' block of the
        # mass matrix (hand joints held by their drives) at the posture of each step
        dofs = list(self.dofs)
        read = self.arm_j + self.hand_j
        self._dof_from_read = [read.index(j) for j in dofs]
        self._arm_rows = [dofs.index(j) for j in self.arm_j]
        self._mass_matrix = bc.calculateMassMatrix
        pos = [s[0] for s in bc.getJointStates(self.robot, dofs)]
        self.hand_servos = VelocityMotors(
            bc, self.robot, self.hand_j, [self.params.hand_max_torque] * len(self.hand_j)
        )
        # the servos have been holding the robot still before t = 0: their integrals carry the
        # static torques (gravity) at the initial posture
        g = bc.calculateInverseDynamics(self.robot, pos, [0.0] * len(dofs), [0.0] * len(dofs))
        tau0 = {j: g[i] for i, j in enumerate(dofs)}
        self._dof_pos = pos
        return [tau0[j] for j in self.arm_j], self.arm_mass_matrix()

    def make_human(self, rng: np.random.Generator, args: dict) -> HumanHand:
        assert self.obj is not None and self.palm_link is not None
        return HumanHand(self.bc, self.obj, rng, **args)

    def drive_human(self, human, t: float, obj: tuple) -> None:
        human.drive(t, *obj)

    # ------------------------------------------------------------------ state (one read a step)
    def state(self) -> tuple:
        """The state (plain floats) from one getJointStates of arm, hand and palm joint, with
        the hand motors' torques, the wrist's wrench and the object's state."""
        if self._cache is None:
            states = self.get_joint_states(self.robot, self._all_j)  # arm, hand, palm joint
            self._dof_pos = [states[k][0] for k in self._dof_from_read]
            (q, qd), (hq, hqd, heff) = joint_state(states[:-1], self.na, self.pick, self.q_locked_l)
            self.hand_servos.read(heff)
            self.wrench = self.ft.convert(states[-1][2])  # the palm joint's reaction
            opos, orn = self.get_base_pose(self.obj)
            v, w = self.get_base_velocity(self.obj)
            self._cache = ((q, qd), (hq, hqd, self.hand_servos.torque), (opos, orn, v, w))
        return self._cache

    def arm_mass_matrix(self) -> np.ndarray:
        M = np.asarray(self._mass_matrix(self.robot, self._dof_pos))
        return M[np.ix_(self._arm_rows, self._arm_rows)]

    def point_velocity(self, link: int, point) -> tuple[float, float, float]:
        if link != self.palm_link:
            return super().point_velocity(link, point)
        # v + (w x (point - com)) of the palm's state read once this step (frames_now), summed
        # as np.cross's v + cross: the rig's grasp/slip checks and log stay bit-identical to
        # the array form
        (cx, cy, cz), _, _, _, _, _, (vx, vy, vz), (wx, wy, wz) = self.frames_now()[1]
        rx, ry, rz = float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz
        return (vx + (wy * rz - wz * ry), vy + (wz * rx - wx * rz), vz + (wx * ry - wy * rx))

    # ------------------------------------------------------------------ command
    def hand_velocity(self, hand) -> None:
        self.hand_servos.set_command(hand)

    def drive_hand_servos(self, qd: list) -> None:
        self.hand_servos.actuate()
