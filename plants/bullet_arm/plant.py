"""A torque-controlled arm with a position-controlled hand and one free object, in PyBullet.

The engine-free arm rig (plants/arm_rig/rig.py ``ArmRig``: spec, torque limits, truth topics,
events, outcome, scene) owning a ``PybulletEngine`` (the adapter of plants/arm_rig/engine.py):
the adapter builds the world, steps PyBullet by a fixed ``dt`` in DIRECT mode and answers the
rig's engine questions (state, tool frame, point velocities, contacts, the object's velocity,
link frames). It knows nothing of any paper's method.

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

from plants.arm_rig.arm_state import joint_state
from plants.arm_rig.rig import ArmRig
from plants.bullet_arm.quiet import quiet_c_output
from plants.bullet_arm.reach import robot_reach
from plants.bullet_arm.settings import PybulletSettings
from replay.scene import Frame
from replay.spatial import matrix_to_quaternion, rpy_to_matrix

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


class PybulletEngine:
    """The rig's engine in PyBullet (plants/arm_rig/engine.py ``EngineAdapter``), built from the
    rig's public attributes (``rig``: its params, settings, model, URDF, dt and joints) and its
    engine settings (``params.engine_settings``: ``PybulletSettings``, their defaults where the
    scenario names no engine)."""

    def __init__(self, rig: ArmRig) -> None:
        P, S, dt = rig.params, rig.settings, rig.dt
        E = P.engine_settings or PybulletSettings()
        self.params, self.dt, self.model = P, dt, rig.model
        dof, names, self.active = rig.dof, rig.joint_names, rig.active
        self.hand_names, self.hand_table = rig.hand_names, rig.hand_table
        q0, qd0 = S.initial_q, S.initial_qd
        self._steps = 0  # steps advanced (the tool frame's read: once a step)
        self._cache: tuple | None = None  # the state read this step (state)
        self.contacts: list = []  # the object-robot contact rows of the step (object_contacts)

        # ---- the world
        with quiet_c_output():  # connect prints "argv[0]="
            self.bc = bullet_client.BulletClient(connection_mode=p.DIRECT)
        bc = self.bc
        bc.setTimeStep(dt)
        bc.setGravity(0.0, 0.0, -P.gravity)
        bc.setPhysicsEngineParameter(
            numSolverIterations=int(E.solver_iterations), deterministicOverlappingPairs=1
        )
        orn = matrix_to_quaternion(rpy_to_matrix(P.base_rpy))
        self.robot = bc.loadURDF(
            str(rig.urdf_path),
            basePosition=list(P.base_position),
            baseOrientation=list(orn),
            useFixedBase=True,
            flags=p.URDF_USE_INERTIA_FROM_FILE,
        )
        self._index_links(bc, P, names)
        for j in range(-1, bc.getNumJoints(self.robot)):
            bc.changeDynamics(
                self.robot,
                j,
                linearDamping=0.0,
                angularDamping=0.0,
                lateralFriction=P.hand_lateral_friction,
                restitution=E.hand_restitution,
            )
        for k, j in enumerate(self.arm_j):
            bc.resetJointState(self.robot, j, q0[self.active[k]], qd0[self.active[k]])
        bc.setJointMotorControlArray(
            self.robot, self.arm_j, p.VELOCITY_CONTROL, forces=[0.0] * len(self.arm_j)
        )
        for j, v in zip(self.hand_j, S.hand_initial):
            bc.resetJointState(self.robot, j, float(v), 0.0)
        # one getJointStates a step for the arm and the hand; q of the locked joints preset
        self._read_j = self.arm_j + self.hand_j
        self.na = len(self.arm_j)
        self.q_locked_l = [float(rig.locked.get(n, 0.0)) for n in names]
        # per arm joint its read joint's index, -1 for a locked one (arm_state.joint_state)
        slot = {i: k for k, i in enumerate(self.active)}
        self.pick = tuple(slot.get(i, -1) for i in range(dof))
        # the tool frame and the palm: one getLinkStates a step (frames_now)
        self._frame_links = [self.tool_link] + ([] if self.palm_link is None else [self.palm_link])
        self._bind_calls(bc)
        self._hand_forces = [float(P.hand_max_torque)] * len(self.hand_j)
        self._hand_v: list | None = None  # the hand motors' last targets (None: none set yet)

        # ---- the free object
        self.obj = self._make_object(bc, P, E)

        # ---- bookkeeping
        # (the contacts list it is of, parts, links, N)
        self._contact_summary: tuple[list | None, tuple, tuple, float] = (None, (), (), 0.0)
        self._contact_key: tuple = ()  # the touching links of the last summary, and their names
        self._contact_names: tuple = ((), ())
        # beyond this distance from the base the object touches nothing of the robot (m)
        self._contact_radius = (
            robot_reach(bc, self.robot, self._base_pose[0], self._parent_link)
            + (P.object_radius if P.object == "ball" else 0.5 * math.hypot(*P.object_size))
            + 0.05
        )
        # (step, the tool link's state): read at most once a step
        self._effector: tuple[int, tuple] | None = None

    def _index_links(self, bc, P, names) -> None:
        """The robot's joints and links by name and index, its base pose, the arm's and the
        hand's joints, the tool and palm links and PyBullet's dof order."""
        orn = matrix_to_quaternion(rpy_to_matrix(P.base_rpy))
        self.jidx = {}
        self._link_name = {-1: "wam_base"}
        for j in range(bc.getNumJoints(self.robot)):
            info = bc.getJointInfo(self.robot, j)
            self.jidx[info[1].decode()] = j
            self._link_name[j] = info[12].decode()
        self._link_index = {v: k for k, v in self._link_name.items()}
        # each link's parent link (-1: the base), for the link frames of 3-D viewers (frames())
        self._parent_link = [
            int(bc.getJointInfo(self.robot, j)[16]) for j in range(bc.getNumJoints(self.robot))
        ]
        qx, qy, qz, qw = orn
        bx, by, bz = P.base_position
        self._base_pose = ((float(bx), float(by), float(bz)), (qx, qy, qz, qw))
        self._all_links = list(range(len(self._parent_link)))
        self.arm_j = [self.jidx[names[i]] for i in self.active]
        self.hand_j = [self.jidx[n] for n in self.hand_names]
        self.tool_link = self._link_index["wam_tool"]
        self.palm_link = self.palm_id = self._link_index.get("palm")
        # pybullet dof order (movable joints in index order) -> for calculate* helpers
        self.dofs = [
            j
            for j in range(bc.getNumJoints(self.robot))
            if bc.getJointInfo(self.robot, j)[2] == p.JOINT_REVOLUTE
        ]

    def _bind_calls(self, bc) -> None:
        """BulletClient makes a new functools.partial on every attribute access: the calls made
        every step bound once; those called through the client (stepSimulation: the bench
        times it there) are kept on it as attributes."""
        for name in PER_STEP_CALLS:
            setattr(bc, name, getattr(bc, name))
        self.get_joint_states = bc.getJointStates
        self.get_base_pose = bc.getBasePositionAndOrientation
        self.get_base_velocity = bc.getBaseVelocity
        self._get_link_state = bc.getLinkState
        self._get_link_states = bc.getLinkStates
        self._get_contact_points = bc.getContactPoints
        self.set_motors = bc.setJointMotorControlArray

    def _make_object(self, bc, P, E: PybulletSettings):
        """The free object (a ball or a box) with its contact settings and initial velocity;
        None when the scenario has none."""
        if P.object == "none":
            return None
        if P.object == "ball":
            shape = bc.createCollisionShape(p.GEOM_SPHERE, radius=P.object_radius)
        else:
            shape = bc.createCollisionShape(p.GEOM_BOX, halfExtents=[s / 2 for s in P.object_size])
        oorn = matrix_to_quaternion(rpy_to_matrix(P.object_rpy))
        obj = bc.createMultiBody(
            baseMass=P.object_mass,
            baseCollisionShapeIndex=shape,
            basePosition=list(P.object_position),
            baseOrientation=list(oorn),
        )
        kw = dict(
            linearDamping=0.0,
            angularDamping=0.0,
            lateralFriction=P.object_lateral_friction,
            rollingFriction=E.object_rolling_friction,
            spinningFriction=E.object_spinning_friction,
            restitution=E.object_restitution,
        )
        if E.contact_stiffness > 0.0:
            kw.update(contactStiffness=E.contact_stiffness, contactDamping=E.contact_damping)
        bc.changeDynamics(obj, -1, **kw)
        bc.resetBaseVelocity(obj, list(P.object_velocity), list(P.object_angular_velocity))
        return obj

    # ------------------------------------------------------------------ state
    def state(self) -> tuple:
        """((q, qd), hand (q, qd, effort), object (pos, orn, v, w) or None) as plain floats
        (lists; the object's PyBullet tuples), read from PyBullet once after each step (one
        getJointStates for arm and hand) and kept until the next one (``invalidate_state``
        after changing the simulation other than by stepping it). Shared, never mutated: the
        accessors below give copies."""
        if self._cache is None:
            arm, hand = joint_state(
                self.get_joint_states(self.robot, self._read_j),
                self.na,
                self.pick,
                self.q_locked_l,
            )
            obj = None
            if self.obj is not None:
                pos, orn = self.get_base_pose(self.obj)
                v, w = self.get_base_velocity(self.obj)
                obj = (pos, orn, v, w)
            self._cache = (arm, hand, obj)
        return self._cache

    def invalidate_state(self) -> None:
        """Forget the state read from PyBullet (after a reset* call: the next read is fresh)."""
        self._cache = None
        self._effector = None

    def effector_now(self) -> tuple:
        """effector_state as PyBullet's tuples, read once a step."""
        return self.frames_now()[0]

    def frames_now(self) -> tuple:
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

    def set_object_velocity(self, v: list, w) -> None:
        self.bc.resetBaseVelocity(self.obj, v, list(w))

    def notes(self) -> dict:
        return {}

    # ------------------------------------------------------------------ step
    def apply_torques(self, tau: list) -> None:
        self.set_motors(self.robot, self.arm_j, p.TORQUE_CONTROL, forces=tau)

    def drive_hand(self, v: list, qd: list) -> None:
        # PyBullet's velocity motor is implicit (the rig's rate-limited servo is stable); it keeps
        # its target and force until set again: the same targets as last step (closing at full
        # speed, at rest) need no call
        if v != self._hand_v:
            self.set_motors(
                self.robot,
                self.hand_j,
                p.VELOCITY_CONTROL,
                targetVelocities=v,
                forces=self._hand_forces,
            )
            self._hand_v = v

    def hold_object(self, obj: tuple) -> None:
        if not self.params.object_gravity:
            P = self.params
            force = [0.0, 0.0, P.object_mass * P.gravity]
            self.bc.applyExternalForce(self.obj, -1, force, list(obj[0]), p.WORLD_FRAME)

    def advance(self) -> bool:
        self.bc.stepSimulation()
        self._steps += 1
        self._cache = None
        return False  # a non-finite state is the rig's check (limit_flags)

    # ------------------------------------------------------------------ events
    def object_contacts(self, pos, v) -> list:
        """The step's contact points object-robot that touch (normal force > 0 or no gap); none while
        the object at ``pos`` (moving at ``v``) is beyond the robot's reach (reach.py) by more
        than its bounding radius, its travel in two steps and 5 cm: no point can be there (the
        points of a step are found at its start, nearer than Bullet's contact threshold)."""
        x, y, z = pos
        bx, by, bz = self._base_pose[0]
        vx, vy, vz = v
        far = self._contact_radius + 2.0 * self.dt * math.sqrt(vx * vx + vy * vy + vz * vz)
        dx, dy, dz = x - bx, y - by, z - bz
        if dx * dx + dy * dy + dz * dz > far * far:
            self.contacts = []
        else:
            pts = self._get_contact_points(bodyA=self.obj, bodyB=self.robot)
            self.contacts = [c for c in pts if c[9] > 0.0 or c[8] <= 1e-4]
        return self.contacts

    def touch(self, contacts: list) -> tuple:
        c = max(contacts, key=lambda c: c[9])
        return c[4], c[6], c[7]

    def point_velocity(self, link: int, point) -> tuple[float, float, float]:
        """v + w x (point - link COM) of a robot link now (world), as floats."""
        if link < 0:
            return (0.0, 0.0, 0.0)
        ls = self.frames_now()[1] if link == self.palm_link else None
        if ls is None:
            ls = self._get_link_state(
                self.robot, link, computeLinkVelocity=1, computeForwardKinematics=1
            )
        (vx, vy, vz), (wx, wy, wz), (cx, cy, cz) = ls[6], ls[7], ls[0]
        rx, ry, rz = map(float, point)
        rx, ry, rz = rx - cx, ry - cy, rz - cz  # v + w x (point - link COM)
        return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx)

    # ------------------------------------------------------------------ log and scene
    def inverse_dynamics(self, q, qd, qdd) -> tuple:
        bc, dofs = self.bc, self.dofs
        pos = [s[0] for s in bc.getJointStates(self.robot, dofs)]
        vel, acc = [0.0] * len(dofs), [0.0] * len(dofs)
        cols = [dofs.index(j) for j in self.arm_j]
        for c, x, v, a in zip(cols, q, qd, qdd):
            pos[c], vel[c], acc[c] = float(x), float(v), float(a)
        tau = np.array(bc.calculateInverseDynamics(self.robot, pos, vel, acc))
        M = np.array(bc.calculateMassMatrix(self.robot, pos))
        return tau[cols], M[np.ix_(cols, cols)]

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

    def contact_summary(self) -> tuple[tuple, tuple, float]:
        """(parts, links, total normal force) of ``contacts`` (tuples, shared: copy them into
        a payload), summed once per list."""
        contacts = self.contacts
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

    def close(self) -> None:
        if getattr(self, "bc", None) is not None:
            try:
                self.bc.disconnect()
            except Exception:
                pass
            self.bc = None
