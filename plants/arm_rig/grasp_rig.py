"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999), engine-free: the arm rig with the
arm's 7 AC servos on velocity commands (``ServoCommand``; ``servo.VelocityServos``), the hand's
14 DC servos, a pan/tilt head (``head.HeadServo``) carrying the vision chip's camera, the wrist's
F/T sensor and a human hand moving the object on its constraint plane.

``GraspRig`` owns, once for every engine: the head, the plane, the arm servos and their torques,
the command, the step, its logged topics (the functions of ``grasp_topics``, fed the servos',
head's, human's and engine's readings) and its verdict (``verdict``, a
``grasp_verdict.GraspVerdict`` fed each step's readings). Its engine adapter (``engine``) is the
arm rig's widened by the grasp's engine questions (``GraspEngine`` below); an engine's grasp plant
is this class with its ``Params``, ``Engine`` and ``description``.
"""

from __future__ import annotations

from typing import ClassVar, Protocol

import numpy as np

from plants.arm_rig.engine import EngineAdapter
from plants.arm_rig.grasp_setup import head_setup, human_args, plane_setup
from plants.arm_rig.grasp_topics import (
    HEAD_JOINTS,
    grasp_readings,
    head_frame,
    head_topics,
    human_topics,
    servo_topic,
    wrist_topic,
)
from plants.arm_rig.grasp_verdict import GraspReading, GraspVerdict
from plants.arm_rig.head import HeadServo
from plants.arm_rig.human_path import HumanPath
from plants.arm_rig.params import GraspParams
from plants.arm_rig.rig import ArmRig
from plants.arm_rig.servo import VelocityServos
from replay.robot.arm_types import GraspSpec, ServoCommand
from replay.robot.head import camera_pose
from replay.scene import Frame, Scene
from replay.spatial import matrix_to_quaternion


def hand_speeds(hand, n: int) -> list[float]:
    """A hand velocity command (``ServoCommand.hand``) as ``n`` floats, a non-finite one 0;
    ValueError for another count."""
    h = np.asarray(hand, float).reshape(-1)
    if h.shape != (n,):
        raise ValueError(f"velocity command needs {n} values, got {h.shape[0]}")
    return [x if np.isfinite(x) else 0.0 for x in h.tolist()]


class GraspEngine(EngineAdapter, Protocol):
    """The grasping rig's engine questions, on top of the arm rig's."""

    wrench: list  # the wrist's true wrench [Fx, Fy, Fz, Mx, My, Mz] of the last step

    def grasp_setup(self) -> tuple[list, np.ndarray]:
        """The engine's hand drives and wrist sensor; (the arm joints' static torques at the
        initial posture, the arm's mass matrix there): the servos' preload."""

    def make_human(self, rng: np.random.Generator, args: dict) -> HumanPath:
        """The human hand (a ``human_path.HumanPath`` the engine applies) from ``args``."""

    def drive_human(self, human: HumanPath, t: float, obj: tuple) -> None:
        """Apply the human's coupling at ``t`` (the object's state ``obj``) over the next step."""

    def arm_mass_matrix(self) -> np.ndarray:
        """The arm joints' block of the joint-space mass matrix now (kg m^2)."""

    def hand_velocity(self, hand) -> None:
        """Set the hand servos' velocity command (rad/s per hand joint)."""

    def drive_hand_servos(self, qd: list) -> None:
        """Drive the hand servos at their command over the coming step (``qd``: their speeds)."""


class GraspRig(ArmRig):
    Params: ClassVar[type] = GraspParams
    description = (
        "the grasping rig: a WAM-7 and a 14-joint hand on velocity servos, a pan/tilt head, a "
        "wrist F/T sensor and an object moved by a human hand on a constraint plane, on the "
        "physics engine plant.params.engine names (PyBullet where it is empty)"
    )
    spec_type = GraspSpec
    command_types = (ServoCommand,)  # type: ignore[assignment]
    hold_event = "grasp"
    engine_role = "grasp"

    engine: GraspEngine

    def __init__(self, params: GraspParams, *, dt: float, rng: np.random.Generator) -> None:
        if params.object == "none" or params.hand == "none":
            raise ValueError("the grasping rig needs a hand and an object")
        super().__init__(params, dt=dt, rng=rng)  # the arm rig in its engine
        self._watch = None  # the catch verdict's watcher: this rig's is outcome()
        P = params
        self.arm_servos = VelocityServos(
            self.torque_limits[list(self.active)], P.arm_servo_bandwidth, dt
        )
        self.arm_servos.preload(*self.engine.grasp_setup())  # held still before t = 0
        self._read_servos()
        # the head, the constraint plane and the human (grasp_setup)
        self.head, h0 = head_setup(P)
        self.head_servo = HeadServo(self.head, P.head_servo_bandwidth, dt, h0)
        self.plane, u, v, n = plane_setup(P)
        self.human = self.engine.make_human(rng, human_args(P, u, v, n))
        self.verdict = GraspVerdict(P, self.plane, u, v, dt)
        self._head_pose: tuple | None = None
        self._spec = self._grasp_spec(self._spec)

    # ------------------------------------------------------------------ spec
    def _grasp_spec(self, base) -> GraspSpec:
        fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
        fields["notes"] = {
            **base.notes,
            "arm": "WAM-7 stands in for the paper's unnamed 7-axis arm; velocity servos",
        }
        return GraspSpec(**fields, head=self.head, plane=self.plane)

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
            self.engine.hand_velocity(command.hand)
        if command.head is not None:
            self.head_servo.set_command(command.head)

    def _servo_torques(self, qd: list) -> list:
        """The arm servos' torques for the coming step (active joints), at joint speeds ``qd``."""
        return self.arm_servos.torques(
            qd if self._all_active else [qd[i] for i in self.active], self.engine.arm_mass_matrix()
        )

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

    def step(self) -> None:
        E = self.engine
        (_, qd), hand, obj = self._state()
        E.drive_human(self.human, self._t, obj)
        E.apply_torques(self._servo_torques(qd))
        E.drive_hand_servos(hand[1])
        self.head_servo.step()
        self._obj_vel_before = obj[2]
        diverged = E.advance()
        self._steps += 1
        self._t = self._steps * self.dt
        self._head_pose = None
        if diverged:
            self._diverge()
        if self.diverged:
            return
        self._read_servos()
        self._torque_events(None, self._tau_applied, self._clamped)
        n_before = len(self._events)
        self._check_events()
        self._events += self.verdict.observe(self._reading(), self._events[n_before:])

    def _reading(self) -> GraspReading:
        """This step's truth for the verdict."""
        E, human = self.engine, self.human
        parts, _, force = E.contact_summary()
        pos = self._state()[2][0]
        return GraspReading(
            self._t, pos, E.effector_now(), parts, force, self.caught, human.target_l, human.force_l
        )

    def outcome(self, t: float) -> dict:
        """The physical verdict (grasp_verdict.py ``GraspVerdict.outcome``)."""
        return self.verdict.outcome(t)

    # ------------------------------------------------------------------ log and scene
    def _head_reading(self):
        """(R, c, [qx, qy, qz, qw]) of the head camera now (computed once a step: the log, the
        scene and the 3-D frames)."""
        if self._head_pose is None:
            R, c = camera_pose(self.head, *self.head_servo.q_l)
            self._head_pose = (R, c, [float(x) for x in matrix_to_quaternion(R)])
        return self._head_pose

    def truth(self, t: float) -> dict:
        out = super().truth(t)
        del out["/arm/applied_torque"]
        out["/arm/servo"] = servo_topic(
            t, self.joint_names, self.active, self.arm_servos, self._tau_applied, self._clamped
        )
        out.update(head_topics(t, self.head_servo, self._head_reading()))
        out.update(human_topics(t, self.human, self._state()[2][0]))
        out["/wrist/wrench_truth"] = wrist_topic(t, self.engine.wrench)
        return out

    def joints(self) -> tuple[list, list, list, list]:
        """The arm's and hand's joints, then the head's pan and tilt."""
        names, q, qd, effort = super().joints()
        hs = self.head_servo
        return names + list(HEAD_JOINTS), q + hs.q_l, qd + hs.qd_l, effort + hs.torque_l

    def frames(self) -> list[Frame]:
        """The robot's links and the head's camera in ``world``."""
        return super().frames() + [head_frame(self._head_reading())]

    def scene(self) -> Scene:
        sc = super().scene()
        camera, wrench = self._head_reading(), self.engine.wrench
        sc.readings.update(
            grasp_readings(self.hand_names, self._state()[1], self.head_servo, camera, wrench)
        )
        return sc
