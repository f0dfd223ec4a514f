"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in MuJoCo: physics only, the PyBullet
rig's contract (plants/bullet_arm/grasp_plant.py ``BulletGraspPlant``) on ``MujocoArmPlant``:

- the arm's 7 AC servos take velocity commands (``ServoCommand.arm``): the engine-free
  inertia-decoupled ``servo.VelocityServos`` on MuJoCo's arm mass matrix (``mj_fullM``), their
  torques applied as ``qfrc_applied``; the hand's 14 DC servos (``ServoCommand.hand``) are the
  MuJoCo plant's velocity actuators capped at ``hand_max_torque`` (``_hand_caps`` below);
- the engine-free pan/tilt head (``head.HeadServo``) with the vision chip's camera;
- the wrist F/T sensor (``world.wrist_wrench``: MuJoCo's force/torque sensors on the palm);
- the human hand (``human.drive_human``: the engine-free ``HumanPath`` through ``xfrc_applied``);
- the same truth topics, events (``grasp``, ``release``, ``slip``, ``torque_limit``, ...) and
  ``outcome`` (the engine-free ``GraspVerdict``), the contact summary from MuJoCo's contacts.

The head, plane and human come from the same ``grasp_setup`` as PyBullet's.
"""

from __future__ import annotations

import mujoco
import numpy as np

from plants.arm_rig.grasp_setup import head_setup, human_args, plane_setup
from plants.arm_rig.grasp_topics import GraspRigTopics
from plants.arm_rig.grasp_verdict import GraspVerdict
from plants.arm_rig.head import HeadServo
from plants.arm_rig.human_path import HumanPath
from plants.bullet_arm.servo import VelocityServos
from plants.mujoco_arm.human import drive_human
from plants.mujoco_arm.params import GraspParams
from plants.mujoco_arm.plant import MujocoArmPlant
from plants.mujoco_arm.world import wrist_wrench
from replay.interfaces import Occurrence
from replay.robot.arm_types import GraspSpec, ServoCommand
from replay.robot.head import camera_pose
from replay.spatial import matrix_to_quaternion


class MujocoGraspPlant(GraspVerdict, GraspRigTopics, MujocoArmPlant):
    Params = GraspParams
    spec_type = GraspSpec
    command_types = (ServoCommand,)  # type: ignore[assignment]
    hold_event = "grasp"
    description = (
        "MuJoCo WAM-7 + 14-joint hand on velocity servos, pan/tilt head, wrist F/T, "
        "an object moved by a human hand on a constraint plane"
    )

    def __init__(self, params: GraspParams, *, dt: float, rng: np.random.Generator) -> None:
        if params.object == "none" or params.hand == "none":
            raise ValueError("the grasping rig needs a hand and an object")
        super().__init__(params, dt=dt, rng=rng)
        self._watch = None  # the catch verdict's watcher: this rig's is outcome()
        P = params
        m, d, W = self.mj, self.md, self.world
        # the hand servos: never clipped by MuJoCo (_hand_caps clips their command)
        m.actuator_forcerange[self._hand_act] = [(-1e6 * self._hand_cap, 1e6 * self._hand_cap)]
        self._hand_band = self._hand_cap / self._hand_kv  # rad/s
        self._hand_v_cmd = [0.0] * len(self._hand_act)
        # the servos are inertia-decoupled (servo.VelocityServos) by the arm joints' block of
        # MuJoCo's mass matrix (hand joints held by their servos), as the PyBullet rig's
        self._M = np.zeros((m.nv, m.nv))
        self._arm_block = np.ix_(W.arm_dof, W.arm_dof)
        self.arm_servos = VelocityServos(
            self.torque_limits[list(self.active)], P.arm_servo_bandwidth, dt
        )
        # held still before t = 0: the integrals carry the static (gravity) torques at the
        # initial posture (qfrc_bias at zero velocity)
        self.arm_servos.preload(d.qfrc_bias[list(W.arm_dof)].tolist(), self.arm_mass_matrix())
        self._all_active = len(self.active) == self.dof
        self._read_servos()
        # the head, the constraint plane and the human (grasp_setup: the PyBullet rig's)
        self.head, h0 = head_setup(P)
        self.head_servo = HeadServo(self.head, P.head_servo_bandwidth, dt, h0)
        self.plane, u, v, n = plane_setup(P)
        self._u_l, self._v_l, self._n_l = u.tolist(), v.tolist(), [float(x) for x in n]
        self.human = HumanPath(rng, **human_args(P, u, v, n))
        self._wrench = wrist_wrench(W, d)
        self._start_verdict(P.slip_time, dt)
        self._head_pose: tuple | None = None
        self._spec = self._grasp_spec(self._spec)

    # ------------------------------------------------------------------ spec
    # ------------------------------------------------------------------ state
    def arm_mass_matrix(self) -> np.ndarray:
        """The arm joints' block of the joint-space mass matrix now (kg m^2)."""
        mujoco.mj_fullM(self.mj, self.md, self._M)
        return self._M[self._arm_block]

    def _read_servos(self) -> None:
        """The servos' torques as the arm's applied torques (full joint list)."""
        s = self.arm_servos
        if self._all_active:
            tau, clamped = s.torque_l[:], s.saturated_l[:]
        else:
            tau, clamped = [0.0] * self.dof, [False] * self.dof
            for k, i in enumerate(self.active):
                tau[i], clamped[i] = s.torque_l[k], s.saturated_l[k]
        self._tau_applied = self._tau_cmd = tau
        self._clamped = clamped

    def _frames_now(self) -> tuple:
        """(the tool frame's (pos, orn xyzw, v, w),): the verdict's view of the hand."""
        return (self._body_motion(self._tool),)

    def _contact_summary_now(self) -> tuple:
        return self._contact_summary()

    # ------------------------------------------------------------------ hand servos
    def _hand_caps(self, v_cmd: list, v: list) -> None:
        """The hand servos' command for the coming step, capped. PyBullet's hand motor is a
        velocity constraint with its force capped at ``hand_max_torque``, solved with the
        contacts. MuJoCo clips an actuator's force before its implicit step, and a clipped
        servo is integrated explicitly: on the fingers' light, coupled links an explicit step
        overshoots and chatters (measured: +-5 rad/s two-step oscillation of index j3 from
        20 ms on). So the servo here is never clipped by MuJoCo: its command is clipped to
        v +- hand_max_torque / kv instead (a torque-limited velocity amplifier), which keeps
        kv (u - v) within the cap and the servo implicit, rigid below the cap."""
        band, ctrl = self._hand_band, self.md.ctrl
        for a, x, y in zip(self._hand_act, v_cmd, v):
            ctrl[a] = min(max(x, y - band), y + band)

    def _hand_effort(self, v: list) -> list[float]:
        """The hand servos' torques of the last step (N*m): the implicit step's kv (u - v
        after it); actuator_force is kv (u - v before it). Zero before the first step."""
        kv = self._hand_kv
        return [kv * (x - y) for x, y in zip(self.md.ctrl[self._hand_act].tolist(), v)]

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
            h = np.asarray(command.hand, float).reshape(-1)
            if h.shape != (len(self._hand_act),):
                raise ValueError(
                    f"velocity command needs {len(self._hand_act)} values, got {h.shape[0]}"
                )
            self._hand_v_cmd = [x if np.isfinite(x) else 0.0 for x in h.tolist()]
        if command.head is not None:
            self.head_servo.set_command(command.head)

    def step(self) -> None:
        m, d, W = self.mj, self.md, self.world
        (_, qd), hand, obj = self._state()
        drive_human(self.human, d, self._t, W.object_qpos, W.object_dof, self._ob)
        tau = self.arm_servos.torques(
            qd if self._all_active else [qd[i] for i in self.active], self.arm_mass_matrix()
        )
        d.qfrc_applied[self._arm_dof] = tau
        self._hand_caps(self._hand_v_cmd, hand[1])
        self.head_servo.step()
        self._obj_vel_before = obj[2]
        mujoco.mj_step2(m, d)
        self._read_contacts()
        self._wrench = wrist_wrench(W, d)  # the step's reaction (acceleration-stage sensors)
        mujoco.mj_step1(m, d)
        self._cache = None
        self._steps += 1
        self._t = self._steps * self.dt
        self._head_pose = None
        if not self.diverged and self._warned():
            self.diverged = True
            self._events.append(Occurrence("nan", {"step": self._steps}))
        if self.diverged:
            return
        self._read_servos()
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
        """(R, c, [qx, qy, qz, qw]) of the head camera now (once a step)."""
        if self._head_pose is None:
            R, c = camera_pose(self.head, *self.head_servo.q_l)
            self._head_pose = (R, c, [float(x) for x in matrix_to_quaternion(R)])
        return self._head_pose
