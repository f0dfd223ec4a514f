"""The grasping rig (Namiki, Nakabo, Ishii & Ishikawa 1999) on the bullet_arm plant: physics only.

What it adds to :class:`BulletArmPlant` (same URDF builder, same object, same contact/hold events):

- the arm's 7 AC servos and the hand's 14 DC servos take **velocity commands**
  (:class:`ServoCommand`; eq. 2's and eq. 4's outputs) with their torque limits
  (``servo.VelocityServos``); the motors' torques are read back (the hand's are its strain
  gauges' F^h);
- a 2-axis pan/tilt **head** (``head.HeadServo``) carrying the vision chip's camera;
- the wrist's 6-axis **force/torque sensor** on the fixed flange-palm joint (``ft_sensor``);
- a **human hand** moving the object on its constraint plane (``human_hand``);
- events ``grasp`` (the base's hold event under this name), ``release`` (with how long it was
  held), ``slip``, and the run's outcome: grasped, held while the human kept moving the object.

One ``getJointStates`` per step reads the arm, the hand and the palm joint together; the base's
state readers use that cache, and its one ``getLinkStates`` a step (tool and palm frames) gives the
effector's motion, the grasp point and the palm's point velocity.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p

from plants.bullet_arm.ft_sensor import WristFT
from plants.bullet_arm.head import HeadServo
from plants.bullet_arm.human_hand import HumanHand
from plants.bullet_arm.params import GraspParams
from plants.bullet_arm.payloads import HeadState, HumanState, ServoState, Wrench
from plants.bullet_arm.plant import BulletArmPlant
from plants.bullet_arm.servo import VelocityMotors, VelocityServos, apply_torques
from replay.interfaces import Occurrence
from replay.messages import JointState
from replay.robot.arm_types import GraspSpec, PlaneSpec, ServoCommand
from replay.robot.hand import palm_body
from replay.robot.head import HeadSpec, camera_pose, look_angles
from replay.scene import Frame, Scene
from replay.spatial import matrix_to_quaternion

HEAD_JOINTS = ("pan", "tilt")
# the PyBullet calls the rig's helpers (servos, human hand) and the runner make every step through
# the client: BulletClient builds a new functools.partial (client id bound) at each attribute
# access, so the rig keeps one per name on its client (the same call; the base binds its reads)
PER_STEP_CALLS = (
    "stepSimulation",
    "setJointMotorControlArray",
    "changeConstraint",
    "getConstraintState",
)


class BulletGraspPlant(BulletArmPlant):
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
        for name in PER_STEP_CALLS:
            setattr(bc, name, getattr(bc, name))
        self._palm_j = self._jidx["palm_joint"]
        assert self.hand_table is not None
        self.ft = WristFT(bc, self.robot, self._palm_j, palm_body(self.hand_table).com)
        self._all_j = self._arm_j + self._hand_j + [self._palm_j]
        self._act = np.array(self.active, dtype=int)
        self._all_active = len(self.active) == self.dof  # no locked joint: no index mapping
        # the servos: every arm and hand joint's own inertia at the initial posture
        bc.setJointMotorControlArray(
            self.robot, self._hand_j, p.VELOCITY_CONTROL, forces=[0.0] * len(self._hand_j)
        )
        dofs = [j for j in self._dofs]
        pos = [s[0] for s in bc.getJointStates(self.robot, dofs)]
        Minv = np.linalg.inv(np.array(bc.calculateMassMatrix(self.robot, pos)))
        # each joint's effective inertia with the others free (1 / (M^-1)_jj), divided by the
        # largest eigenvalue of M^-1 diag(1 / (M^-1)_jj) (~2.7: the joints' coupling), so that
        # the fastest mode of all loops acting together has the stated bandwidth
        d = 1.0 / np.diag(Minv)
        coupling = float(np.max(np.linalg.eigvals(Minv * d[None, :]).real))
        inertia = {j: d[i] / coupling for i, j in enumerate(dofs)}
        self.arm_servos = VelocityServos(
            [inertia[j] for j in self._arm_j],
            self.torque_limits[list(self.active)],
            P.arm_servo_bandwidth,
            dt,
        )
        self.hand_servos = VelocityMotors(
            bc, self.robot, self._hand_j, [P.hand_max_torque] * len(self._hand_j)
        )
        self._servo_j = self._arm_j
        # the servos have been holding the robot still before t = 0: their integrals carry the
        # static torques (gravity) at the initial posture
        g = bc.calculateInverseDynamics(self.robot, pos, [0.0] * len(dofs), [0.0] * len(dofs))
        tau0 = {j: g[i] for i, j in enumerate(dofs)}
        self.arm_servos.preload([tau0[j] for j in self._arm_j])
        # the head
        self.head = HeadSpec(
            position=tuple(P.head_position),
            yaw=float(P.head_yaw),
            camera_offset=float(P.head_camera_offset),
            lower=tuple(P.head_lower),
            upper=tuple(P.head_upper),
            inertia=tuple(P.head_inertia),
            torque_limit=tuple(P.head_torque_limit),
            velocity_limit=tuple(P.head_velocity_limit),
        )
        h0 = (
            list(P.head_initial)
            if P.head_initial
            else list(look_angles(self.head, P.object_position))
        )
        if len(h0) != 2:
            raise ValueError("head_initial needs 2 values (pan, tilt)")
        self.head_servo = HeadServo(self.head, P.head_servo_bandwidth, dt, h0)
        # the constraint plane and the human
        n = np.asarray(P.plane_normal, float)
        if np.linalg.norm(n) == 0.0:
            raise ValueError("plane_normal must not be zero")
        n = n / np.linalg.norm(n)
        u = np.cross([0.0, 0.0, 1.0], n)
        if np.linalg.norm(u) < 1e-9:
            u = np.array([0.0, 1.0, 0.0])
        u = u / np.linalg.norm(u)
        v = np.cross(n, u)
        op = [float(x) for x in P.object_position]
        self.plane = PlaneSpec(
            point=(op[0], op[1], op[2]), normal=(float(n[0]), float(n[1]), float(n[2]))
        )
        self._u, self._v = u, v
        assert self.obj is not None and self._palm_link is not None
        self.human = HumanHand(
            bc,
            self.obj,
            rng,
            origin=P.object_position,
            rpy0=P.object_rpy,
            u=u,
            v=v,
            n=n,
            speed=P.human_speed,
            roll_rate=P.human_roll_rate,
            f_min=P.human_f_min,
            f_max=P.human_f_max,
            components=P.human_components,
            max_force=P.human_max_force,
            start=P.human_start,
        )
        # bookkeeping of the verdict
        self._grasps: list[dict] = []
        self._grasp_start = 0.0
        self._slipping = False
        self._slips = 0
        self._held_path = 0.0
        self._max_parts = 0
        self._touched: set = set()
        self._track_sq = 0.0
        self._track_n = 0
        self._last_pos: np.ndarray | None = None
        self._head_pose: tuple | None = None
        self._read()
        self._spec = self._grasp_spec(self._spec)

    # ------------------------------------------------------------------ spec
    def _grasp_spec(self, base) -> GraspSpec:
        fields = {f: getattr(base, f) for f in base.__dataclass_fields__}
        fields["notes"] = {
            **base.notes,
            "arm": "WAM-7 stands in for the paper's unnamed 7-axis arm; velocity servos",
        }
        return GraspSpec(**fields, head=self.head, plane=self.plane)

    # ------------------------------------------------------------------ state (one read a step)
    def _read(self) -> None:
        st = self._get_joint_states(self.robot, self._all_j)
        na, nh = len(self._arm_j), len(self._hand_j)
        pos, vel = [s[0] for s in st], [s[1] for s in st]
        if self._all_active:
            self._q, self._qd = np.array(pos[:na]), np.array(vel[:na])
            self._tau_applied = self._tau_cmd = self.arm_servos.torque.copy()
            self._clamped = self.arm_servos.saturated.copy()
        else:
            q = np.zeros(self.dof)
            qd = np.zeros(self.dof)
            for n, val in self.locked.items():
                q[self.joint_names.index(n)] = val
            act = self._act
            q[act] = pos[:na]
            qd[act] = vel[:na]
            self._q, self._qd = q, qd
            tau = np.zeros(self.dof)
            tau[act] = self.arm_servos.torque
            self._tau_applied = self._tau_cmd = tau
            self._clamped = np.zeros(self.dof, dtype=bool)
            self._clamped[act] = self.arm_servos.saturated
        self._hq = np.array(pos[na : na + nh])
        self._hqd = np.array(vel[na : na + nh])
        self.hand_servos.read(st[na : na + nh])
        self._htau = self.hand_servos.torque
        self._wrench = self.ft.convert(st[-1][2])
        opos, orn = self._get_base_pose(self.obj)
        v, w = self._get_base_velocity(self.obj)
        self._obj = (np.array(opos), np.array(orn), np.array(v), np.array(w))
        self._head_pose = None

    def arm_state(self):
        return self._q, self._qd

    def hand_state(self):
        return self._hq, self._hqd, self._htau

    def object_state(self):
        return self._obj

    def _link_point_velocity(self, link: int, point: np.ndarray) -> np.ndarray:
        if link != self._palm_link:
            return super()._link_point_velocity(link, point)
        # v + (w x (point - com)) of the palm's state read once this step (the base's
        # _frames_now), summed as np.cross's v + cross: the rig's grasp/slip checks and log
        # stay bit-identical to the array form
        (cx, cy, cz), _, _, _, _, _, (vx, vy, vz), (wx, wy, wz) = self._frames_now()[1]
        rx, ry, rz = float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz
        return np.array(
            [vx + (wy * rz - wz * ry), vy + (wz * rx - wx * rz), vz + (wx * ry - wy * rx)]
        )

    # ------------------------------------------------------------------ command
    def apply(self, command: ServoCommand) -> None:  # type: ignore[override]
        if not isinstance(command, ServoCommand):
            raise TypeError(f"the grasping rig takes ServoCommand, got {type(command).__name__}")
        if command.arm is not None:
            qd = np.asarray(command.arm, float).reshape(-1)
            if qd.shape != (self.dof,):
                raise ValueError(f"ServoCommand.arm needs {self.dof} values, got {qd.shape[0]}")
            self.arm_servos.set_command(qd if self._all_active else qd[self._act])
        if command.hand is not None:
            self.hand_servos.set_command(command.hand)
        if command.head is not None:
            self.head_servo.set_command(command.head)

    def step(self) -> None:
        self.human.drive(self._t)
        apply_torques(
            self.bc, self.robot, self._servo_j, self.arm_servos.torques(self._qd[self._act])
        )
        self.hand_servos.actuate()
        self.head_servo.step()
        self._obj_vel_before = self._obj[2]
        self.bc.stepSimulation()
        self._steps += 1
        self._t = self._steps * self.dt
        self._read()
        for i in np.flatnonzero(self._clamped & ~self._torque_episode):
            self._events.append(
                Occurrence(
                    "torque_limit",
                    {
                        "joint": self.joint_names[i],
                        "applied": float(self._tau_applied[i]),
                        "limit": float(self.torque_limits[i]),
                    },
                )
            )
        self._torque_episode = self._clamped
        self.clamp_count += int(self._clamped.sum())
        was_held = self.caught
        n_before = len(self._events)
        self._check_events()
        self._grasp_bookkeeping(was_held, n_before)

    def _grasp_bookkeeping(self, was_held: bool, n_before: int) -> None:
        pos, _, v, _ = self._obj
        for ev in self._events[n_before:]:
            if ev.kind == "grasp":
                self._grasp_start = self._t - ev.data.get("hold_time", 0.0)
                ev.data["normal_force"] = float(sum(c[9] for c in self._contacts))
                self._grasps.append({"t": self._grasp_start, "held_for": None})
            elif ev.kind == "release" and self._grasps:
                held = self._t - self._grasp_start
                self._grasps[-1]["held_for"] = held
                ev.data["held_for"] = held
        parts = {self.model.part_of_link.get(self._link_name[c[4]], "arm") for c in self._contacts}
        parts.discard("arm")
        self._touched |= parts
        self._max_parts = max(self._max_parts, len(parts))
        pe = self._tool_position()
        d = pos - pe
        if self.caught:
            if self._last_pos is not None:
                self._held_path += float(np.linalg.norm(pos - self._last_pos))
            rel = float(np.linalg.norm(v - self._link_point_velocity(self._palm_link or -1, pos)))
            # a slip episode: faster than slip_speed on the hand, over when below half of it
            if rel > self.params.slip_speed and not self._slipping:
                self._slips += 1
                self._slipping = True
                self._events.append(Occurrence("slip", {"speed": rel, "position": pos.tolist()}))
            elif self._slipping and rel < 0.5 * self.params.slip_speed:
                self._slipping = False
        else:
            self._slipping = False
            self._track_sq += float((d @ self._u) ** 2 + (d @ self._v) ** 2)
            self._track_n += 1
        self._last_pos = pos

    def _tool_position(self) -> np.ndarray:
        return np.array(self._frames_now()[0][0])

    # ------------------------------------------------------------------ verdict
    def outcome(self, t: float) -> dict:
        P = self.params
        holds = [(g["held_for"] if g["held_for"] is not None else t - g["t"]) for g in self._grasps]
        out = {
            "success": True,
            "reason": "grasped",
            "grasps": len(self._grasps),
            "first_grasp_t": self._grasps[0]["t"] if self._grasps else None,
            "hold_time": float(sum(holds)),
            "longest_hold": max(holds, default=0.0),
            "held_path": self._held_path,
            "slips": self._slips,
            "tracking_error_rms": (
                math.sqrt(self._track_sq / self._track_n) if self._track_n else None
            ),
            "hand_parts_touched": sorted(self._touched),
        }
        if not self._grasps:
            out["success"] = False
            if not self._touched:
                out["reason"] = "no grasp: the hand never touched the object"
            else:
                out["reason"] = (
                    f"no grasp: touched by {', '.join(sorted(self._touched))} "
                    f"(at most {self._max_parts} parts at once, "
                    f"{P.catch_min_parts} needed) but never held still against "
                    "the palm"
                )
        elif len(self._grasps) < P.grasp_min_grasps:
            out["success"] = False
            out["reason"] = f"only {len(self._grasps)} of {P.grasp_min_grasps} grasps"
        elif max(holds) < P.grasp_min_hold - 1e-9:
            out["success"] = False
            out["reason"] = (
                f"grasp not held: longest hold {max(holds):.3f} s < {P.grasp_min_hold:g} s"
            )
        elif self._held_path <= 1e-3:
            out["success"] = False
            out["reason"] = "held, but the object did not move while grasped"
        return out

    # ------------------------------------------------------------------ log and scene
    def _head_reading(self):
        """(R, c) of the head camera now (computed once a step: the log and the scene)."""
        if self._head_pose is None:
            self._head_pose = camera_pose(self.head, *self.head_servo.q)
        return self._head_pose

    def truth(self, t: float) -> dict:
        out = super().truth(t)
        del out["/arm/applied_torque"]
        out["/arm/servo"] = ServoState(
            t,
            list(self.joint_names),
            self._full(self.arm_servos.command),
            self._full(self.arm_servos.integral),
            self._tau_applied.tolist(),
            [bool(c) for c in self._clamped],
        )
        hs = self.head_servo
        out["/head/joint_state"] = JointState(
            t, list(HEAD_JOINTS), hs.q.tolist(), hs.qd.tolist(), hs.torque.tolist()
        )
        R, c = self._head_reading()
        out["/head/state"] = HeadState(
            t,
            float(hs.q[0]),
            float(hs.q[1]),
            hs.qd.tolist(),
            c.tolist(),
            [float(x) for x in matrix_to_quaternion(R)],
        )
        out["/human/state"] = HumanState(
            t,
            self.human.target.tolist(),
            float(self.human.roll),
            self.human.force(),
            self.human.max_force,
        )
        w = self._wrench
        out["/wrist/wrench_truth"] = Wrench(t, w[:3].tolist(), w[3:].tolist())
        return out

    def joints(self) -> tuple[list, list, list, list]:
        """The arm's and hand's joints, then the head's pan and tilt."""
        names, q, qd, effort = super().joints()
        hs = self.head_servo
        return (
            names + list(HEAD_JOINTS),
            q + hs.q.tolist(),
            qd + hs.qd.tolist(),
            effort + hs.torque.tolist(),
        )

    def frames(self) -> list[Frame]:
        """The robot's links and the head's camera (``head_camera``: x right, y down, z the
        optical axis) in ``world``."""
        R, c = self._head_reading()
        qx, qy, qz, qw = (float(x) for x in matrix_to_quaternion(R))
        x, y, z = (float(v) for v in c)
        return super().frames() + [Frame("world", "head_camera", (x, y, z), (qx, qy, qz, qw))]

    def _full(self, values) -> list:
        """Per-active-joint values as a list over every arm joint (zero where locked)."""
        if self._all_active:
            return np.asarray(values, float).tolist()
        out = np.zeros(self.dof)
        out[self._act] = values
        return out.tolist()

    def scene(self) -> Scene:
        sc = super().scene()
        hs = self.head_servo
        R, c = self._head_reading()
        sc.readings["hand"] = {
            "name": list(self.hand_names),
            "position": self._hq.tolist(),
            "velocity": self._hqd.tolist(),
        }
        sc.readings["hand_torque"] = {"name": list(self.hand_names), "torque": self._htau}
        sc.readings["head"] = {
            "name": list(HEAD_JOINTS),
            "position": hs.q.tolist(),
            "velocity": hs.qd.tolist(),
            "camera_rotation": R,
            "camera_position": c,
        }
        sc.readings["wrist"] = {"wrench": self._wrench}
        return sc
