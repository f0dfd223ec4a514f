"""The grasping rig's logged topics and scene, engine-free: the truth topics it adds to an arm
plant's (``/arm/servo``, ``/head/joint_state``, ``/head/state``, ``/human/state``,
``/human/wrench``, ``/wrist/wrench_truth``), the head's joints and camera frame, the scene's
hand, head and wrist readings and the rig's GraspSpec. Shared by the PyBullet rig
(``grasp_plant.BulletGraspPlant``) and the MuJoCo one, so both log the same topics from one
source.

Its state is the rig's (``grasp_rig.GraspRig``, its base): the servos, head, human, applied
torques, the wrist's wrench and the arm rig's state; ``super()`` reaches the arm rig's topics.
"""

from __future__ import annotations

from plants.arm_rig.grasp_rig import GraspRig
from plants.arm_rig.payloads import HeadState, HumanState, HumanWrench, ServoState, Wrench
from replay.messages import JointState
from replay.scene import Frame, Scene

HEAD_JOINTS = ("pan", "tilt")


class GraspRigTopics(GraspRig):
    """The grasping rig's truth topics, joints, frames and scene readings."""

    def truth(self, t: float) -> dict:
        out = super().truth(t)
        del out["/arm/applied_torque"]
        servos = self.arm_servos
        out["/arm/servo"] = ServoState(
            t,
            list(self.joint_names),
            self._full(servos.command_l),
            self._full(servos.integral_l),
            self._tau_applied[:],
            self._clamped[:],
        )
        hs = self.head_servo
        out["/head/joint_state"] = JointState(
            t, list(HEAD_JOINTS), hs.q_l[:], hs.qd_l[:], hs.torque_l[:]
        )
        _, c, quat = self._head_reading()
        out["/head/state"] = HeadState(t, hs.q_l[0], hs.q_l[1], hs.qd_l[:], c.tolist(), quat[:])
        human = self.human
        out["/human/state"] = HumanState(
            t, human.target_l[:], float(human.roll), human.force(), human.max_force
        )
        pos = self._state()[2][0]
        out["/human/wrench"] = HumanWrench(
            t,
            human.force(),
            human.torque_l[:],
            [a - b for a, b in zip(pos, human.target_l)],
            human.limited,
        )
        w = self.engine.wrench
        out["/wrist/wrench_truth"] = Wrench(t, w[:3], w[3:])
        return out

    def joints(self) -> tuple[list, list, list, list]:
        """The arm's and hand's joints, then the head's pan and tilt."""
        arm = super().joints()
        assert arm is not None  # an arm plant always has joints
        names, q, qd, effort = arm
        hs = self.head_servo
        return (
            names + list(HEAD_JOINTS),
            q + hs.q_l,
            qd + hs.qd_l,
            effort + hs.torque_l,
        )

    def frames(self) -> list[Frame]:
        """The robot's links and the head's camera (``head_camera``: x right, y down, z the
        optical axis) in ``world``."""
        _, c, quat = self._head_reading()
        x, y, z = (float(v) for v in c)
        return super().frames() + [Frame("world", "head_camera", (x, y, z), tuple(quat))]

    def _full(self, values: list) -> list:
        """Per-active-joint values as a list over every arm joint (zero where locked)."""
        if self._all_active:
            return list(values)
        out = [0.0] * self.dof
        for i, x in zip(self.active, values):
            out[i] = x
        return out

    def scene(self) -> Scene:
        sc = super().scene()
        hs = self.head_servo
        R, c, _ = self._head_reading()
        hq, hqd, htau = self._state()[1]
        sc.readings["hand"] = {"name": list(self.hand_names), "position": hq[:], "velocity": hqd[:]}
        sc.readings["hand_torque"] = {"name": list(self.hand_names), "torque": htau}
        sc.readings["head"] = {
            "name": list(HEAD_JOINTS),
            "position": hs.q_l[:],
            "velocity": hs.qd_l[:],
            "camera_rotation": R,
            "camera_position": c,
        }
        sc.readings["wrist"] = {"wrench": self.engine.wrench}
        return sc
