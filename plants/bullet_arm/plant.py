"""A torque-controlled arm with a position-controlled hand and one free object, in PyBullet.

Physics only: the plant takes joint torques (arm) and joint targets (hand), steps PyBullet by a
fixed ``dt`` in DIRECT mode and reports ground truth, a camera scene, its nominal spec and
physics events (``contact``, ``catch``, ``release``, ``drop``, ``miss``, ``torque_limit``,
``velocity_limit``, ``joint_limit``, ``nan``). It knows nothing of any paper's method.

PyBullet facts used (shared/robots/README.md, measured on this machine):
- URDFs are loaded with ``URDF_USE_INERTIA_FROM_FILE`` (else inertia comes from collision shapes);
- the default joint motors are switched off (``VELOCITY_CONTROL``, force 0) for torque control,
  and ``TORQUE_CONTROL`` torques are set again before every step (PyBullet clears them);
- the tool frame is a zero-mass link; PyBullet's default link damping (0.04) is set to 0 so the
  arm follows M qdd + H qd + g = tau exactly.
"""

from __future__ import annotations

import math

import numpy as np

from plants.bullet_arm.impulse import ImpulseSchedule
from plants.bullet_arm.outcome import CatchWatch
from plants.bullet_arm.params import Params
from plants.bullet_arm.payloads import AppliedTorque, EffectorMotion, ObjectContacts
from plants.bullet_arm.quiet import quiet_c_output
from plants.bullet_arm.settings import resolve
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
from replay.spatial import matrix_to_quaternion, rpy_to_matrix
from replay.robot.wam import DEFAULT_VELOCITY_LIMIT
from replay.scene import Box, Frame, Scene, Sphere

with quiet_c_output():  # PyBullet's import prints a build banner
    import pybullet as p
    from pybullet_utils import bullet_client


class BulletArmPlant(Plant):
    Params = Params
    spec_type = ArmSpec
    command_types = (ArmCommand,)
    description = "PyBullet WAM arm (torque control) + hand (position control) + a free object"
    hold_event = "catch"  # the event kind of "held by the hand" (the grasping rig: "grasp")

    def __init__(self, params: Params, *, dt: float, rng: np.random.Generator) -> None:
        super().__init__(params, dt=dt, rng=rng)
        P = params
        S = self.settings = resolve(P)  # every default worked out (also for the viewer)
        self.dof = dof = S.dof
        self.tool_d = S.tool_d
        self.hand_table = S.hand
        q0, qd0 = S.initial_q.copy(), S.initial_qd.copy()
        self.torque_limits = S.torque_limits.copy()
        self.velocity_limits = S.velocity_limits.copy()
        names = S.joint_names
        self.locked = dict(S.locked)
        self.model = S.arm_model()
        self.urdf_path = self.model.write()
        self.joint_names = names
        self.lower, self.upper = S.lower, S.upper

        # ---- the world
        with quiet_c_output():  # connect prints "argv[0]="
            self.bc = bullet_client.BulletClient(connection_mode=p.DIRECT)
        bc = self.bc
        bc.setTimeStep(dt)
        bc.setGravity(0.0, 0.0, -P.gravity)
        bc.setPhysicsEngineParameter(
            numSolverIterations=int(P.solver_iterations), deterministicOverlappingPairs=1
        )
        orn = matrix_to_quaternion(rpy_to_matrix(P.base_rpy))
        self.robot = bc.loadURDF(
            str(self.urdf_path),
            basePosition=list(P.base_position),
            baseOrientation=list(orn),
            useFixedBase=True,
            flags=p.URDF_USE_INERTIA_FROM_FILE,
        )
        self._jidx = {}
        self._link_name = {-1: "wam_base"}
        for j in range(bc.getNumJoints(self.robot)):
            info = bc.getJointInfo(self.robot, j)
            self._jidx[info[1].decode()] = j
            self._link_name[j] = info[12].decode()
        self._link_index = {v: k for k, v in self._link_name.items()}
        # each link's parent link (-1: the base), for the link frames of 3-D viewers (frames())
        self._parent_link = [
            int(bc.getJointInfo(self.robot, j)[16]) for j in range(bc.getNumJoints(self.robot))
        ]
        self._base_pose = (tuple(float(x) for x in P.base_position), tuple(orn))
        self.active = tuple(i for i, n in enumerate(names) if n not in self.locked)
        self._arm_j = [self._jidx[names[i]] for i in self.active]
        self.hand_names = self.model.hand_joints
        self._hand_j = [self._jidx[n] for n in self.hand_names]
        # pybullet dof order (movable joints in index order) -> for calculate* helpers
        self._dofs = [
            j
            for j in range(bc.getNumJoints(self.robot))
            if bc.getJointInfo(self.robot, j)[2] == p.JOINT_REVOLUTE
        ]
        self._tool_link = self._link_index["wam_tool"]
        self._palm_link = self._link_index.get("palm")
        for j in range(-1, bc.getNumJoints(self.robot)):
            bc.changeDynamics(
                self.robot,
                j,
                linearDamping=0.0,
                angularDamping=0.0,
                lateralFriction=P.hand_lateral_friction,
                restitution=P.hand_restitution,
            )
        for k, j in enumerate(self._arm_j):
            bc.resetJointState(self.robot, j, q0[self.active[k]], qd0[self.active[k]])
        bc.setJointMotorControlArray(
            self.robot, self._arm_j, p.VELOCITY_CONTROL, forces=[0.0] * len(self._arm_j)
        )
        ht = self.hand_table
        h0 = S.hand_initial.copy()
        for j, v in zip(self._hand_j, h0):
            bc.resetJointState(self.robot, j, float(v), 0.0)
        self._hand_target = h0.copy()
        if ht is not None:
            self._hand_lo = np.array([j.lower for j in ht.joints])
            self._hand_hi = np.array([j.upper for j in ht.joints])

        # ---- the free object
        self.obj = None
        if P.object != "none":
            if P.object == "ball":
                shape = bc.createCollisionShape(p.GEOM_SPHERE, radius=P.object_radius)
            else:
                shape = bc.createCollisionShape(
                    p.GEOM_BOX, halfExtents=[s / 2 for s in P.object_size]
                )
            oorn = matrix_to_quaternion(rpy_to_matrix(P.object_rpy))
            self.obj = bc.createMultiBody(
                baseMass=P.object_mass,
                baseCollisionShapeIndex=shape,
                basePosition=list(P.object_position),
                baseOrientation=list(oorn),
            )
            kw = dict(
                linearDamping=0.0,
                angularDamping=0.0,
                lateralFriction=P.object_lateral_friction,
                rollingFriction=P.object_rolling_friction,
                spinningFriction=P.object_spinning_friction,
                restitution=P.object_restitution,
            )
            if P.contact_stiffness > 0.0:
                kw.update(contactStiffness=P.contact_stiffness, contactDamping=P.contact_damping)
            bc.changeDynamics(self.obj, -1, **kw)
            bc.resetBaseVelocity(self.obj, list(P.object_velocity), list(P.object_angular_velocity))

        # ---- command and bookkeeping
        self._tau_cmd = np.zeros(dof)
        self._tau_applied = np.zeros(dof)
        self._clamped = np.zeros(dof, dtype=bool)
        self._events: list[Occurrence] = []
        self._t = 0.0
        self._steps = 0
        self.clamp_count = 0
        self._in_contact = False
        self._hold = 0.0
        self._unhold = 0.0
        self.caught = False
        self._ever_caught = False
        self._fallen = False
        self.diverged = False
        self._vel_over = np.zeros(dof, dtype=bool)
        self._at_limit = np.zeros(dof, dtype=bool)
        self._torque_episode = np.zeros(dof, dtype=bool)
        self._obj_vel_before = (
            np.asarray(P.object_velocity, float) if self.obj is not None else np.zeros(3)
        )
        self._contacts: list = []
        self._impulses = ImpulseSchedule(P.object_impulses, dt)
        self._cache = None
        self._spec = self._make_spec(q0)
        ht = self.hand_table  # the catch verdict (outcome.py): a free object and a hand
        self._watch = (
            CatchWatch(
                kind=P.object,
                palm_radius=ht.palm_size[0]
                if ht.palm_shape == "cylinder"
                else min(ht.palm_size[:2]) / 2,
                palm_thickness=ht.palm_thickness,
            )
            if self.obj is not None and ht is not None
            else None
        )

    # ------------------------------------------------------------------ spec
    def _make_spec(self, q0: np.ndarray) -> ArmSpec:
        P = self.params
        ht = self.hand_table
        model = self.settings.chain(self._hand_target)
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
        if self.obj is not None:
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
            },
        )

    def spec(self) -> ArmSpec:
        return self._spec

    # ------------------------------------------------------------------ state
    def _state(self) -> tuple:
        """((q, qd), hand (q, qd, effort), object (pos, orn, v, w) or None), read from PyBullet
        once after each step and kept until the next one (``invalidate_state`` after changing
        the simulation other than by stepping it)."""
        if self._cache is None:
            q = np.zeros(self.dof)
            qd = np.zeros(self.dof)
            for n, v in self.locked.items():
                q[self.joint_names.index(n)] = v
            for k, st in enumerate(self.bc.getJointStates(self.robot, self._arm_j)):
                q[self.active[k]], qd[self.active[k]] = st[0], st[1]
            if self._hand_j:
                st = self.bc.getJointStates(self.robot, self._hand_j)
                hand = (
                    np.array([s[0] for s in st]),
                    np.array([s[1] for s in st]),
                    np.array([s[3] for s in st]),
                )
            else:
                hand = (np.zeros(0), np.zeros(0), np.zeros(0))
            obj = None
            if self.obj is not None:
                pos, orn = self.bc.getBasePositionAndOrientation(self.obj)
                v, w = self.bc.getBaseVelocity(self.obj)
                obj = (np.array(pos), np.array(orn), np.array(v), np.array(w))
            self._cache = ((q, qd), hand, obj)
        return self._cache

    def invalidate_state(self) -> None:
        """Forget the state read from PyBullet (after a reset* call: the next read is fresh)."""
        self._cache = None

    def arm_state(self) -> tuple[np.ndarray, np.ndarray]:
        """(q, qd) of every arm joint (locked ones at their lock value, zero speed)."""
        q, qd = self._state()[0]
        return q.copy(), qd.copy()

    def hand_state(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return tuple(a.copy() for a in self._state()[1])

    def object_state(self):
        return tuple(a.copy() for a in self._state()[2])

    def effector_state(self):
        """Tool frame: position, orientation [qx,qy,qz,qw], linear and angular velocity."""
        ls = self.bc.getLinkState(
            self.robot, self._tool_link, computeLinkVelocity=1, computeForwardKinematics=1
        )
        return np.array(ls[4]), np.array(ls[5]), np.array(ls[6]), np.array(ls[7])

    # ------------------------------------------------------------------ command
    def apply(self, command: ArmCommand) -> None:
        tau = np.asarray(command.torque, dtype=float).reshape(-1)
        if tau.shape != (self.dof,):
            raise ValueError(f"ArmCommand.torque needs {self.dof} values, got {tau.shape[0]}")
        self._tau_cmd = tau
        if command.hand is not None and self._hand_j:
            h = np.asarray(command.hand, dtype=float).reshape(-1)
            if h.shape != (len(self._hand_j),):
                raise ValueError(f"ArmCommand.hand needs {len(self._hand_j)} values")
            self._hand_target = np.clip(h, self._hand_lo, self._hand_hi)

    def _limit_torque(self, qd: np.ndarray) -> None:
        finite = np.isfinite(self._tau_cmd)
        tau = np.where(finite, self._tau_cmd, 0.0)  # a non-finite command gives no torque
        lim = self.torque_limits
        applied = np.clip(tau, -lim, lim)
        clamped = (applied != tau) | ~finite
        if self.params.enforce_velocity_limits:
            over = (np.abs(qd) >= self.velocity_limits) & (np.sign(applied) == np.sign(qd))
            over &= applied != 0.0
            applied = np.where(over, 0.0, applied)
            clamped |= over
        for n in self.locked:
            i = self.joint_names.index(n)
            applied[i] = 0.0
            clamped[i] = False
        for i in np.flatnonzero(clamped & ~self._torque_episode):
            self._events.append(
                Occurrence(
                    "torque_limit",
                    {
                        "joint": self.joint_names[i],
                        "commanded": float(tau[i]) if finite[i] else None,
                        "applied": float(applied[i]),
                        "limit": float(lim[i]),
                    },
                )
            )
        self._torque_episode = clamped
        self.clamp_count += int(clamped.sum())
        self._tau_applied, self._clamped = applied, clamped

    def step(self) -> None:
        bc = self.bc
        q, qd = self.arm_state()
        self._limit_torque(qd)
        bc.setJointMotorControlArray(
            self.robot,
            self._arm_j,
            p.TORQUE_CONTROL,
            forces=[float(self._tau_applied[i]) for i in self.active],
        )
        if self._hand_j:
            hq, _, _ = self.hand_state()
            speed = self.params.hand_closing_speed
            # rate-limited position servo: reach the target at most at the closing speed, the
            # last step landing on it (PyBullet's velocity motor is implicit, so this is stable)
            v = np.clip((self._hand_target - hq) / self.dt, -speed, speed)
            bc.setJointMotorControlArray(
                self.robot,
                self._hand_j,
                p.VELOCITY_CONTROL,
                targetVelocities=v.tolist(),
                forces=[self.params.hand_max_torque] * len(v),
            )
        if self.obj is not None:
            pos, _, v, _ = self.object_state()
            J = self._impulses.pop(self._steps) if self._impulses else None
            if J is not None:  # a scenario-set kick (impulse.py)
                v = v + J / self.params.object_mass
                bc.resetBaseVelocity(self.obj, v.tolist(), self.object_state()[3].tolist())
                self.invalidate_state()
                self._events.append(
                    Occurrence("impulse", {"impulse": J.tolist(), "velocity_after": v.tolist()})
                )
            self._obj_vel_before = v
            if not self.params.object_gravity:
                bc.applyExternalForce(
                    self.obj,
                    -1,
                    [0.0, 0.0, self.params.object_mass * self.params.gravity],
                    pos.tolist(),
                    p.WORLD_FRAME,
                )
        bc.stepSimulation()
        self._cache = None
        self._steps += 1
        self._t = self._steps * self.dt
        self._check_events()

    # ------------------------------------------------------------------ events
    def _robot_contacts(self):
        """Contact points object-robot that touch (normal force > 0 or no gap)."""
        pts = self.bc.getContactPoints(bodyA=self.obj, bodyB=self.robot)
        return [c for c in pts if c[9] > 0.0 or c[8] <= 1e-4]

    def _link_point_velocity(self, link: int, point: np.ndarray) -> np.ndarray:
        if link < 0:
            return np.zeros(3)
        ls = self.bc.getLinkState(
            self.robot, link, computeLinkVelocity=1, computeForwardKinematics=1
        )
        return np.array(ls[6]) + np.cross(np.array(ls[7]), point - np.array(ls[0]))

    def _check_events(self) -> None:
        P = self.params
        q, qd = self.arm_state()
        finite = bool(np.all(np.isfinite(q)) and np.all(np.isfinite(qd)))
        if self.obj is not None:
            pos, orn, v, w = self.object_state()
            finite = finite and bool(np.all(np.isfinite(pos)) and np.all(np.isfinite(v)))
        if not finite:
            if not self.diverged:
                self.diverged = True
                self._events.append(Occurrence("nan", {"step": self._steps}))
            return
        over = np.abs(qd) > self.velocity_limits
        for i in np.flatnonzero(over & ~self._vel_over):
            self._events.append(
                Occurrence(
                    "velocity_limit",
                    {
                        "joint": self.joint_names[i],
                        "velocity": float(qd[i]),
                        "limit": float(self.velocity_limits[i]),
                    },
                )
            )
        self._vel_over = over
        at = (q <= self.lower + 1e-3) | (q >= self.upper - 1e-3)
        for i in np.flatnonzero(at & ~self._at_limit):
            if self.joint_names[i] in self.locked:
                continue
            self._events.append(
                Occurrence(
                    "joint_limit",
                    {
                        "joint": self.joint_names[i],
                        "position": float(q[i]),
                        "lower": float(self.lower[i]),
                        "upper": float(self.upper[i]),
                    },
                )
            )
        self._at_limit = at
        if self.obj is None:
            return
        contacts = self._robot_contacts()
        self._contacts = contacts
        links = sorted({self._link_name[c[4]] for c in contacts})
        parts = sorted({self.model.part_of_link.get(l, "arm") for l in links})
        if contacts and not self._in_contact:
            c = max(contacts, key=lambda c: c[9])
            point = np.array(c[6])
            n = np.array(c[7])  # from the robot towards the object
            v_rel = self._obj_vel_before - self._link_point_velocity(c[4], point)
            self._events.append(
                Occurrence(
                    "contact",
                    {
                        "links": links,
                        "parts": parts,
                        "position": point.tolist(),
                        "speed": float(np.linalg.norm(v_rel)),
                        "normal_speed": float(-v_rel @ n),
                        "object_velocity_before": self._obj_vel_before.tolist(),
                        "object_velocity_after": v.tolist(),
                    },
                )
            )
        self._in_contact = bool(contacts)
        # caught: touching enough hand parts and moving with the palm
        hand_parts = [x for x in parts if x != "arm"]
        held = False
        if self._palm_link is not None and len(hand_parts) >= P.catch_min_parts:
            rel = v - self._link_point_velocity(self._palm_link, pos)
            held = float(np.linalg.norm(rel)) < P.catch_relative_speed
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
                        "position": pos.tolist(),
                        "hold_time": float(self._hold),
                    },
                )
            )
        if self.caught and not held and self._unhold >= P.catch_hold_time - eps:
            self.caught = False
            self._events.append(Occurrence("release", {"position": pos.tolist()}))
        if not self._fallen and pos[2] < P.miss_height:
            self._fallen = True
            kind = "drop" if self._ever_caught else "miss"
            self._events.append(
                Occurrence(kind, {"position": pos.tolist(), "velocity": v.tolist()})
            )
        if self._watch is not None:
            pe, oe, ve, we = self.effector_state()
            self._watch.observe(self._t, pos, v, pe, oe, ve, we, parts, self.caught)

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict | None:
        """Caught or not, and why, with the first touch's metrics (plants/bullet_arm/outcome.py)."""
        if self._watch is None:
            return None
        return self._watch.verdict(caught=self.caught, ever_caught=self._ever_caught)

    # ------------------------------------------------------------------ log and scene
    def truth(self, t: float) -> dict:
        q, qd = self.arm_state()
        out = {
            TOPIC_ARM_JOINT_STATE: JointState(
                t, list(self.joint_names), q.tolist(), qd.tolist(), self._tau_applied.tolist()
            ),
            TOPIC_ARM_APPLIED_TORQUE: AppliedTorque(
                t,
                list(self.joint_names),
                [float(x) if math.isfinite(x) else None for x in self._tau_cmd.tolist()],
                self._tau_applied.tolist(),
                [bool(c) for c in self._clamped],
            ),
        }
        if self._hand_j:
            hq, hqd, heff = self.hand_state()
            out[TOPIC_HAND_JOINT_STATE] = JointState(
                t, list(self.hand_names), hq.tolist(), hqd.tolist(), heff.tolist()
            )
        # the tool frame's motion; /effector/state (actual and desired point) is the controller's
        pe, oe, ve, we = self.effector_state()
        out[TOPIC_EFFECTOR_MOTION] = EffectorMotion(
            t, pe.tolist(), oe.tolist(), ve.tolist(), we.tolist(), float(np.linalg.norm(ve))
        )
        if self.obj is not None:
            pos, orn, v, w = self.object_state()
            out[TOPIC_OBJECT_STATE] = ObjectState(
                t, pos.tolist(), orn.tolist(), v.tolist(), w.tolist()
            )
            links = sorted({self._link_name[c[4]] for c in self._contacts})
            out[TOPIC_OBJECT_CONTACTS] = ObjectContacts(
                t,
                sorted({self.model.part_of_link.get(l, "arm") for l in links}),
                links,
                float(sum(c[9] for c in self._contacts)),
            )
        return out

    def robot_description(self) -> str:
        return self.model.urdf

    def frames(self) -> list[Frame]:
        """Every URDF link in its parent link (the base in ``world``): PyBullet's link frames
        (not its centre-of-mass frames), made relative to the parent's."""
        bc = self.bc
        n = len(self._parent_link)
        states = bc.getLinkStates(self.robot, list(range(n)), computeForwardKinematics=1)
        world = {-1: self._base_pose}
        out = [Frame("world", self._link_name[-1], *self._base_pose)]
        for j, st in enumerate(states):
            world[j] = (st[4], st[5])
            pp, po = world[self._parent_link[j]]
            ip, io = bc.invertTransform(pp, po)
            rp, ro = bc.multiplyTransforms(ip, io, st[4], st[5])
            out.append(Frame(self._link_name[self._parent_link[j]], self._link_name[j], rp, ro))
        return out

    def joints(self) -> tuple[list, list, list, list]:
        """The arm's joints (effort: the applied torque), then the hand's."""
        q, qd = self.arm_state()
        hq, hqd, heff = self.hand_state()
        return (
            list(self.joint_names) + list(self.hand_names),
            q.tolist() + hq.tolist(),
            qd.tolist() + hqd.tolist(),
            self._tau_applied.tolist() + heff.tolist(),
        )

    def scene(self) -> Scene:
        prims = []
        if self.obj is not None:
            pos, orn, _, _ = self.object_state()
            if self.params.object == "ball":
                prims.append(
                    Sphere(
                        "ball",
                        tuple(pos.tolist()),
                        float(self.params.object_radius),
                        float(self.params.object_albedo),
                    )
                )
            else:
                prims.append(
                    Box(
                        "box",
                        tuple(pos.tolist()),
                        tuple(orn.tolist()),
                        tuple(float(s) for s in self.params.object_size),
                        float(self.params.object_albedo),
                    )
                )
        q, qd = self.arm_state()
        encoders = {"name": list(self.joint_names), "position": q.tolist(), "velocity": qd.tolist()}
        return Scene(prims, readings={"arm": encoders})

    def close(self) -> None:
        if getattr(self, "bc", None) is not None:
            try:
                self.bc.disconnect()
            except Exception:
                pass
            self.bc = None
