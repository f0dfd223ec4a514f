"""A torque-controlled arm with a position-controlled hand and one free object, in MuJoCo.

The engine-free arm rig (plants/arm_rig/rig.py ``ArmRig``) in MuJoCo, as the PyBullet plant is
in PyBullet: the same ``Params`` (plus MuJoCo's contact settings), commands, limits, truth
topics, events and ``outcome`` are the rig's, written once, so a scenario differs from its
PyBullet twin only in ``plant.type``. This plant builds the world and answers the rig's engine
questions. Physics only: it knows nothing of any paper's method.

Stepping: ``mj_step2`` (actuation, constraints, integration) then ``mj_step1`` (positions,
velocities, collision at the new state): the contacts and their forces read between the two are
the step's own (as PyBullet's ``getContactPoints`` after ``stepSimulation``), and the kinematics
read after it are the new state's, at the cost of one ``mj_step``.
"""

from __future__ import annotations

import mujoco
import numpy as np

from plants.arm_rig.engine import ContactRows
from plants.arm_rig.rig import ArmRig
from plants.mujoco_arm.params import Params as MujocoParams
from plants.mujoco_arm.world import NEAR, build_world, free_velocity
from replay.scene import Frame


def _xyzw(q) -> tuple[float, float, float, float]:
    w, x, y, z = q
    return (float(x), float(y), float(z), float(w))


def _index(ix: list) -> slice | list:
    """A slice for ascending consecutive addresses (MuJoCo's arrays read and write a slice
    for ~half a fancy index's cost), else the list itself."""
    if ix and ix == list(range(ix[0], ix[0] + len(ix))):
        return slice(ix[0], ix[0] + len(ix))
    return ix


class MujocoEngine(ContactRows):
    """The rig's engine in MuJoCo (plants/arm_rig/engine.py ``EngineAdapter``), built from the
    rig's public attributes (``rig``: its params, settings, model, dt and joints)."""

    def __init__(self, rig: ArmRig) -> None:
        P, S, dt = rig.params, rig.settings, rig.dt
        self.dof, self.active, self.hand_names = rig.dof, rig.active, rig.hand_names
        self._cache: tuple | None = None  # the state read this step (state)
        self.contacts: list = []  # the step's rows (body, position, normal, force): _read_contacts
        # MuJoCo's settings: the engine field's, else the mujoco_arm params' own (flat)
        E = P.engine_settings if P.engine_settings is not None else P
        W = self.world = build_world(P, S, rig.model, dt, E)
        self.body_names, self.part_of_body = W.body_names, W.part_of_body  # ContactRows
        m, d = self.mj, self.md = W.model, W.data
        self._arm_qpos, self._arm_dof = list(W.arm_qpos), list(W.arm_dof)
        self._hand_qpos, self._hand_dof = list(W.hand_qpos), list(W.hand_dof)
        self._hand_act = list(W.hand_act)
        self._arm_dof_ix, self._hand_act_ix = _index(self._arm_dof), _index(self._hand_act)
        self._tool = W.body_names.index("wam_tool")
        self._palm = W.body_names.index("palm") if "palm" in W.body_names else -1
        self.palm_id = self._palm if self._palm >= 0 else None
        self._ob = W.object_body
        self._set_initial_state(W, S, P)
        mujoco.mj_forward(m, d)
        self._q_locked = [float(rig.locked.get(n, 0.0)) for n in rig.joint_names]
        # (arm joint index, qpos address, dof address) of each active joint
        self._arm_slots = [(i, W.arm_qpos[k], W.arm_dof[k]) for k, i in enumerate(self.active)]
        self._root = m.body_rootid.tolist()
        self._geom_body = m.geom_bodyid.tolist()
        self._motions: dict = {}  # body -> _body_motion, this step's
        # frames(): per robot body (body, parent, parent's name, its name)
        self._frame_rows = [
            (i, int(m.body_parentid[i]), W.body_names[int(m.body_parentid[i])], W.body_names[i])
            for i in range(1, m.nbody)
            if W.part_of_body[i] is not None
        ]
        self._f6 = np.zeros(6)
        self._index_hand(W, P, dt)
        self._hand_kv = float(E.hand_servo_gain)
        # MuJoCo resets the state where it diverges (a warning count): those are the "nan"
        self._bad = [
            int(w)
            for w in (
                mujoco.mjtWarning.mjWARN_BADQACC,
                mujoco.mjtWarning.mjWARN_BADQVEL,
                mujoco.mjtWarning.mjWARN_BADQPOS,
            )
        ]

    def _set_initial_state(self, W, S, P) -> None:
        """The arm, the hand and the object at the scenario's initial state (before the
        final mj_forward)."""
        m, d = W.model, W.data
        q0, qd0 = S.initial_q, S.initial_qd
        for k, i in enumerate(self.active):
            d.qpos[W.arm_qpos[k]] = q0[i]
            d.qvel[W.arm_dof[k]] = qd0[i]
        for a, v in zip(W.hand_qpos, S.hand_initial):
            d.qpos[a] = v
        if self._ob >= 0:
            a, b = W.object_qpos, W.object_dof
            mujoco.mj_forward(m, d)  # the object's rotation, for its body-frame spin
            R = d.xmat[self._ob].reshape(3, 3)
            d.qvel[b : b + 6] = free_velocity(R, P.object_velocity, P.object_angular_velocity)

    def _index_hand(self, W, P, dt: float) -> None:
        """The hand servos' torque cap and inertia per step, each hand link's body and geoms,
        and how near the object must be before a hand link can touch it."""
        m, d = W.model, W.data
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

    # ------------------------------------------------------------------ state
    def state(self) -> tuple:
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

    def _body_motion(self, body: int) -> tuple:
        """(position, orientation xyzw, v, w) of a body's frame (world), from MuJoCo's cvel
        (rotation; translation of the point at the subtree centre of mass of the body's root,
        moving with the body), read once a step per body."""
        got = self._motions.get(body)
        if got is not None:
            return got
        d = self.md
        wx, wy, wz, ux, uy, uz = d.cvel[body].tolist()
        px, py, pz = d.xpos[body].tolist()
        cx, cy, cz = d.subtree_com[self._root[body]].tolist()
        rx, ry, rz = px - cx, py - cy, pz - cz
        v = (ux + wy * rz - wz * ry, uy + wz * rx - wx * rz, uz + wx * ry - wy * rx)
        got = ((px, py, pz), _xyzw(d.xquat[body].tolist()), v, (wx, wy, wz))
        self._motions[body] = got
        return got

    def effector_now(self) -> tuple:
        return self._body_motion(self._tool)

    def set_object_velocity(self, v: list, w) -> None:
        b = self.world.object_dof
        self.md.qvel[b : b + 3] = v

    def notes(self) -> dict:
        return {"engine": f"mujoco {mujoco.__version__}"}

    def point_velocity(self, body: int, point) -> tuple[float, float, float]:
        """v + w x (point - body origin) of a robot body now (world)."""
        if self.world.part_of_body[body] is None:
            return (0.0, 0.0, 0.0)
        (cx, cy, cz), _, (vx, vy, vz), (wx, wy, wz) = self._body_motion(body)
        rx, ry, rz = (float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz)
        return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx)

    # ------------------------------------------------------------------ command
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

    def apply_torques(self, tau: list) -> None:
        self.md.qfrc_applied[self._arm_dof_ix] = tau

    def drive_hand(self, v: list, qd: list) -> None:
        self.md.ctrl[self._hand_act_ix] = v
        self._hand_caps(v, qd)

    def hold_object(self, obj: tuple) -> None:
        pass  # object_gravity off: the world's gravity compensation (world.py)

    def advance(self) -> bool:
        m, d = self.mj, self.md
        mujoco.mj_step2(m, d)
        self._read_contacts()
        mujoco.mj_step1(m, d)
        self._cache = None
        self._motions.clear()
        # MuJoCo found a non-finite or huge state and reset it: the run has diverged
        return self._warned()

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
        self.contacts = out

    def inverse_dynamics(self, q, qd, qdd) -> tuple:
        m, W = self.mj, self.world
        d = mujoco.MjData(m)  # a scratch copy: the simulation's data untouched
        d.qpos[:] = self.md.qpos
        d.qpos[list(W.arm_qpos)] = q
        d.qvel[list(W.arm_dof)] = qd
        d.qacc[list(W.arm_dof)] = qdd
        mujoco.mj_inverse(m, d)
        M = np.zeros((m.nv, m.nv))
        mujoco.mj_fullM(m, d, M)
        return d.qfrc_inverse[list(W.arm_dof)].copy(), M[np.ix_(W.arm_dof, W.arm_dof)]

    # ------------------------------------------------------------------ log and scene
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

    def close(self) -> None:
        """Nothing to free: MuJoCo's model and data go with the adapter."""


class MujocoArmPlant(ArmRig):
    Params = MujocoParams
    Engine = MujocoEngine
    description = "MuJoCo WAM arm (torque control) + hand (velocity servos) + a free object"
