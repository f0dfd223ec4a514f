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

from plants.arm_rig.arm_state import TorqueLimits, joint_state, limit_flags
from plants.arm_rig.impulse import ImpulseSchedule
from plants.arm_rig.outcome import CatchWatch
from plants.arm_rig.params import Params as ArmParams
from plants.arm_rig.payloads import AppliedTorque, EffectorMotion, ObjectContacts
from plants.bullet_arm.quiet import quiet_c_output
from plants.bullet_arm.reach import robot_reach
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
from replay.spatial import matrix_to_quaternion, rpy_to_matrix
from replay.robot.wam import DEFAULT_VELOCITY_LIMIT
from replay.scene import Box, Frame, Primitive, Scene, Sphere

from plants.bullet_arm.engine import bullet_client
from plants.bullet_arm.engine import pybullet as p


# the PyBullet calls made every step through the client (the plant, the grasp rig's helpers, the
# bench): BulletClient builds a new functools.partial (client id bound) at each attribute access,
# so the plant keeps one per name on its client (the same call)
PER_STEP_CALLS = (
    "stepSimulation",
    "setJointMotorControlArray",
    "changeConstraint",
    "getConstraintState",
)


def _vec3(values) -> tuple[float, float, float]:
    """Three numbers as a tuple of floats (a scene primitive's or a frame's position, a size)."""
    x, y, z = values
    return float(x), float(y), float(z)


def _floats(values, n: int, what: str) -> list[float]:
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


class BulletArmPlant(TorqueLimits, Plant):
    Params = ArmParams
    spec_type = ArmSpec
    command_types = (ArmCommand,)
    description = "PyBullet WAM arm (torque control) + hand (position control) + a free object"
    hold_event = "catch"  # the event kind of "held by the hand" (the grasping rig: "grasp")

    def __init__(self, params: ArmParams, *, dt: float, rng: np.random.Generator) -> None:
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
        self._lower_in, self._upper_in = self.lower + 1e-3, self.upper - 1e-3  # "at the limit"

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
        qx, qy, qz, qw = orn
        self._base_pose = (_vec3(P.base_position), (qx, qy, qz, qw))
        self._all_links = list(range(len(self._parent_link)))
        self.active = tuple(i for i, n in enumerate(names) if n not in self.locked)
        self._arm_j = [self._jidx[names[i]] for i in self.active]
        self.hand_names = self.model.hand_joints
        self._hand_j = [self._jidx[n] for n in self.hand_names]
        self._tool_link = self._link_index["wam_tool"]
        self._palm_link = self._link_index.get("palm")
        # pybullet dof order (movable joints in index order) -> for calculate* helpers
        self._dofs = [
            j
            for j in range(bc.getNumJoints(self.robot))
            if bc.getJointInfo(self.robot, j)[2] == p.JOINT_REVOLUTE
        ]
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
        self._hand_target = h0.tolist()
        # one getJointStates a step for the arm and the hand; q of the locked joints preset
        self._read_j = self._arm_j + self._hand_j
        self._na = len(self._arm_j)
        self._all_active = len(self.active) == dof  # no locked joint: no index mapping
        self._q_locked_l = [float(self.locked.get(n, 0.0)) for n in names]
        # per arm joint its read joint's index, -1 for a locked one (arm_state.joint_state)
        slot = {i: k for k, i in enumerate(self.active)}
        self._pick = tuple(slot.get(i, -1) for i in range(dof))
        # the tool frame and the palm: one getLinkStates a step (_frames_now)
        self._frame_links = [self._tool_link] + (
            [] if self._palm_link is None else [self._palm_link]
        )
        # BulletClient makes a new functools.partial on every attribute access: bind the calls
        # made every step once; those called through the client (stepSimulation: the bench
        # times it there) are kept on it as attributes
        for name in PER_STEP_CALLS:
            setattr(bc, name, getattr(bc, name))
        self._get_joint_states = bc.getJointStates
        self._get_base_pose = bc.getBasePositionAndOrientation
        self._get_base_velocity = bc.getBaseVelocity
        self._get_link_state = bc.getLinkState
        self._get_link_states = bc.getLinkStates
        self._get_contact_points = bc.getContactPoints
        self._set_motors = bc.setJointMotorControlArray
        if ht is not None:
            self._hand_lo = np.array([j.lower for j in ht.joints])
            self._hand_hi = np.array([j.upper for j in ht.joints])
            self._hand_lo_l, self._hand_hi_l = self._hand_lo.tolist(), self._hand_hi.tolist()
        self._hand_speed = float(P.hand_closing_speed)
        self._hand_forces = [float(P.hand_max_torque)] * len(self._hand_j)
        self._hand_v: list | None = None  # the hand motors' last targets (None: none set yet)

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
        # per joint in plain floats and bools (4-7 of them: lists beat arrays)
        self._tau_cmd = [0.0] * dof
        self._tau_applied = [0.0] * dof
        self._clamped = [False] * dof
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
        self._vel_over = [False] * dof  # per joint: over its speed limit / at a joint limit
        self._at_limit = [False] * dof
        self._vlim_l = self.velocity_limits.tolist()
        self._tlim_l = self.torque_limits.tolist()
        self._lower_l, self._upper_l = self._lower_in.tolist(), self._upper_in.tolist()
        self._locked_l = [n in self.locked for n in self.joint_names]
        self._enforce_vlim = bool(P.enforce_velocity_limits)
        # (the contacts list it is of, parts, links, N)
        self._contact_summary: tuple[list | None, tuple, tuple, float] = (None, (), (), 0.0)
        self._contact_key: tuple = ()  # the touching links of the last summary, and their names
        self._contact_names: tuple = ((), ())
        # the scene's primitive sizes as floats, once
        self._obj_radius = float(P.object_radius)
        self._obj_albedo = float(P.object_albedo)
        self._obj_size = _vec3(P.object_size)
        self._torque_episode = [False] * dof
        self._obj_vel_before = (
            tuple(float(x) for x in P.object_velocity) if self.obj is not None else (0.0,) * 3
        )
        self._contacts: list = []
        # beyond this distance from the base the object touches nothing of the robot (m)
        self._contact_radius = (
            robot_reach(bc, self.robot, self._base_pose[0], self._parent_link)
            + (self._obj_radius if P.object == "ball" else 0.5 * math.hypot(*self._obj_size))
            + 0.05
        )
        self._impulses = ImpulseSchedule(P.object_impulses, dt)
        self._cache: tuple | None = None
        # (step, the tool link's state): read at most once a step
        self._effector: tuple[int, tuple] | None = None
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
        """((q, qd), hand (q, qd, effort), object (pos, orn, v, w) or None) as plain floats
        (lists; the object's PyBullet tuples), read from PyBullet once after each step (one
        getJointStates for arm and hand) and kept until the next one (``invalidate_state``
        after changing the simulation other than by stepping it). Shared, never mutated: the
        accessors below give copies."""
        if self._cache is None:
            arm, hand = joint_state(
                self._get_joint_states(self.robot, self._read_j),
                self._na,
                self._pick,
                self._q_locked_l,
            )
            obj = None
            if self.obj is not None:
                pos, orn = self._get_base_pose(self.obj)
                v, w = self._get_base_velocity(self.obj)
                obj = (pos, orn, v, w)
            self._cache = (arm, hand, obj)
        return self._cache

    def invalidate_state(self) -> None:
        """Forget the state read from PyBullet (after a reset* call: the next read is fresh)."""
        self._cache = None
        self._effector = None

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
        return tuple(np.array(x) for x in self._effector_now())

    def _effector_now(self) -> tuple:
        """effector_state as PyBullet's tuples, read once a step."""
        return self._frames_now()[0]

    def _frames_now(self) -> tuple:
        """(tool (pos, orn, v, w), palm link state or None): one getLinkStates a step for the
        tool frame and the palm (the catch check's point velocity)."""
        if self._effector is None or self._effector[0] != self._steps:
            st = self._get_link_states(
                self.robot, self._frame_links, computeLinkVelocity=1, computeForwardKinematics=1
            )
            ls = st[0]
            self._effector = (
                self._steps,
                ((ls[4], ls[5], ls[6], ls[7]), st[1] if len(st) > 1 else None),
            )
        return self._effector[1]

    # ------------------------------------------------------------------ command
    def apply(self, command: ArmCommand) -> None:
        self._tau_cmd = _floats(command.torque, self.dof, "ArmCommand.torque")
        if command.hand is not None and self._hand_j:
            h = _floats(command.hand, len(self._hand_j), "ArmCommand.hand")
            # np.clip per joint in floats (NaN stays NaN, as there)
            self._hand_target = [
                min(max(x, lo), hi) for x, lo, hi in zip(h, self._hand_lo_l, self._hand_hi_l)
            ]

    def step(self) -> None:
        bc = self.bc
        (_, qd), hand, obj = self._state()
        self._limit_torque(qd)
        applied = self._tau_applied
        self._set_motors(
            self.robot,
            self._arm_j,
            p.TORQUE_CONTROL,
            forces=applied if self._all_active else [applied[i] for i in self.active],
        )
        if self._hand_j:
            speed, dt = self._hand_speed, self.dt
            # rate-limited position servo: reach the target at most at the closing speed, the
            # last step landing on it (PyBullet's velocity motor is implicit, so this is stable)
            v = [min(max((x - y) / dt, -speed), speed) for x, y in zip(self._hand_target, hand[0])]
            # PyBullet keeps a velocity motor's target and force until set again: the same
            # targets as last step (closing at full speed, at rest) need no call
            if v != self._hand_v:
                self._set_motors(
                    self.robot,
                    self._hand_j,
                    p.VELOCITY_CONTROL,
                    targetVelocities=v,
                    forces=self._hand_forces,
                )
                self._hand_v = v
        if obj is not None:
            pos, _, v, w = obj
            J = self._impulses.pop(self._steps) if self._impulses.due else None
            if J is not None:  # a scenario-set kick (impulse.py)
                v = (np.asarray(v) + J / self.params.object_mass).tolist()
                bc.resetBaseVelocity(self.obj, v, list(w))
                self.invalidate_state()
                self._events.append(
                    Occurrence("impulse", {"impulse": J.tolist(), "velocity_after": v})
                )
            self._obj_vel_before = tuple(v)
            if not self.params.object_gravity:
                bc.applyExternalForce(
                    self.obj,
                    -1,
                    [0.0, 0.0, self.params.object_mass * self.params.gravity],
                    list(pos),
                    p.WORLD_FRAME,
                )
        bc.stepSimulation()
        self._cache = None
        self._steps += 1
        self._t = self._steps * self.dt
        self._check_events()

    # ------------------------------------------------------------------ events
    def _robot_contacts(self, pos, v) -> list:
        """Contact points object-robot that touch (normal force > 0 or no gap); none while
        the object at ``pos`` (moving at ``v``) is beyond the robot's reach (reach.py) by more
        than its bounding radius, its travel in two steps and 5 cm: no point can be there (the
        points of a step are found at its start, nearer than Bullet's contact threshold)."""
        x, y, z = pos
        bx, by, bz = self._base_pose[0]
        vx, vy, vz = v
        far = self._contact_radius + 2.0 * self.dt * math.sqrt(vx * vx + vy * vy + vz * vz)
        dx, dy, dz = x - bx, y - by, z - bz
        if dx * dx + dy * dy + dz * dz > far * far:
            return []
        pts = self._get_contact_points(bodyA=self.obj, bodyB=self.robot)
        return [c for c in pts if c[9] > 0.0 or c[8] <= 1e-4]

    def _link_point_velocity(self, link: int, point) -> tuple[float, float, float]:
        """v + w x (point - link COM) of a robot link now (world), as floats."""
        if link < 0:
            return (0.0, 0.0, 0.0)
        ls = self._frames_now()[1] if link == self._palm_link else None
        if ls is None:
            ls = self._get_link_state(
                self.robot, link, computeLinkVelocity=1, computeForwardKinematics=1
            )
        (vx, vy, vz), (wx, wy, wz), (cx, cy, cz) = ls[6], ls[7], ls[0]
        rx, ry, rz = map(float, point)
        rx, ry, rz = rx - cx, ry - cy, rz - cz  # v + w x (point - link COM)
        return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx)

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
            pos, orn, v, w = obj
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
                if not self.diverged:
                    self.diverged = True
                    self._events.append(Occurrence("nan", {"step": self._steps}))
                return
            self._limit_events(ql, qdl, over, at)
        if pos is None or v is None:  # no object
            return
        contacts = self._robot_contacts(pos, v)
        self._contacts = contacts
        parts, links, _ = self._contact_summary_now()
        if contacts and not self._in_contact:
            c = max(contacts, key=lambda c: c[9])
            point = np.array(c[6])
            n = np.array(c[7])  # from the robot towards the object
            v_rel = np.subtract(self._obj_vel_before, self._link_point_velocity(c[4], point))
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
        self._in_contact = bool(contacts)
        # caught: touching enough hand parts and moving with the palm
        hand_parts = [x for x in parts if x != "arm"]
        held = False
        if self._palm_link is not None and len(hand_parts) >= P.catch_min_parts:
            px, py, pz = self._link_point_velocity(self._palm_link, pos)
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
        if not self._fallen and pos[2] < P.miss_height:
            self._fallen = True
            kind = "drop" if self._ever_caught else "miss"
            self._events.append(Occurrence(kind, {"position": list(pos), "velocity": list(v)}))
        if self._watch is not None:
            pe, oe, ve, we = self._effector_now()  # floats: faster than arrays here
            self._watch.observe(self._t, pos, v, pe, oe, ve, we, parts, self.caught)

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
        if self._hand_j:
            out[TOPIC_HAND_JOINT_STATE] = JointState(
                t, list(self.hand_names), hq[:], hqd[:], heff[:]
            )
        # the tool frame's motion; /effector/state (actual and desired point) is the controller's
        pe, oe, ve, we = self._effector_now()
        vx, vy, vz = ve
        out[TOPIC_EFFECTOR_MOTION] = EffectorMotion(
            t, list(pe), list(oe), list(ve), list(we), math.sqrt(vx * vx + vy * vy + vz * vz)
        )
        if obj is not None:
            pos, orn, v, w = obj
            out[TOPIC_OBJECT_STATE] = ObjectState(t, list(pos), list(orn), list(v), list(w))
            parts, links, force = self._contact_summary_now()
            out[TOPIC_OBJECT_CONTACTS] = ObjectContacts(t, list(parts), list(links), force)
        return out

    def robot_description(self) -> str:
        return self.model.urdf

    def frames(self) -> list[Frame]:
        """Every URDF link in its parent link (the base in ``world``): PyBullet's link frames
        (not its centre-of-mass frames), made relative to the parent's. The transform helpers
        are the module's (they need no physics client: no BulletClient partial per call)."""
        states = self._get_link_states(self.robot, self._all_links, computeForwardKinematics=1)
        world = {-1: self._base_pose}
        names, parents = self._link_name, self._parent_link
        invert, multiply = p.invertTransform, p.multiplyTransforms
        out = [Frame("world", names[-1], *self._base_pose)]
        for j, st in enumerate(states):
            world[j] = (st[4], st[5])
            parent = parents[j]
            ip, io = invert(*world[parent])
            rp, ro = multiply(ip, io, st[4], st[5])
            out.append(Frame(names[parent], names[j], rp, ro))
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

    def _contact_summary_now(self) -> tuple[tuple, tuple, float]:
        """(parts, links, total normal force) of ``_contacts`` (tuples, shared: copy them into
        a payload), summed once per list."""
        contacts = self._contacts
        if self._contact_summary[0] is not contacts:
            if contacts:
                key = tuple(c[4] for c in contacts)  # the touching links: names once per set
                if key != self._contact_key:
                    links = sorted({self._link_name[k] for k in key})
                    parts = sorted({self.model.part_of_link.get(l, "arm") for l in links})
                    self._contact_key, self._contact_names = key, (tuple(parts), tuple(links))
                parts, links = self._contact_names
                force = float(sum(c[9] for c in contacts))
                self._contact_summary = (contacts, parts, links, force)
            else:
                self._contact_summary = (contacts, (), (), 0.0)
        return self._contact_summary[1:]

    def scene(self) -> Scene:
        (q, qd), _, obj = self._state()
        prims: list[Primitive] = []
        if obj is not None:
            P = self.params
            if P.object == "ball":
                prims.append(Sphere("ball", obj[0], self._obj_radius, self._obj_albedo))
            else:
                prims.append(Box("box", obj[0], obj[1], self._obj_size, self._obj_albedo))
        encoders = {"name": list(self.joint_names), "position": q[:], "velocity": qd[:]}
        return Scene(prims, readings={"arm": encoders})

    def close(self) -> None:
        if getattr(self, "bc", None) is not None:
            try:
                self.bc.disconnect()
            except Exception:
                pass
            self.bc = None
