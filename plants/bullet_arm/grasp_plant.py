"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) on the bullet_arm plant: physics only.

What it adds to :class:`BulletArmPlant` (same URDF builder, same object, same contact/hold events):

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
from plants.arm_rig.grasp_setup import head_setup, human_args, plane_setup
from plants.arm_rig.grasp_topics import GraspRigTopics
from plants.arm_rig.grasp_verdict import GraspVerdict
from plants.arm_rig.head import HeadServo
from plants.bullet_arm.human_hand import HumanHand
from plants.arm_rig.params import GraspParams
from plants.bullet_arm.plant import BulletArmPlant
from plants.bullet_arm.servo import VelocityMotors, VelocityServos
from replay.interfaces import Occurrence
from replay.robot.arm_types import GraspSpec, ServoCommand
from replay.robot.hand import palm_body
from replay.robot.head import camera_pose
from replay.spatial import matrix_to_quaternion


class BulletGraspPlant(GraspVerdict, GraspRigTopics, BulletArmPlant):
    Params = GraspParams
    spec_type = GraspSpec
    command_types = (ServoCommand,)  # type: ignore[assignment]
    hold_event = "grasp"
    description = (
        "PyBullet WAM-7 + 14-joint hand on velocity servos, pan/tilt head, wrist F/T, "
        "an object moved by a human hand on a constraint plane"
    )

    def __init__(self, params: GraspParams, *, dt: float, rng: np.random.Generator) -> None:
        if params.object == "none" or params.hand == "none":
            raise ValueError("the grasping rig needs a hand and an object")
        super().__init__(params, dt=dt, rng=rng)
        self._watch = None  # the catch verdict's watcher: this rig's is outcome()
        P = params
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
        self.arm_servos = VelocityServos(
            self.torque_limits[list(self.active)], P.arm_servo_bandwidth, dt
        )
        self.hand_servos = VelocityMotors(
            bc, self.robot, self._hand_j, [P.hand_max_torque] * len(self._hand_j)
        )
        self._servo_j = self._arm_j
        # the servos have been holding the robot still before t = 0: their integrals carry the
        # static torques (gravity) at the initial posture
        g = bc.calculateInverseDynamics(self.robot, pos, [0.0] * len(dofs), [0.0] * len(dofs))
        tau0 = {j: g[i] for i, j in enumerate(dofs)}
        self._dof_pos = pos
        self.arm_servos.preload([tau0[j] for j in self._arm_j], self.arm_mass_matrix())
        # the head, the constraint plane and the human (grasp_setup: shared with MuJoCo's rig)
        self.head, h0 = head_setup(P)
        self.head_servo = HeadServo(self.head, P.head_servo_bandwidth, dt, h0)
        self.plane, u, v, n = plane_setup(P)
        self._u, self._v = u, v
        self._u_l, self._v_l = u.tolist(), v.tolist()
        assert self.obj is not None and self._palm_link is not None
        self.human = HumanHand(bc, self.obj, rng, **human_args(P, u, v, n))
        # bookkeeping of the verdict
        self._n_l = [float(x) for x in n]
        self._start_verdict(P.slip_time, dt)
        self._head_pose: tuple | None = None
        self._read()
        self._spec = self._grasp_spec(self._spec)

    # ------------------------------------------------------------------ spec
    # ------------------------------------------------------------------ state (one read a step)
    def _read(self) -> None:
        """The base's state cache (plain floats) from one getJointStates of arm, hand and palm
        joint, with the servos' torques, the wrist's wrench and the object's state."""
        states = self._get_joint_states(self.robot, self._all_j)  # arm, hand, palm joint
        self._dof_pos = [states[k][0] for k in self._dof_from_read]
        (q, qd), (hq, hqd, heff) = joint_state(states[:-1], self._na, self._pick, self._q_locked_l)
        servos = self.arm_servos
        if self._all_active:
            tau, clamped = servos.torque_l[:], servos.saturated_l[:]
        else:
            tau, clamped = [0.0] * self.dof, [False] * self.dof
            for k, i in enumerate(self.active):
                tau[i], clamped[i] = servos.torque_l[k], servos.saturated_l[k]
        self._tau_applied = self._tau_cmd = tau
        self._clamped = clamped
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
        """The arm joints' block of the joint-space mass matrix now (kg m^2)."""
        M = np.asarray(self._mass_matrix(self.robot, self._dof_pos))
        return M[np.ix_(self._arm_rows, self._arm_rows)]

    def _link_point_velocity(self, link: int, point) -> tuple[float, float, float]:
        if link != self._palm_link:
            return super()._link_point_velocity(link, point)
        # v + (w x (point - com)) of the palm's state read once this step (the base's
        # _frames_now), summed as np.cross's v + cross: the rig's grasp/slip checks and log
        # stay bit-identical to the array form
        (cx, cy, cz), _, _, _, _, _, (vx, vy, vz), (wx, wy, wz) = self._frames_now()[1]
        rx, ry, rz = float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz
        return (vx + (wy * rz - wz * ry), vy + (wz * rx - wx * rz), vz + (wx * ry - wy * rx))

    # ------------------------------------------------------------------ command
    def apply(self, command: ServoCommand) -> None:  # type: ignore[override]
        if not isinstance(command, ServoCommand):
            raise TypeError(f"the grasping rig takes ServoCommand, got {type(command).__name__}")
        if command.arm is not None:
            qd = np.asarray(command.arm, float).reshape(-1)
            if qd.shape != (self.dof,):
                raise ValueError(f"ServoCommand.arm needs {self.dof} values, got {qd.shape[0]}")
            self.arm_servos.set_command(qd if self._all_active else qd[list(self.active)])
        if command.hand is not None:
            self.hand_servos.set_command(command.hand)
        if command.head is not None:
            self.head_servo.set_command(command.head)

    def step(self) -> None:
        (_, qd), _, obj = self._state()
        self.human.drive(self._t, *obj)
        self._set_motors(
            self.robot,
            self._servo_j,
            p.TORQUE_CONTROL,
            forces=self.arm_servos.torques(
                qd if self._all_active else [qd[i] for i in self.active],
                self.arm_mass_matrix(),
            ),
        )
        self.hand_servos.actuate()
        self.head_servo.step()
        self._obj_vel_before = obj[2]
        self.bc.stepSimulation()
        self._steps += 1
        self._t = self._steps * self.dt
        self._read()
        clamped, episode = self._clamped, self._torque_episode
        if True in clamped:
            for i, c in enumerate(clamped):
                if c and not episode[i]:
                    self._events.append(
                        Occurrence(
                            "torque_limit",
                            {
                                "joint": self.joint_names[i],
                                "applied": self._tau_applied[i],
                                "limit": self._tlim_l[i],
                            },
                        )
                    )
            self.clamp_count += sum(clamped)
        self._torque_episode = clamped
        was_held = self.caught
        n_before = len(self._events)
        self._check_events()
        self._grasp_bookkeeping(was_held, n_before)

    # ------------------------------------------------------------------ log and scene
    def _head_reading(self):
        """(R, c, [qx, qy, qz, qw]) of the head camera now (computed once a step: the log, the
        scene and the 3-D frames)."""
        if self._head_pose is None:
            R, c = camera_pose(self.head, *self.head_servo.q_l)
            self._head_pose = (R, c, [float(x) for x in matrix_to_quaternion(R)])
        return self._head_pose
