"""The arm rig, engine-free: a torque-controlled arm, a position-controlled hand and one free
object, as every physics engine's plant shares it.

``ArmRig`` owns what does not depend on the engine, once: the resolved settings, the nominal
spec, the torque limiting, the command, the truth topics, the events (``contact``, ``catch``,
``release``, ``drop``, ``miss``, ``torque_limit``, ``velocity_limit``, ``joint_limit``, ``nan``,
``impulse``), the catch verdict (``outcome``) and the camera scene. It owns one engine adapter
(``engine``, engine.py ``EngineAdapter``: the world, built from the rig's public attributes,
answering the engine questions); an engine's plant (``plants.bullet_arm``, ``plants.mujoco_arm``)
names its adapter class (``Engine``).
"""

from __future__ import annotations

import math
from typing import ClassVar
import numpy as np

from plants.arm_rig.engine import EngineAdapter, adapter_class, own_engine_settings
from plants.arm_rig.arm_state import limit_flags, limit_torque, torque_limit_events
from plants.arm_rig.impulse import ImpulseSchedule
from plants.arm_rig.outcome import CatchWatch
from plants.arm_rig.params import Params as ArmParams
from plants.arm_rig.payloads import AppliedTorque, EffectorMotion, ObjectContacts
from plants.arm_rig.settings import resolve
from replay.interfaces import Occurrence, Plant
from replay.messages import (
    TOPIC_ARM_APPLIED_TORQUE,
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_MOTION,
    TOPIC_HAND_JOINT_STATE,
    TOPIC_OBJECT_CONTACTS,
    TOPIC_OBJECT_STATE,
    JointState,
    ObjectState,
)
from replay.robot.arm_types import ArmCommand, ArmSpec, HandSpec, ObjectSpec
from replay.robot.hand import hand_mass
from replay.robot.wam import DEFAULT_VELOCITY_LIMIT
from replay.scene import Box, Frame, Primitive, Scene, Sphere


def floats(values, n: int, what: str) -> list[float]:
    """``np.asarray(values, dtype=float).reshape(-1).tolist()`` of ``n`` values: a flat list or
    tuple of numbers by ``float()`` (the same doubles, no array made a step), else NumPy's."""
    if type(values) in (list, tuple) and len(values) == n:
        try:
            return list(map(float, values))
        except (TypeError, ValueError):
            pass  # nested or odd entries: NumPy decides
    a = np.asarray(values, dtype=float).reshape(-1)
    if a.shape != (n,):
        raise ValueError(f"{what} needs {n} values, got {a.shape[0]}")
    return a.tolist()


def _vec3(values) -> tuple[float, float, float]:
    x, y, z = values
    return float(x), float(y), float(z)


class ArmRig(Plant):
    Params: ClassVar[type] = ArmParams
    description = (
        "the arm rig: a WAM arm (torque control), a hand and a free object, on the physics "
        "engine plant.params.engine names (PyBullet where it is empty)"
    )
    spec_type = ArmSpec
    command_types = (ArmCommand,)
    hold_event = "catch"  # the event kind of "held by the hand" (the grasping rig: "grasp")

    def __init__(self, params: ArmParams, *, dt: float, rng: np.random.Generator) -> None:
        super().__init__(params, dt=dt, rng=rng)
        P = params
        S = self.settings = resolve(P)  # every default worked out (also for the viewer)
        self.dof = dof = S.dof
        self.tool_d = S.tool_d
        self.hand_table = ht = S.hand
        self.torque_limits = S.torque_limits.copy()
        self.velocity_limits = S.velocity_limits.copy()
        self.joint_names = S.joint_names
        self.locked = dict(S.locked)
        self.active = S.active
        self._all_active = len(self.active) == dof  # no locked joint: no index mapping
        self.model = S.arm_model()
        self.urdf_path = self.model.write()
        self.hand_names = self.model.hand_joints
        self.lower, self.upper = S.lower, S.upper
        self._hand_target = S.hand_initial.tolist()
        if ht is not None:
            self._hand_lo = np.array([j.lower for j in ht.joints])
            self._hand_hi = np.array([j.upper for j in ht.joints])
            self._hand_lo_l, self._hand_hi_l = self._hand_lo.tolist(), self._hand_hi.tolist()
        # per joint in plain floats and bools (4-7 of them: lists beat arrays)
        self._tau_cmd = [0.0] * dof
        self._tau_applied = [0.0] * dof
        self._clamped = [False] * dof
        self._torque_episode = [False] * dof
        self._vel_over = [False] * dof  # per joint: over its speed limit / at a joint limit
        self._at_limit = [False] * dof
        self._vlim_l = self.velocity_limits.tolist()
        self._tlim_l = self.torque_limits.tolist()
        self._lower_l = (self.lower + 1e-3).tolist()  # "at the limit"
        self._upper_l = (self.upper - 1e-3).tolist()
        self._locked_l = [n in self.locked for n in self.joint_names]
        self._enforce_vlim = bool(P.enforce_velocity_limits)
        self._hand_speed = float(P.hand_closing_speed)
        self._events: list[Occurrence] = []
        self._t = 0.0
        self._steps = 0
        self.clamp_count = 0
        self._in_contact = False
        self._hold = self._unhold = 0.0
        self.caught = self._ever_caught = self._fallen = self.diverged = False
        self._has_object = P.object != "none"
        self._obj_vel_before = (
            tuple(float(x) for x in P.object_velocity) if self._has_object else (0.0,) * 3
        )
        # the scene's primitive sizes as floats, once
        self._obj_radius = float(P.object_radius)
        self._obj_albedo = float(P.object_albedo)
        self._obj_size = _vec3(P.object_size)
        self._impulses = ImpulseSchedule(P.object_impulses, dt)
        # the world, from the public state above: the engine field's adapter, else the one an
        # old log's plant type names (``Engine``), else the params' own engine's
        E = P.engine_settings if P.engine_settings is not None else own_engine_settings(type(self))
        Engine = adapter_class(E, self.engine_role) if E is not None else self.Engine
        assert Engine is not None
        self.engine: EngineAdapter = Engine(self)
        self._spec = self._make_spec(S.initial_q.copy())
        self._watch = (  # the catch verdict (outcome.py): a free object and a hand
            CatchWatch(
                kind=P.object,
                palm_radius=ht.palm_size[0]
                if ht.palm_shape == "cylinder"
                else min(ht.palm_size[:2]) / 2,
                palm_thickness=ht.palm_thickness,
            )
            if self._has_object and ht is not None
            else None
        )

    # ------------------------------------------------------------------ the engine
    # an old plant type's fixed adapter class (engine.py ``EngineAdapter``; mujoco_arm's), else
    # None: the engine the params name
    Engine: type | None = None
    engine_role = "arm"  # which of an engine's adapters the rig takes (engine.py)

    def _state(self) -> tuple:
        """The engine's state (engine.py ``EngineAdapter.state``): the one read the grasping rig
        widens with its servos' torques."""
        return self.engine.state()

    def invalidate_state(self) -> None:
        """Forget the state read (after setting the simulation other than by stepping it)."""
        self.engine.invalidate_state()

    def frames(self) -> list[Frame]:
        return self.engine.frames()

    def close(self) -> None:
        if getattr(self, "engine", None) is not None:  # None: the rig's __init__ failed first
            self.engine.close()

    # ------------------------------------------------------------------ spec
    def _make_spec(self, q0: np.ndarray) -> ArmSpec:
        P = self.params
        ht = self.hand_table
        model = self.settings.chain(np.asarray(self._hand_target, float))
        hand = None
        if ht is not None:
            hand = HandSpec(
                name=ht.name,
                joint_names=ht.joint_names,
                lower=self._hand_lo,
                upper=self._hand_hi,
                open_posture=ht.open_posture,
                closed_posture=ht.closed_posture,
                closing_speed=float(P.hand_closing_speed),
                max_torque=float(P.hand_max_torque),
                mass=hand_mass(ht),
                table=ht,
            )
        obj = None
        if self._has_object:
            obj = ObjectSpec(
                kind=P.object,
                mass=float(P.object_mass),
                radius=float(P.object_radius) if P.object == "ball" else 0.0,
                size=tuple(P.object_size) if P.object == "box" else (0.0, 0.0, 0.0),
            )
        return ArmSpec(
            name=P.arm,
            joint_names=self.joint_names,
            lower=self.lower,
            upper=self.upper,
            torque_limits=self.torque_limits.copy(),
            velocity_limits=self.velocity_limits.copy(),
            locked_joints=tuple(self.locked),
            initial_q=q0.copy(),
            model=model,
            tool=model.tool.copy(),
            hand=hand,
            object=obj,
            gravity=float(P.gravity),
            dt=self.dt,
            notes={
                "torque_limits": P.torque_limit_set if not P.torque_limits else "scenario",
                "velocity_limits": "scenario"
                if P.velocity_limits
                else f"assumed {DEFAULT_VELOCITY_LIMIT} rad/s (no table source)",
                "hand": ht.note if ht else "",
                "urdf": str(self.urdf_path),
                **self.engine.notes(),
            },
        )

    def spec(self) -> ArmSpec:
        return self._spec

    # ------------------------------------------------------------------ state
    def arm_state(self) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) of every arm joint (locked ones at their lock value, zero speed)."""
        q, qd = self._state()[0]
        return np.array(q), np.array(qd)

    def hand_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q, qd, effort = self._state()[1]
        return np.array(q, dtype=float), np.array(qd, dtype=float), np.array(effort, dtype=float)

    def object_state(self):
        return tuple(np.array(a) for a in self._state()[2])

    def effector_state(self):
        """Tool frame: position, orientation [qx,qy,qz,qw], linear and angular velocity (read
        once a step, like the joint state)."""
        return tuple(np.array(x) for x in self.engine.effector_now())

    # ------------------------------------------------------------------ command
    def apply(self, command: ArmCommand) -> None:
        self._tau_cmd = floats(command.torque, self.dof, "ArmCommand.torque")
        if command.hand is not None and self.hand_names:
            h = floats(command.hand, len(self.hand_names), "ArmCommand.hand")
            # np.clip per joint in floats (NaN stays NaN, as there)
            self._hand_target = [
                min(max(x, lo), hi) for x, lo, hi in zip(h, self._hand_lo_l, self._hand_hi_l)
            ]

    def _limit_torque(self, qdl: list) -> None:
        """The command ``_tau_cmd`` becomes ``_tau_applied`` and ``_clamped`` (arm_state's
        ``limit_torque``), with a ``torque_limit`` event per joint clamped anew."""
        cmd = self._tau_cmd
        applied, clamped = limit_torque(
            cmd, self._tlim_l, self._locked_l, self._enforce_vlim, self._vlim_l, qdl
        )
        self._tau_applied = applied
        self._torque_events(cmd, applied, clamped)

    def _torque_events(self, cmd: list | None, applied: list, clamped: list) -> None:
        """The step's torques ``applied`` (``clamped`` per joint; ``cmd`` the commanded ones,
        None where the servos' own): a ``torque_limit`` event per joint clamped anew (arm_state's
        ``torque_limit_events``), counted."""
        if True in clamped:
            self._events += torque_limit_events(
                clamped, self._torque_episode, cmd, applied, self.joint_names, self._tlim_l
            )
            self.clamp_count += sum(clamped)
        self._clamped = self._torque_episode = clamped

    def _kick(self, obj: tuple) -> None:
        """Before a step: the object's scenario-set kick due now (impulse.py), and its velocity
        before the step (the contact event's)."""
        v = obj[2]
        J = self._impulses.pop(self._steps) if self._impulses.due else None
        if J is not None:
            v = (np.asarray(v) + J / self.params.object_mass).tolist()
            self.engine.set_object_velocity(v, obj[3])
            self.invalidate_state()
            self._events.append(Occurrence("impulse", {"impulse": J.tolist(), "velocity_after": v}))
        self._obj_vel_before = tuple(v)

    def step(self) -> None:
        (_, qd), hand, obj = self._state()
        self._limit_torque(qd)
        applied = self._tau_applied
        self.engine.apply_torques(
            applied if self._all_active else [applied[i] for i in self.active]
        )
        if self.hand_names:
            speed, dt = self._hand_speed, self.dt
            # rate-limited position servo: reach the target at most at the closing speed, the
            # last step landing on it
            v = [min(max((x - y) / dt, -speed), speed) for x, y in zip(self._hand_target, hand[0])]
            self.engine.drive_hand(v, hand[1])
        if obj is not None:
            self._kick(obj)
            self.engine.hold_object(obj)
        diverged = self.engine.advance()
        self._steps += 1
        self._t = self._steps * self.dt
        if diverged:
            self._diverge()
            return
        self._check_events()

    # ------------------------------------------------------------------ events
    def _diverge(self) -> None:
        """The run has diverged: one ``nan`` event."""
        if not self.diverged:
            self.diverged = True
            self._events.append(Occurrence("nan", {"step": self._steps}))

    def _limit_events(self, ql: list, qdl: list, over: list, at: list) -> None:
        """velocity_limit and joint_limit events of the joints whose flags rose this step."""
        for i in range(self.dof) if over != self._vel_over else ():
            if over[i] and not self._vel_over[i]:
                self._events.append(
                    Occurrence(
                        "velocity_limit",
                        {
                            "joint": self.joint_names[i],
                            "velocity": qdl[i],
                            "limit": self._vlim_l[i],
                        },
                    )
                )
        self._vel_over = over
        for i in range(self.dof) if at != self._at_limit else ():
            if at[i] and not self._at_limit[i] and not self._locked_l[i]:
                self._events.append(
                    Occurrence(
                        "joint_limit",
                        {
                            "joint": self.joint_names[i],
                            "position": ql[i],
                            "lower": float(self.lower[i]),
                            "upper": float(self.upper[i]),
                        },
                    )
                )
        self._at_limit = at

    def _check_events(self) -> None:
        P = self.params
        (ql, qdl), _, obj = self._state()
        pos = v = None
        if obj is not None:
            pos, _, v, _ = obj
        flags = limit_flags(
            ql,
            qdl,
            pos,
            v,
            self._vlim_l,
            self._lower_l,
            self._upper_l,
            self._vel_over,
            self._at_limit,
        )
        if flags is not None:  # not finite, or a joint's limit flags changed
            finite, over, at = flags
            if not finite:
                self._diverge()
                return
            assert over is not None and at is not None  # finite: both lists
            self._limit_events(ql, qdl, over, at)
        if pos is None or v is None:  # no object
            return
        contacts = self.engine.object_contacts(pos, v)
        parts, links, _ = self.engine.contact_summary()
        if contacts and not self._in_contact:
            self._contact_event(contacts, parts, links, v)
        self._in_contact = bool(contacts)
        self._hold_events(parts, links, pos, v)
        if not self._fallen and pos[2] < P.miss_height:
            self._fallen = True
            kind = "drop" if self._ever_caught else "miss"
            self._events.append(Occurrence(kind, {"position": list(pos), "velocity": list(v)}))
        if self._watch is not None:
            pe, oe, ve, we = self.engine.effector_now()  # floats: faster than arrays here
            self._watch.observe(self._t, pos, v, pe, oe, ve, we, parts, self.caught)

    def _contact_event(self, contacts: list, parts, links, v) -> None:
        """The ``contact`` event of the first touch: where, and how fast relative to the robot."""
        link, point, normal = self.engine.touch(contacts)
        point = np.array(point)
        n = np.array(normal)  # from the robot towards the object
        v_rel = np.subtract(self._obj_vel_before, self.engine.point_velocity(link, point))
        self._events.append(
            Occurrence(
                "contact",
                {
                    "links": list(links),
                    "parts": list(parts),
                    "position": point.tolist(),
                    "speed": float(np.linalg.norm(v_rel)),
                    "normal_speed": float(-v_rel @ n),
                    "object_velocity_before": list(self._obj_vel_before),
                    "object_velocity_after": list(v),
                },
            )
        )

    def _hold_events(self, parts, links, pos, v) -> None:
        """``catch`` (the rig's hold event) and ``release``: held while touching enough hand
        parts and moving with the palm for ``catch_hold_time``."""
        P = self.params
        hand_parts = [x for x in parts if x != "arm"]
        held = False
        if self.engine.palm_id is not None and len(hand_parts) >= P.catch_min_parts:
            px, py, pz = self.engine.point_velocity(self.engine.palm_id, pos)
            dx, dy, dz = v[0] - px, v[1] - py, v[2] - pz
            held = math.sqrt(dx * dx + dy * dy + dz * dz) < P.catch_relative_speed
        if held:
            self._hold += self.dt
            self._unhold = 0.0
        else:
            self._hold = 0.0
            self._unhold += self.dt
        eps = 1e-9
        if held and not self.caught and self._hold >= P.catch_hold_time - eps:
            self.caught = self._ever_caught = True
            self._events.append(
                Occurrence(
                    self.hold_event,
                    {
                        "parts": hand_parts,
                        "links": list(links),
                        "position": list(pos),
                        "hold_time": float(self._hold),
                    },
                )
            )
        if self.caught and not held and self._unhold >= P.catch_hold_time - eps:
            self.caught = False
            self._events.append(Occurrence("release", {"position": list(pos)}))

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict | None:
        """Caught or not, and why, with the first touch's metrics (plants/arm_rig/outcome.py)."""
        if self._watch is None:
            return None
        return self._watch.verdict(caught=self.caught, ever_caught=self._ever_caught)

    # ------------------------------------------------------------------ log and scene
    def truth(self, t: float) -> dict:
        (q, qd), (hq, hqd, heff), obj = self._state()
        applied = self._tau_applied
        isfinite = math.isfinite
        out = {
            TOPIC_ARM_JOINT_STATE: JointState(t, list(self.joint_names), q[:], qd[:], applied[:]),
            TOPIC_ARM_APPLIED_TORQUE: AppliedTorque(
                t,
                list(self.joint_names),
                [x if isfinite(x) else None for x in self._tau_cmd],
                applied[:],
                self._clamped[:],
            ),
        }
        if self.hand_names:
            out[TOPIC_HAND_JOINT_STATE] = JointState(
                t, list(self.hand_names), hq[:], hqd[:], heff[:]
            )
        # the tool frame's motion; /effector/state (actual and desired point) is the controller's
        pe, oe, ve, we = self.engine.effector_now()
        vx, vy, vz = ve
        out[TOPIC_EFFECTOR_MOTION] = EffectorMotion(
            t, list(pe), list(oe), list(ve), list(we), math.sqrt(vx * vx + vy * vy + vz * vz)
        )
        if obj is not None:
            pos, orn, v, w = obj
            out[TOPIC_OBJECT_STATE] = ObjectState(t, list(pos), list(orn), list(v), list(w))
            parts, links, force = self.engine.contact_summary()
            out[TOPIC_OBJECT_CONTACTS] = ObjectContacts(t, list(parts), list(links), force)
        return out

    def robot_description(self) -> str:
        return self.model.urdf

    def joints(self) -> tuple[list, list, list, list]:
        """The arm's joints (effort: the applied torque), then the hand's."""
        (q, qd), (hq, hqd, heff), _ = self._state()
        return (
            list(self.joint_names) + list(self.hand_names),
            q + hq,
            qd + hqd,
            self._tau_applied + heff,
        )

    def scene(self) -> Scene:
        (q, qd), _, obj = self._state()
        prims: list[Primitive] = []
        if obj is not None:
            if self.params.object == "ball":
                prims.append(Sphere("ball", obj[0], self._obj_radius, self._obj_albedo))
            else:
                prims.append(Box("box", obj[0], obj[1], self._obj_size, self._obj_albedo))
        encoders = {"name": list(self.joint_names), "position": q[:], "velocity": qd[:]}
        return Scene(prims, readings={"arm": encoders})
