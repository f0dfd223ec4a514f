"""The arm rig's engine in Drake: pydrake's MultibodyPlant from the rig's URDF, 1 kHz steps.

``DrakeEngine`` is the engine-free arm rig's (plants/arm_rig/rig.py ``ArmRig``) adapter
(plants/arm_rig/engine.py ``EngineAdapter``), as ``PybulletEngine`` and ``MujocoEngine`` are in
theirs: the rig's commands, limits, truth topics, events and ``outcome`` are the rig's, so a
scenario differs from its PyBullet twin only in ``plant.params.engine``. The adapter builds the
world (world.py) and answers the rig's engine questions; it holds only Drake calls and Drake
state. Physics only: it knows nothing of any paper's method.

Stepping: the plant's context is advanced directly, one discrete update a step
(``EvalUniquePeriodicDiscreteUpdate``, then the new state set), no Simulator: the contact
results, the hand servos' torques and the joints' reaction forces read between the two are the
step's own (computed once, with the update), the kinematics read after it the new state's.

The rig's public attributes it reads: ``params`` (its ``engine_settings``: ``DrakeSettings``),
``settings``, ``model``, ``dt``, ``dof``, ``active``, ``locked``, ``joint_names``.
"""

from __future__ import annotations

import importlib.metadata
from typing import Any

import numpy as np
from pydrake.multibody.math import SpatialVelocity
from pydrake.multibody.tree import MultibodyForces

from plants.arm_rig.engine import ContactRows
from plants.arm_rig.rig import ArmRig
from plants.drake_arm.world import build_world, set_object, vec
from replay.scene import Frame

VERSION = importlib.metadata.version("drake")


def _pose(X) -> tuple:
    """(position, orientation [x, y, z, w]) of a RigidTransform, as floats."""
    q = X.rotation().ToQuaternion()
    x, y, z = X.translation().tolist()
    return (x, y, z), (float(q.x()), float(q.y()), float(q.z()), float(q.w()))


class DrakeEngine(ContactRows):
    """The rig's engine in Drake (plants/arm_rig/engine.py ``EngineAdapter``), built from the
    rig's public attributes (``rig``: its params, settings, model, dt and joints)."""

    def __init__(self, rig: ArmRig) -> None:
        P, S, dt = rig.params, rig.settings, rig.dt
        self.dof, self.dt = rig.dof, dt
        self._cache: tuple | None = None  # the state read this step (state)
        W = self.world = build_world(P, S, rig.model, dt, P.engine_settings)
        self.body_names, self.part_of_body = W.body_names, W.part_of_body  # ContactRows
        p, ctx = self.mbp, self.ctx = W.plant, W.context
        # ---- the initial state
        q = p.GetPositions(ctx)
        v = p.GetVelocities(ctx)
        for k, i in enumerate(rig.active):
            q[W.arm_q[k]], v[W.arm_v[k]] = S.initial_q[i], S.initial_qd[i]
        for a, x in zip(W.hand_q, S.hand_initial):
            q[a] = x
        p.SetPositions(ctx, q)
        p.SetVelocities(ctx, v)
        if W.object_body is not None:
            set_object(W, P.object_position, P.object_rpy, P.object_velocity,
                       P.object_angular_velocity)  # fmt: skip
        self._q_locked = [float(rig.locked.get(n, 0.0)) for n in rig.joint_names]
        self._arm_slots = [(i, W.arm_q[k], W.arm_v[k]) for k, i in enumerate(rig.active)]
        names = W.body_names
        self._tool = W.bodies[names.index("wam_tool")]
        self.palm_id = names.index("palm") if "palm" in names else None
        self._nv = p.num_velocities()
        self._tau = [0.0] * self._nv  # the generalized forces of the coming step
        self._tau_port = p.get_applied_generalized_force_input_port()
        self._tau_port.FixValue(ctx, np.zeros(self._nv))
        self._desired_port = p.get_desired_state_input_port(W.robot)
        nh = len(W.hand_v)
        self._desired_port.FixValue(ctx, np.zeros(2 * nh))
        p.get_actuation_input_port().FixValue(ctx, np.zeros(p.num_actuators()))
        self._hand_tau = [0.0] * nh  # the hand servos' torques of the last step
        self._motions: dict = {}  # body index -> (pos, orn, v, w) this step
        # frames(): per robot body, its parent's and its own Drake body and names
        self._frame_rows = []
        for j in p.GetJointIndices(W.robot):
            joint = p.get_joint(j)
            self._frame_rows.append(
                (joint.parent_body(), joint.child_body(), joint.parent_body().name(),
                 joint.child_body().name())
            )  # fmt: skip
        self.contacts: list = []  # the step's rows (body, point, normal, force): _read_contacts

    # ------------------------------------------------------------------ state
    def state(self) -> tuple:
        """((q, qd), hand (q, qd, effort), object (pos, orn xyzw, v, w world) or None) as
        plain floats, read once after each step; shared, never mutated."""
        if self._cache is None:
            W, p, ctx = self.world, self.mbp, self.ctx
            qp, qv = p.GetPositions(ctx).tolist(), p.GetVelocities(ctx).tolist()
            q, qd = self._q_locked[:], [0.0] * self.dof
            for i, a, b in self._arm_slots:
                q[i], qd[i] = qp[a], qv[b]
            hand = ([qp[a] for a in W.hand_q], [qv[b] for b in W.hand_v], self._hand_tau[:])
            obj = None
            if W.object_body is not None:
                a, b = W.object_q, W.object_v
                qw, qx, qy, qz, x, y, z = qp[a : a + 7]
                wx, wy, wz, vx, vy, vz = qv[b : b + 6]  # Drake's free body: w, v in the world
                obj = ((x, y, z), (qx, qy, qz, qw), (vx, vy, vz), (wx, wy, wz))
            self._cache = ((q, qd), hand, obj)
        return self._cache

    def invalidate_state(self) -> None:
        """Forget the state read (after setting the context other than by stepping)."""
        self._cache = None
        self._motions.clear()

    def _body_motion(self, k: int) -> tuple:
        """(position, orientation xyzw, v, w) of robot body ``k``'s frame (world), once a step."""
        got = self._motions.get(k)
        if got is None:
            body = self.world.bodies[k] if k >= 0 else self._tool
            X = self.mbp.EvalBodyPoseInWorld(self.ctx, body)
            V = self.mbp.EvalBodySpatialVelocityInWorld(self.ctx, body)
            pos, orn = _pose(X)
            got = (pos, orn, tuple(V.translational().tolist()), tuple(V.rotational().tolist()))
            self._motions[k] = got
        return got

    def effector_now(self) -> tuple:
        return self._body_motion(-1)

    def point_velocity(self, link: int, point) -> tuple[float, float, float]:
        """v + w x (point - body origin) of a robot body now (world)."""
        (cx, cy, cz), _, (vx, vy, vz), (wx, wy, wz) = self._body_motion(link)
        rx, ry, rz = (float(point[0]) - cx, float(point[1]) - cy, float(point[2]) - cz)
        return (vx + wy * rz - wz * ry, vy + wz * rx - wx * rz, vz + wx * ry - wy * rx)

    def set_object_velocity(self, v: list, w) -> None:
        V = SpatialVelocity(vec(w), vec(v))
        self.mbp.SetFreeBodySpatialVelocity(self.ctx, self.world.object_body, V)

    def notes(self) -> dict:
        return {"engine": f"drake {VERSION}"}

    # ------------------------------------------------------------------ command
    def apply_torques(self, tau: list) -> None:
        for (_, _, b), x in zip(self._arm_slots, tau):
            self._tau[b] = x

    def drive_hand(self, v: list, qd: list) -> None:
        # desired positions: unused (Kp = 0); desired velocities: the servos' speeds
        self._desired_port.FixValue(self.ctx, np.array(self.state()[1][0] + list(v)))

    def hold_object(self, obj: tuple) -> None:
        pass  # object_gravity off: the object's model instance has no gravity (world.py)

    def advance(self) -> bool:
        p, ctx = self.mbp, self.ctx
        self._tau_port.FixValue(ctx, np.array(self._tau))
        try:
            x = p.EvalUniquePeriodicDiscreteUpdate(ctx)
            self._read_step()
            ctx.SetDiscreteState(x)
        except RuntimeError:  # SAP found no solution (a non-finite state): diverged
            return True
        finally:
            self._cache = None
            self._motions.clear()
        root = self.world.root
        root.SetTime(root.get_time() + self.dt)
        return False

    def _read_step(self) -> None:
        """The step's own contact rows and hand servo torques (before its state is set)."""
        p, ctx = self.mbp, self.ctx
        if self.world.hand_v:
            tau: Any = p.get_net_actuation_output_port().Eval(ctx)
            self._hand_tau = tau.tolist()
        self._read_contacts()

    # ------------------------------------------------------------------ events
    def _read_contacts(self) -> None:
        """The step's object-robot contacts (the robot touches nothing else): body, point,
        normal from the robot towards the object, normal force (N)."""
        out: list = []
        if self.world.object_body is not None:
            res: Any = self.mbp.get_contact_results_output_port().Eval(self.ctx)
            self._point_rows(res, out)
            if res.num_hydroelastic_contacts():
                self._patch_rows(res, out)
        self.contacts = out

    def _point_rows(self, res: Any, out: list) -> None:
        """Point contacts: Drake's normal from B into A, its force on B."""
        ob, index = int(self.world.object_body.index()), self.world.body_of_drake
        for i in range(res.num_point_pair_contacts()):
            c = res.point_pair_contact_info(i)
            a, b = int(c.bodyA_index()), int(c.bodyB_index())
            n = c.point_pair().nhat_BA_W.tolist()
            f = c.contact_force().tolist()
            pt = c.contact_point().tolist()
            if b == ob:  # the robot is A: robot -> object is -n; the force on B pushes
                n = [-n[0], -n[1], -n[2]]
                out.append((index[a], pt, n, f[0] * n[0] + f[1] * n[1] + f[2] * n[2]))
            elif a == ob:
                out.append((index[b], pt, n, -(f[0] * n[0] + f[1] * n[1] + f[2] * n[2])))

    def _patch_rows(self, res: Any, out: list) -> None:
        """Hydroelastic patches: at the patch's centroid, the net force's direction on the
        object as the normal and its size as the normal force (friction included)."""
        p, W = self.mbp, self.world
        inspector = W.scene_graph.model_inspector()
        ob, index = int(W.object_body.index()), W.body_of_drake
        for i in range(res.num_hydroelastic_contacts()):
            c = res.hydroelastic_contact_info(i)
            s = c.contact_surface()
            m = int(p.GetBodyFromFrameId(inspector.GetFrameId(s.id_M())).index())
            n_ = int(p.GetBodyFromFrameId(inspector.GetFrameId(s.id_N())).index())
            f = c.F_Ac_W().translational()  # on M's body, at the centroid
            robot = n_ if m == ob else m
            if ob not in (m, n_) or robot not in index:
                continue
            f_obj = f if m == ob else -f
            size = float(np.linalg.norm(f_obj))
            n = (f_obj / size).tolist() if size > 0.0 else [0.0, 0.0, 0.0]
            out.append((index[robot], s.centroid().tolist(), n, size))

    def inverse_dynamics(self, q, qd, qdd) -> tuple:
        p, W = self.mbp, self.world
        ctx = p.CreateDefaultContext()  # a scratch context: the simulation's untouched
        x = p.GetPositions(self.ctx)
        v: Any = np.zeros(self._nv)
        vdot: Any = np.zeros(self._nv)
        x[list(W.arm_q)], v[list(W.arm_v)], vdot[list(W.arm_v)] = q, qd, qdd
        p.SetPositions(ctx, x)
        p.SetVelocities(ctx, v)
        gravity = MultibodyForces(p)
        p.CalcForceElementsContribution(ctx, gravity)  # Drake's gravity is a force element
        tau: Any = p.CalcInverseDynamics(ctx, vdot, gravity)
        M: Any = p.CalcMassMatrix(ctx)
        return tau[list(W.arm_v)], M[np.ix_(W.arm_v, W.arm_v)]

    # ------------------------------------------------------------------ log and scene
    def frames(self) -> list[Frame]:
        """Every URDF link in its parent link, the base in ``world`` (the robot's bodies; the
        free object is the scene's), in plain floats."""
        p, ctx = self.mbp, self.ctx
        out = []
        for parent, child, pn, cn in self._frame_rows:
            X = p.CalcRelativeTransform(ctx, parent.body_frame(), child.body_frame())
            pos, orn = _pose(X)
            out.append(Frame(pn, cn, pos, orn))
        return out

    def close(self) -> None:
        """Nothing to free: Drake's diagram and context go with the adapter."""
