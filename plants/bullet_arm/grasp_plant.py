"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in PyBullet: physics only.

The engine-free rig (plants/arm_rig/grasp_rig.py ``GraspRig``, its topics and verdict) on
:class:`BulletArmPlant`; this module holds its PyBullet drives, sensor and human. The rig:

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
from plants.arm_rig.grasp_topics import GraspRigTopics
from plants.arm_rig.grasp_verdict import GraspVerdict
from plants.arm_rig.params import GraspParams
from plants.bullet_arm.ft_sensor import WristFT
from plants.bullet_arm.human_hand import HumanHand
from plants.bullet_arm.motors import VelocityMotors
from plants.bullet_arm.plant import BulletArmPlant
from replay.robot.hand import palm_body


class BulletGraspPlant(GraspVerdict, GraspRigTopics, BulletArmPlant):
    Params = GraspParams
    description = (
        "PyBullet WAM-7 + 14-joint hand on velocity servos, pan/tilt head, wrist F/T, "
        "an object moved by a human hand on a constraint plane"
    )

    def _grasp_engine_setup(self) -> None:
        bc = self.bc
        self._palm_j = self._jidx["palm_joint"]
        assert self.hand_table is not None
        self.ft = WristFT(bc, self.robot, self._palm_j, palm_body(self.hand_table).com)
        self._all_j = self._arm_j + self._hand_j + [self._palm_j]
        # the hand joints: no PyBullet default motor (their VelocityMotors drive them)
        bc.setJointMotorControlArray(
            self.robot, self._hand_j, p.VELOCITY_CONTROL, forces=[0.0] * len(self._hand_j)
        )
        # the servos are inertia-decoupled (servo.VelocityServos): the arm joints' block of the
        # mass matrix (hand joints held by their drives) at the posture of each step
        dofs = list(self._dofs)
        read = self._arm_j + self._hand_j
        self._dof_from_read = [read.index(j) for j in dofs]
        self._arm_rows = [dofs.index(j) for j in self._arm_j]
        self._mass_matrix = bc.calculateMassMatrix
        pos = [s[0] for s in bc.getJointStates(self.robot, dofs)]
        self.hand_servos = VelocityMotors(
            bc, self.robot, self._hand_j, [self.params.hand_max_torque] * len(self._hand_j)
        )
        self._servo_j = self._arm_j
        # the servos have been holding the robot still before t = 0: their integrals carry the
        # static torques (gravity) at the initial posture
        g = bc.calculateInverseDynamics(self.robot, pos, [0.0] * len(dofs), [0.0] * len(dofs))
        tau0 = {j: g[i] for i, j in enumerate(dofs)}
        self._dof_pos = pos
        self.arm_servos.preload([tau0[j] for j in self._arm_j], self.arm_mass_matrix())
        self._read()

    def _make_human(self, rng: np.random.Generator, args: dict) -> HumanHand:
        assert self.obj is not None and self._palm_link is not None
        return HumanHand(self.bc, self.obj, rng, **args)

    # ------------------------------------------------------------------ state (one read a step)
    def _read(self) -> None:
        """The base's state cache (plain floats) from one getJointStates of arm, hand and palm
        joint, with the servos' torques, the wrist's wrench and the object's state."""
        states = self._get_joint_states(self.robot, self._all_j)  # arm, hand, palm joint
        self._dof_pos = [states[k][0] for k in self._dof_from_read]
        (q, qd), (hq, hqd, heff) = joint_state(states[:-1], self._na, self._pick, self._q_locked_l)
        self._read_servos()
        self.hand_servos.read(heff)
        self._wrench = self.ft.convert(states[-1][2])  # the palm joint's reaction
        opos, orn = self._get_base_pose(self.obj)
        v, w = self._get_base_velocity(self.obj)
        self._cache = (
            (q, qd),
            (hq, hqd, self.hand_servos.torque),
            (opos, orn, v, w),
        )
        self._head_pose = None

    def _state(self) -> tuple:
        if self._cache is None:
            self._read()
            assert self._cache is not None
        return self._cache

    def arm_mass_matrix(self) -> np.ndarray:
        M = np.asarray(self._mass_matrix(self.robot, self._dof_pos))
        return M[np.ix_(self._arm_rows, self._arm_rows)]

    def _point_velocity(self, link: int, point) -> tuple[float, float, float]:
        if link != self._palm_link:
            return super()._point_velocity(link, point)
        # v + (w x (point - com)) of the palm's state read once this step (the base's
        # _frames_now), summed as np.cross's v + cross: the rig's grasp/slip checks and log
        # stay bit-identical to the array form
        (cx, cy, cz), _, _, _, _, _, (vx, vy, vz), (wx, wy, wz) = self._frames_now()[1]
        rx, ry, rz = float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz
        return (vx + (wy * rz - wz * ry), vy + (wz * rx - wx * rz), vz + (wx * ry - wy * rx))

    # ------------------------------------------------------------------ command
    def _hand_velocity(self, hand) -> None:
        self.hand_servos.set_command(hand)

    def step(self) -> None:
        (_, qd), _, obj = self._state()
        self.human.drive(self._t, *obj)
        self._set_motors(
            self.robot,
            self._servo_j,
            p.TORQUE_CONTROL,
            forces=self._servo_torques(qd),
        )
        self.hand_servos.actuate()
        self.head_servo.step()
        self._obj_vel_before = obj[2]
        self.bc.stepSimulation()
        self._steps += 1
        self._t = self._steps * self.dt
        self._read()
        self._judge_step()
