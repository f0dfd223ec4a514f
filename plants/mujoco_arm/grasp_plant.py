"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) in MuJoCo: physics only, the PyBullet
rig's contract (plants/arm_rig/grasp_rig.py ``GraspRig``) on the MuJoCo adapter
(``MujocoGraspEngine``, widening ``MujocoEngine``):

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

from plants.arm_rig.grasp_rig import GraspRig, hand_speeds
from plants.arm_rig.human_path import HumanPath
from plants.mujoco_arm.human import drive_human
from plants.mujoco_arm.params import GraspParams
from plants.mujoco_arm.plant import MujocoEngine
from plants.mujoco_arm.world import wrist_wrench


class MujocoGraspEngine(MujocoEngine):
    """The MuJoCo adapter widened by the grasping rig's engine questions
    (grasp_rig.py ``GraspEngine``): the hand servos' command band, the wrist's F/T sensor,
    the arm's mass matrix and the human's forces."""

    def grasp_setup(self) -> tuple[list, np.ndarray]:
        m, d, W = self.mj, self.md, self.world
        # the hand servos: never clipped by MuJoCo (_hand_caps clips their command)
        m.actuator_forcerange[self._hand_act] = [(-1e6 * self._hand_cap, 1e6 * self._hand_cap)]
        self._hand_band = self._hand_cap / self._hand_kv  # rad/s
        self._hand_v_cmd = [0.0] * len(self._hand_act)
        # the servos are inertia-decoupled (servo.VelocityServos) by the arm joints' block of
        # MuJoCo's mass matrix (hand joints held by their servos), as the PyBullet rig's
        self._M = np.zeros((m.nv, m.nv))
        self._arm_block = np.ix_(W.arm_dof, W.arm_dof)
        self.wrench = wrist_wrench(W, d)
        # held still before t = 0: the integrals carry the static (gravity) torques at the
        # initial posture (qfrc_bias at zero velocity)
        return d.qfrc_bias[list(W.arm_dof)].tolist(), self.arm_mass_matrix()

    def make_human(self, rng: np.random.Generator, args: dict) -> HumanPath:
        return HumanPath(rng, **args)

    def drive_human(self, human: HumanPath, t: float, obj: tuple) -> None:
        W = self.world
        drive_human(human, self.md, t, W.object_qpos, W.object_dof, self._ob)

    # ------------------------------------------------------------------ state
    def arm_mass_matrix(self) -> np.ndarray:
        mujoco.mj_fullM(self.mj, self.md, self._M)
        return self._M[self._arm_block]

    def _read_contacts(self) -> None:
        super()._read_contacts()
        self.wrench = wrist_wrench(self.world, self.md)  # the step's (acceleration-stage sensors)

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
    def hand_velocity(self, hand) -> None:
        self._hand_v_cmd = hand_speeds(hand, len(self._hand_act))

    def drive_hand_servos(self, qd: list) -> None:
        self._hand_caps(self._hand_v_cmd, qd)


class MujocoGraspPlant(GraspRig):
    Params = GraspParams
    Engine = MujocoGraspEngine
    description = (
        "MuJoCo WAM-7 + 14-joint hand on velocity servos, pan/tilt head, wrist F/T, "
        "an object moved by a human hand on a constraint plane"
    )
