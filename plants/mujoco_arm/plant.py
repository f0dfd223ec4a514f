"""A torque-controlled arm with a position-controlled hand and one free object, in MuJoCo.

The same contract as the PyBullet plant (plants/bullet_arm/plant.py): the same ``Params`` (plus
MuJoCo's contact settings), commands, limits, truth topics, events (``contact``, ``catch``,
``release``, ``drop``, ``miss``, ``torque_limit``, ``velocity_limit``, ``joint_limit``, ``nan``,
``impulse``) and ``outcome`` (the same ``CatchWatch``), so a scenario differs from its PyBullet
twin only in ``plant.type``. Physics only: it knows nothing of any paper's method.

Stepping: ``mj_step2`` (actuation, constraints, integration) then ``mj_step1`` (positions,
velocities, collision at the new state): the contacts and their forces read between the two are
the step's own (as PyBullet's ``getContactPoints`` after ``stepSimulation``), and the kinematics
read after it are the new state's, at the cost of one ``mj_step``.
"""

from __future__ import annotations

import math
from typing import cast

import mujoco
import numpy as np

from plants.arm_rig.arm_state import TorqueLimits, limit_flags
from plants.arm_rig.impulse import ImpulseSchedule
from plants.arm_rig.outcome import CatchWatch
from plants.arm_rig.payloads import AppliedTorque, EffectorMotion, ObjectContacts
from plants.arm_rig.settings import resolve
from plants.mujoco_arm.params import Params as MujocoParams
from plants.mujoco_arm.world import NEAR, build_world, free_velocity
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
from replay.scene import Box, Frame, Scene, Sphere


def _xyzw(q) -> tuple[float, float, float, float]:
    w, x, y, z = q
    return (float(x), float(y), float(z), float(w))


def _index(ix: list) -> slice | list:
    """A slice for ascending consecutive addresses (MuJoCo's arrays read and write a slice
    for ~half a fancy index's cost), else the list itself."""
    if ix and ix == list(range(ix[0], ix[0] + len(ix))):
        return slice(ix[0], ix[0] + len(ix))
    return ix


def _floats(values, n: int, what: str) -> list[float]:
    """A flat list of ``n`` floats: a list or tuple of numbers by ``float()``, else NumPy's."""
    if type(values) in (list, tuple) and len(values) == n:
        try:
            return list(map(float, values))
        except (TypeError, ValueError):
            pass
    a = np.asarray(values, dtype=float).reshape(-1)
    if a.shape != (n,):
        raise ValueError(f"{what} needs {n} values, got {a.shape[0]}")
    return a.tolist()


class MujocoArmPlant(TorqueLimits, Plant):
    Params = MujocoParams
    spec_type = ArmSpec
    command_types = (ArmCommand,)
    description = "MuJoCo WAM arm (torque control) + hand (velocity servos) + a free object"
    hold_event = "catch"

    def __init__(self, params: MujocoParams, *, dt: float, rng: np.random.Generator) -> None:
        super().__init__(params, dt=dt, rng=rng)
        P = params
        S = self.settings = resolve(P)
        self.dof = S.dof
        self.tool_d = S.tool_d
        self.hand_table = ht = S.hand
        self.torque_limits = S.torque_limits.copy()
        self.velocity_limits = S.velocity_limits.copy()
        self.joint_names = S.joint_names
        self.locked = dict(S.locked)
        self.model = S.arm_model()
        self.urdf_path = self.model.write()
        self.lower, self.upper = S.lower, S.upper
        self.active = S.active
        self.hand_names = self.model.hand_joints
        W = self.world = build_world(P, S, self.model, dt)
        m, d = self.mj, self.md = W.model, W.data
        self._arm_qpos, self._arm_dof = list(W.arm_qpos), list(W.arm_dof)
        self._hand_qpos, self._hand_dof = list(W.hand_qpos), list(W.hand_dof)
        self._hand_act = list(W.hand_act)
        self._arm_dof_ix, self._hand_act_ix = _index(self._arm_dof), _index(self._hand_act)
        self._tool = W.body_names.index("wam_tool")
        self._palm = W.body_names.index("palm") if "palm" in W.body_names else -1
        self._ob = W.object_body
        # ---- the initial state
        q0, qd0 = S.initial_q, S.initial_qd
        for k, i in enumerate(self.active):
            d.qpos[W.arm_qpos[k]] = q0[i]
            d.qvel[W.arm_dof[k]] = qd0[i]
        h0 = S.hand_initial
        for a, v in zip(W.hand_qpos, h0):
            d.qpos[a] = v
        self._hand_target = [float(x) for x in h0]
        if ht is not None:
            self._hand_lo = np.array([j.lower for j in ht.joints])
            self._hand_hi = np.array([j.upper for j in ht.joints])
            self._hand_lo_l, self._hand_hi_l = self._hand_lo.tolist(), self._hand_hi.tolist()
        if self._ob >= 0:
            a, b = W.object_qpos, W.object_dof
            mujoco.mj_forward(m, d)  # the object's rotation, for its body-frame spin
            R = d.xmat[self._ob].reshape(3, 3)
            d.qvel[b : b + 6] = free_velocity(R, P.object_velocity, P.object_angular_velocity)
        mujoco.mj_forward(m, d)
        self._q_locked = [float(self.locked.get(n, 0.0)) for n in self.joint_names]
        # (arm joint index, qpos address, dof address) of each active joint
        self._arm_slots = [(i, W.arm_qpos[k], W.arm_dof[k]) for k, i in enumerate(self.active)]
        self._root = m.body_rootid.tolist()
        self._geom_body = m.geom_bodyid.tolist()
        self._motions: dict = {}  # (step, body) -> _body_motion
        # frames(): per robot body (body, parent, parent's name, its name)
        self._frame_rows = [
            (i, int(m.body_parentid[i]), W.body_names[int(m.body_parentid[i])], W.body_names[i])
            for i in range(1, m.nbody)
            if W.part_of_body[i] is not None
        ]
        self._f6 = np.zeros(6)
        # ---- bookkeeping (as the PyBullet plant's)
        dof = self.dof
        self._tau_cmd = [0.0] * dof
        self._tau_applied = [0.0] * dof
        self._clamped = [False] * dof
        self._torque_episode = [False] * dof
        self._events: list[Occurrence] = []
        self._steps = 0
        self._t = 0.0
        self.clamp_count = 0
        self._in_contact = False
        self._hold = self._unhold = 0.0
        self.caught = self._ever_caught = self._fallen = self.diverged = False
        self._vel_over = [False] * dof
        self._at_limit = [False] * dof
        self._vlim_l = self.velocity_limits.tolist()
        self._tlim_l = self.torque_limits.tolist()
        self._lower_l = (self.lower + 1e-3).tolist()  # "at the limit", as the PyBullet plant
        self._upper_l = (self.upper - 1e-3).tolist()
        self._locked_l = [n in self.locked for n in self.joint_names]
        self._enforce_vlim = bool(P.enforce_velocity_limits)
        self._hand_speed = float(P.hand_closing_speed)
        # the hand servos' torque cap (N*m) and, per joint, the torque per rad/s of speed change
        # in one step, I / dt (I: its inertia about its axis; a finger joint's link is a leaf:
        # M_ii is constant), its link's body (contacts)
        self._hand_cap = float(P.hand_max_torque)
        self._hand_i_dt = [float(m.dof_M0[i]) / dt for i in W.hand_dof]
        self._hand_body = [W.body_names.index(f"{n}_link") for n in self.hand_names]
        self._hand_capped: list | None = None
        # each hand link's geoms, the object's, and how near the palm the object must be
        # before a link can be NEAR it: the hand's size (links' geoms about the palm, bounded by
        # their bodies' bounding spheres at rest) + the object's + NEAR
        self._hand_geoms = [
            list(range(m.body_geomadr[b], m.body_geomadr[b] + m.body_geomnum[b]))
            for b in self._hand_body
        ]
        self._obj_geom = int(m.body_geomadr[self._ob]) if self._ob >= 0 else -1
        # _near_links: each hand geom, its joint, (its bounding radius + the object's + NEAR)^2
        self._near_geoms = [g for gs in self._hand_geoms for g in gs]
        self._near_joint = [k for k, gs in enumerate(self._hand_geoms) for _ in gs]
        r_obj = float(m.geom_rbound[self._obj_geom]) if self._ob >= 0 else 0.0
        self._near_lim2 = [(float(m.geom_rbound[g]) + r_obj + NEAR) ** 2 for g in self._near_geoms]
        if self._palm >= 0 and self._ob >= 0:
            ext = max(
                float(np.linalg.norm(d.geom_xpos[g] - d.xpos[self._palm])) + m.geom_rbound[g]
                for gs in self._hand_geoms
                + [[g for g in range(m.ngeom) if m.geom_bodyid[g] == self._palm]]
                for g in gs
            )
            reach = ext + float(m.geom_rbound[self._obj_geom]) + NEAR
            self._hand_reach2 = reach * reach
        self._hand_kv = float(P.hand_servo_gain)
        # MuJoCo resets the state where it diverges (a warning count): those are the "nan"
        self._bad = [
            int(w)
            for w in (
                mujoco.mjtWarning.mjWARN_BADQACC,
                mujoco.mjtWarning.mjWARN_BADQVEL,
                mujoco.mjtWarning.mjWARN_BADQPOS,
            )
        ]
        self._impulses = ImpulseSchedule(P.object_impulses, dt)
        self._obj_vel_before = tuple(float(x) for x in P.object_velocity)
        self._contacts: list = []  # (body, position, normal robot->object, normal force)
        self._cache: tuple | None = None
        self._spec = self._make_spec(q0)
        self._watch = (
            CatchWatch(
                kind=P.object,
                palm_radius=ht.palm_size[0]
                if ht.palm_shape == "cylinder"
                else min(ht.palm_size[:2]) / 2,
                palm_thickness=ht.palm_thickness,
            )
            if self._ob >= 0 and ht is not None
            else None
        )

    # ------------------------------------------------------------------ spec
    def _make_spec(self, q0: np.ndarray) -> ArmSpec:
        """The nominal description, field for field the PyBullet plant's."""
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
        if self._ob >= 0:
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
                "engine": f"mujoco {mujoco.__version__}",
            },
        )

    def spec(self) -> ArmSpec:
        return self._spec

    # ------------------------------------------------------------------ state
    def _state(self) -> tuple:
        """((q, qd), hand (q, qd, effort), object (pos, orn xyzw, v, w world) or None) as
        plain floats, read once after each step; shared, never mutated."""
        if self._cache is None:
            d = self.md
            qp, qv = d.qpos.tolist(), d.qvel.tolist()  # one read each: lists beat fancy indexing
            q, qd = self._q_locked[:], [0.0] * self.dof
            for i, a, b in self._arm_slots:
                q[i], qd[i] = qp[a], qv[b]
            hv = [qv[b] for b in self._hand_dof]
            hand = ([qp[a] for a in self._hand_qpos], hv, self._hand_effort(hv))
            obj = None
            if self._ob >= 0:
                a, b = self.world.object_qpos, self.world.object_dof
                # the free joint's spin is in the body frame: w = R w_local
                r = d.xmat[self._ob].tolist()
                lx, ly, lz = qv[b + 3 : b + 6]
                w = (
                    r[0] * lx + r[1] * ly + r[2] * lz,
                    r[3] * lx + r[4] * ly + r[5] * lz,
                    r[6] * lx + r[7] * ly + r[8] * lz,
                )
                qw, qx, qy, qz = qp[a + 3 : a + 7]
                obj = (tuple(qp[a : a + 3]), (qx, qy, qz, qw), tuple(qv[b : b + 3]), w)
            self._cache = ((q, qd), hand, obj)
        return self._cache

    def invalidate_state(self) -> None:
        """Forget the state read (after setting qpos/qvel other than by stepping)."""
        mujoco.mj_step1(self.mj, self.md)
        self._cache = None
        self._motions.clear()

    def arm_state(self) -> tuple[np.ndarray, np.ndarray]:
        q, qd = self._state()[0]
        return np.array(q), np.array(qd)

    def hand_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q, qd, effort = self._state()[1]
        return np.array(q, float), np.array(qd, float), np.array(effort, float)

    def object_state(self):
        return tuple(np.array(a) for a in self._state()[2])

    def _body_motion(self, body: int) -> tuple:
        """(position, orientation xyzw, v, w) of a body's frame (world), from MuJoCo's cvel
        (rotation; translation of the point at the subtree centre of mass of the body's root,
        moving with the body), read once a step per body."""
        key = (self._steps, body)
        got = self._motions.get(key)
        if got is not None:
            return got
        if len(self._motions) > 8:
            self._motions.clear()
        d = self.md
        wx, wy, wz, ux, uy, uz = d.cvel[body].tolist()
        px, py, pz = d.xpos[body].tolist()
        cx, cy, cz = d.subtree_com[self._root[body]].tolist()
        rx, ry, rz = px - cx, py - cy, pz - cz
        v = (ux + wy * rz - wz * ry, uy + wz * rx - wx * rz, uz + wx * ry - wy * rx)
        got = ((px, py, pz), _xyzw(d.xquat[body].tolist()), v, (wx, wy, wz))
        self._motions[key] = got
        return got

    def effector_state(self):
        """Tool frame: position, orientation [qx,qy,qz,qw], linear and angular velocity."""
        return tuple(np.array(x) for x in self._body_motion(self._tool))

    def _point_velocity(self, body: int, point) -> tuple[float, float, float]:
        """v + w x (point - body origin) of a robot body now (world)."""
        if self.world.part_of_body[body] is None:
            return (0.0, 0.0, 0.0)
        (cx, cy, cz), _, (vx, vy, vz), (wx, wy, wz) = self._body_motion(body)
        rx, ry, rz = (float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz)
        return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx)

    # ------------------------------------------------------------------ command
    def apply(self, command: ArmCommand) -> None:
        self._tau_cmd = _floats(command.torque, self.dof, "ArmCommand.torque")
        if command.hand is not None and self._hand_act:
            h = _floats(command.hand, len(self._hand_act), "ArmCommand.hand")
            self._hand_target = [
                min(max(x, lo), hi) for x, lo, hi in zip(h, self._hand_lo_l, self._hand_hi_l)
            ]

    def _hand_effort(self, v: list) -> list[float]:
        """The hand servos' torques of the last step (N*m): where clipped, MuJoCo's
        actuator_force; else the implicit step's kv (v_cmd - v after it) (actuator_force is
        then the force before the step, kv (v_cmd - v before it))."""
        if self._hand_capped is None:
            return [0.0] * len(v)
        kv, d = self._hand_kv, self.md
        ix = self._hand_act_ix
        f, u = d.actuator_force[ix].tolist(), d.ctrl[ix].tolist()
        return [a if c else kv * (x - y) for a, c, x, y in zip(f, self._hand_capped, u, v)]

    def _near_links(self) -> list[bool]:
        """Per hand joint: its link may touch the object in the coming step: a geom's bounding
        sphere within ``NEAR`` of the object's (conservative: a sphere bounds a box); asked
        only with the object near the palm."""
        n = len(self._hand_body)
        if self._ob < 0 or self._palm < 0:
            return [False] * n
        d = self.md
        x, y, z = d.xpos[self._ob].tolist()  # floats: 3-vectors cost less than arrays
        px, py, pz = d.xpos[self._palm].tolist()
        if (x - px) ** 2 + (y - py) ** 2 + (z - pz) ** 2 > self._hand_reach2:
            return [False] * n
        xpos = d.geom_xpos.tolist()  # (one list of all: a dozen geoms)
        near = [False] * n
        for g, k, lim2 in zip(self._near_geoms, self._near_joint, self._near_lim2):
            gx, gy, gz = xpos[g]
            if (gx - x) ** 2 + (gy - y) ** 2 + (gz - z) ** 2 < lim2:
                near[k] = True
        return near

    def _hand_caps(self, v_cmd: list, v: list) -> None:
        """PyBullet's hand motor is a velocity constraint whose force is capped. MuJoCo clips an
        actuator's force before its implicit step, and a clipped servo is integrated
        explicitly. So each joint's stiff servo is left unclipped (rigid, as the constraint)
        while a free finger needs less than the cap to reach ``v_cmd`` in a step (I dv / dt),
        and is clipped to the force that would (at most the cap) when it needs more or its
        link may touch the object in the coming step (``_near_links``): explicit then, with no
        overshoot. (PyBullet caps the motor in the impact's own solve; a stiff servo hitting
        the ball unclipped for a step kicks it off.)"""
        near = self._near_links()
        cap = self._hand_cap
        need = [k * abs(x - y) for x, y, k in zip(v_cmd, v, self._hand_i_dt)]
        capped = [f > cap or n for f, n in zip(need, near)]
        if capped != self._hand_capped or True in capped:
            big = 1e6 * cap
            self.mj.actuator_forcerange[self._hand_act_ix] = [
                (-min(f, cap), min(f, cap)) if c else (-big, big) for c, f in zip(capped, need)
            ]
            self._hand_capped = capped

    def step(self) -> None:
        m, d = self.mj, self.md
        (_, qd), hand, obj = self._state()
        self._limit_torque(qd)
        applied = self._tau_applied
        d.qfrc_applied[self._arm_dof_ix] = [applied[i] for i in self.active]
        if self._hand_act:
            speed, dt = self._hand_speed, self.dt
            # rate-limited position servo (as PyBullet's): reach the target at most at the
            # closing speed, the last step landing on it
            v_cmd = [
                min(max((x - y) / dt, -speed), speed) for x, y in zip(self._hand_target, hand[0])
            ]
            d.ctrl[self._hand_act_ix] = v_cmd
            self._hand_caps(v_cmd, hand[1])
        if obj is not None:
            v = obj[2]
            J = self._impulses.pop(self._steps) if self._impulses.due else None
            if J is not None:  # a scenario-set kick (plants/arm_rig/impulse.py)
                b = self.world.object_dof
                v = (np.asarray(v) + J / self.params.object_mass).tolist()
                d.qvel[b : b + 3] = v
                self.invalidate_state()
                self._events.append(
                    Occurrence("impulse", {"impulse": J.tolist(), "velocity_after": v})
                )
            self._obj_vel_before = tuple(v)
        mujoco.mj_step2(m, d)
        self._read_contacts()
        mujoco.mj_step1(m, d)
        self._cache = None
        self._steps += 1
        self._t = self._steps * self.dt
        if not self.diverged and self._warned():
            # MuJoCo found a non-finite or huge state and reset it: the run has diverged
            self.diverged = True
            self._events.append(Occurrence("nan", {"step": self._steps}))
        if self.diverged:
            return
        self._check_events()

    # ------------------------------------------------------------------ events
    def _warned(self) -> bool:
        """MuJoCo counted a bad qacc, qvel or qpos warning: every count read as one list (a
        warning struct per kind costs more than the step's own arithmetic)."""
        counts = self.md.warning.number.tolist()
        return any(counts[w] for w in self._bad)

    def _read_contacts(self) -> None:
        """The step's object-robot contacts (the robot touches nothing else) that were in its
        constraint solve (the nearer-than-margin ones are not: world.py): body, point, normal
        from the robot towards the object, normal force (N)."""
        d = self.md
        out = []
        n = d.ncon
        if n and self._ob >= 0:
            m, ob, f6 = self.mj, self._ob, self._f6
            con = d.contact
            # each array read once as a list (indexing the contact struct per item is slow)
            bodyid = self._geom_body
            g1, g2, adr = con.geom1.tolist(), con.geom2.tolist(), con.efc_address.tolist()
            pos, frame = con.pos.tolist(), con.frame.tolist()
            for i in range(n):
                b1, b2 = bodyid[g1[i]], bodyid[g2[i]]
                if ob not in (b1, b2) or adr[i] < 0:  # not in the solve: near
                    continue
                mujoco.mj_contactForce(m, d, i, f6)
                nx, ny, nz = frame[i][:3]  # from geom1 to geom2
                if b2 == ob:
                    out.append((b1, pos[i], [nx, ny, nz], float(f6[0])))
                else:
                    out.append((b2, pos[i], [-nx, -ny, -nz], float(f6[0])))
        self._contacts = out

    def _contact_summary(self) -> tuple[list, list, float]:
        """(parts, links, total normal force) of the step's contacts."""
        if not self._contacts:
            return [], [], 0.0
        W = self.world
        bodies = {c[0] for c in self._contacts}
        links = sorted(W.body_names[b] for b in bodies)
        parts = sorted({W.part_of_body[b] or "arm" for b in bodies})
        return parts, links, float(sum(c[3] for c in self._contacts))

    def _limit_events(self, ql: list, qdl: list, over: list, at: list) -> None:
        for i in range(self.dof):
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
        self._vel_over, self._at_limit = over, at

    def _check_events(self) -> None:
        """The PyBullet plant's rules (plants/bullet_arm/plant.py ``_check_events``)."""
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
        if flags is not None:
            finite, over, at = flags
            if not finite:
                if not self.diverged:
                    self.diverged = True
                    self._events.append(Occurrence("nan", {"step": self._steps}))
                return
            assert over is not None and at is not None  # finite: both lists
            self._limit_events(ql, qdl, over, at)
        if obj is None:
            return
        pos, _, v, _ = obj
        contacts = self._contacts
        parts, links, _ = self._contact_summary()
        if contacts and not self._in_contact:
            c = max(contacts, key=lambda c: c[3])
            point, n = np.array(c[1]), np.array(c[2])
            v_rel = np.subtract(self._obj_vel_before, self._point_velocity(c[0], point))
            self._events.append(
                Occurrence(
                    "contact",
                    {
                        "links": links,
                        "parts": parts,
                        "position": point.tolist(),
                        "speed": float(np.linalg.norm(v_rel)),
                        "normal_speed": float(-v_rel @ n),
                        "object_velocity_before": list(self._obj_vel_before),
                        "object_velocity_after": list(v),
                    },
                )
            )
        self._in_contact = bool(contacts)
        hand_parts = [x for x in parts if x != "arm"]
        held = False
        if self._palm >= 0 and len(hand_parts) >= P.catch_min_parts:
            px, py, pz = self._point_velocity(self._palm, pos)
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
                        "links": links,
                        "position": list(pos),
                        "hold_time": float(self._hold),
                    },
                )
            )
        if self.caught and not held and self._unhold >= P.catch_hold_time - eps:
            self.caught = False
            self._events.append(Occurrence("release", {"position": list(pos)}))
        if not self._fallen and pos[2] < P.miss_height:
            self._fallen = True
            kind = "drop" if self._ever_caught else "miss"
            self._events.append(Occurrence(kind, {"position": list(pos), "velocity": list(v)}))
        if self._watch is not None:
            pe, oe, ve, we = self._body_motion(self._tool)
            self._watch.observe(self._t, pos, v, pe, oe, ve, we, parts, self.caught)

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict | None:
        """Caught or not, and why (plants/arm_rig/outcome.py, the same judge)."""
        if self._watch is None:
            return None
        return self._watch.verdict(caught=self.caught, ever_caught=self._ever_caught)

    # ------------------------------------------------------------------ log and scene
    def truth(self, t: float) -> dict:
        (q, qd), (hq, hqd, heff), obj = self._state()
        applied = self._tau_applied
        out = {
            TOPIC_ARM_JOINT_STATE: JointState(t, list(self.joint_names), q[:], qd[:], applied[:]),
            TOPIC_ARM_APPLIED_TORQUE: AppliedTorque(
                t,
                list(self.joint_names),
                cast(list, [x if math.isfinite(x) else None for x in self._tau_cmd]),
                applied[:],
                self._clamped[:],
            ),
        }
        if self._hand_act:
            out[TOPIC_HAND_JOINT_STATE] = JointState(
                t, list(self.hand_names), hq[:], hqd[:], heff[:]
            )
        pe, oe, ve, we = self._body_motion(self._tool)
        out[TOPIC_EFFECTOR_MOTION] = EffectorMotion(
            t, list(pe), list(oe), list(ve), list(we), math.sqrt(sum(x * x for x in ve))
        )
        if obj is not None:
            pos, orn, v, w = obj
            out[TOPIC_OBJECT_STATE] = ObjectState(t, list(pos), list(orn), list(v), list(w))
            parts, links, force = self._contact_summary()
            out[TOPIC_OBJECT_CONTACTS] = ObjectContacts(t, parts, links, force)
        return out

    def robot_description(self) -> str:
        return self.model.urdf

    def frames(self) -> list[Frame]:
        """Every URDF link (a body of the same name) in its parent link, the base in ``world``
        (the robot's bodies; the free object is the scene's), in plain floats."""
        d = self.md
        X, R, Q = d.xpos.tolist(), d.xmat.tolist(), d.xquat.tolist()
        out = []
        for b, p, pn, bn in self._frame_rows:
            (px, py, pz), r = X[p], R[p]
            x, y, z = X[b][0] - px, X[b][1] - py, X[b][2] - pz
            w1, x1, y1, z1 = Q[p]
            x1, y1, z1 = -x1, -y1, -z1  # the parent's conjugate times the child's (wxyz)
            w2, x2, y2, z2 = Q[b]
            out.append(
                Frame(
                    pn,
                    bn,
                    (  # R_p^T (x_b - x_p)
                        r[0] * x + r[3] * y + r[6] * z,
                        r[1] * x + r[4] * y + r[7] * z,
                        r[2] * x + r[5] * y + r[8] * z,
                    ),
                    (
                        w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                        w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
                        w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
                        w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
                    ),
                )
            )
        return out

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
        prims: list = []
        if obj is not None:
            P = self.params
            if P.object == "ball":
                prims.append(Sphere("ball", obj[0], float(P.object_radius), P.object_albedo))
            else:
                sx, sy, sz = (float(s) for s in P.object_size)
                prims.append(Box("box", obj[0], obj[1], (sx, sy, sz), P.object_albedo))
        encoders = {"name": list(self.joint_names), "position": q[:], "velocity": qd[:]}
        return Scene(prims, readings={"arm": encoders})
