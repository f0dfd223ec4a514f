"""The Drake world of the arm rig, built from the generated URDF (``plants.models``: the one
source of the robot), the rig's ``Params`` and Drake's settings (``DrakeSettings``): no second
robot description.

Drake facts used (drake 1.51, checked by tests/plants/drake_arm):
- the URDF is parsed as it is: every link a body of the same name (the massless ``wam_base`` and
  ``wam_tool`` welded), its joint limits SAP constraints, no joint damping or friction: the arm
  follows M qdd + H qd + g = tau (our RNEA's); the base is welded to the world at
  ``base_position``/``base_rpy``;
- the robot's geometries collide only with the object (one collision filter over all of them;
  PyBullet does not collide a body's links with each other, there is no floor);
- point contact (``contact_model: point``; ``dk_contact_model``): the object is a sphere or a
  box against the robot's boxes, cylinders and spheres, one point per geometry pair; or
  hydroelastic (``hydroelastic_with_fallback``: every geometry compliant, contact patches);
- Drake combines two geometries' stiffness in series and their friction as 2 mu1 mu2 / (mu1 +
  mu2): both get 2 k and mu = hand_lateral_friction * object_lateral_friction (PyBullet's
  product), so the pair has k and mu; the dissipation of equal ones is theirs;
- the hand joints are PD servos with Kp = 0 (velocity servos), effort-limited at
  ``hand_max_torque``: SAP solves them with the contacts, implicitly (PyBullet's capped motor);
- the object's gravity is switched off for its model instance where ``object_gravity`` is off;
- output ports are not sampled: the contact results, reaction forces and net actuation read
  before a step are that step's (computed once, with the discrete update).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from pydrake.geometry import (
    AddCompliantHydroelasticProperties,
    AddContactMaterial,
    Box,
    CollisionFilterDeclaration,
    GeometrySet,
    ProximityProperties,
    RoleAssign,
    Shape,
    Sphere,
)
from pydrake.multibody.math import SpatialVelocity
from pydrake.math import RigidTransform, RollPitchYaw, RotationMatrix
from pydrake.multibody.parsing import Parser
from pydrake.multibody.plant import (
    AddMultibodyPlant,
    CoulombFriction,
    MultibodyPlant,
    MultibodyPlantConfig,
)
from pydrake.multibody.tree import PdControllerGains, SpatialInertia
from pydrake.systems.framework import Context, Diagram, DiagramBuilder

from plants.arm_rig.settings import ArmSettings
from plants.arm_rig.params import Params
from plants.drake_arm.params import DrakeSettings
from plants.models.arm import ArmModel

OBJECT = "object"


@dataclass(frozen=True)
class World:
    """The finalised plant, its context and where the plant finds things in it."""

    diagram: Diagram
    plant: MultibodyPlant
    scene_graph: Any  # SceneGraph (its model inspector: the hydroelastic patches' bodies)
    context: Context  # the plant's (within the diagram's)
    root: Context  # the diagram's
    robot: Any  # ModelInstanceIndex
    arm_q: tuple[int, ...]  # position index per active arm joint (in ``active`` order)
    arm_v: tuple[int, ...]
    hand_q: tuple[int, ...]
    hand_v: tuple[int, ...]
    bodies: tuple  # robot bodies (RigidBody) by our index
    body_names: tuple[str, ...]
    part_of_body: tuple[str, ...]  # "arm", "palm", a finger's name
    body_of_drake: dict  # Drake's BodyIndex (int) -> our index; the object's absent
    object_body: Any  # RigidBody or None
    object_q: int  # position index of the object's quaternion (w x y z, then x y z); -1: none
    object_v: int  # velocity index of its w (world), then v
    palm_joint: Any  # the palm's weld (Joint) or None


def vec(values) -> Any:
    """``values`` as a float array (pydrake's vectors)."""
    return np.asarray(values, dtype=float)


def _material(P: Params, E: DrakeSettings) -> ProximityProperties:
    """Proximity properties whose pair with another of the same gives (k, d, mu): Drake
    combines stiffness in series, so each geometry gets 2 k; with hydroelastic contact each is
    also compliant (modulus E, tessellated to 1 cm)."""
    k, d = float(E.dk_point_stiffness), float(E.dk_dissipation)
    mu = float(P.hand_lateral_friction) * float(P.object_lateral_friction)  # PyBullet's product
    props = ProximityProperties()
    AddContactMaterial(d, 2.0 * k, CoulombFriction(mu, mu), props)
    if E.dk_contact_model == "hydroelastic":
        AddCompliantHydroelasticProperties(0.01, float(E.dk_hydroelastic_modulus), props)
    return props


def build_world(P: Params, S: ArmSettings, arm: ArmModel, dt: float, E: DrakeSettings) -> World:
    config = MultibodyPlantConfig(
        time_step=dt,
        contact_model="point" if E.dk_contact_model == "point" else "hydroelastic_with_fallback",
        discrete_contact_approximation=E.dk_contact_approximation,
        use_sampled_output_ports=False,
    )
    builder = DiagramBuilder()
    plant, scene_graph = AddMultibodyPlant(config, builder)
    (robot,) = Parser(plant).AddModelsFromString(arm.urdf, "urdf")
    plant.set_gravity_enabled(robot, True)
    plant.mutable_gravity_field().set_gravity_vector([0.0, 0.0, -float(P.gravity)])
    X_base = RigidTransform(RotationMatrix(RollPitchYaw(vec(P.base_rpy))), vec(P.base_position))
    plant.WeldFrames(plant.world_frame(), plant.GetFrameByName("wam_base", robot), X_base)
    for name in arm.hand_joints:
        a = plant.AddJointActuator(
            f"{name}_servo", plant.GetJointByName(name, robot), float(P.hand_max_torque)
        )
        a.set_controller_gains(PdControllerGains(p=0.0, d=float(E.dk_hand_servo_gain)))
    props = _material(P, E)
    body_ids = plant.GetBodyIndices(robot)
    robot_geoms = [
        g for b in body_ids for g in plant.GetCollisionGeometriesForBody(plant.get_body(b))
    ]
    source = plant.get_source_id()
    for g in robot_geoms:
        scene_graph.AssignRole(source, g, props, RoleAssign.kReplace)
    ob = None
    if P.object != "none":
        inst = plant.AddModelInstance(OBJECT)
        m = float(P.object_mass)
        shape: Shape
        if P.object == "ball":
            r = float(P.object_radius)
            M, shape = SpatialInertia.SolidSphereWithMass(m, r), Sphere(r)
        else:
            sx, sy, sz = (float(s) for s in P.object_size)
            M, shape = SpatialInertia.SolidBoxWithMass(m, sx, sy, sz), Box(sx, sy, sz)
        ob = plant.AddRigidBody(OBJECT, inst, M)
        plant.RegisterCollisionGeometry(ob, RigidTransform(), shape, OBJECT, props)
        plant.set_gravity_enabled(inst, bool(P.object_gravity))
    scene_graph.collision_filter_manager().Apply(
        CollisionFilterDeclaration().ExcludeWithin(GeometrySet(robot_geoms))
    )
    plant.Finalize()
    diagram = builder.Build()
    root = diagram.CreateDefaultContext()
    ctx = plant.GetMyMutableContextFromRoot(root)
    joint = lambda n: plant.GetJointByName(n, robot)  # noqa: E731
    active = [joint(S.joint_names[i]) for i in S.active]
    hand = [joint(n) for n in arm.hand_joints]
    bodies = tuple(plant.get_body(b) for b in body_ids)
    names = tuple(b.name() for b in bodies)
    palm = None
    if arm.palm_link is not None:
        palm = next(
            plant.get_joint(j)
            for j in plant.GetJointIndices(robot)
            if plant.get_joint(j).child_body().name() == arm.palm_link
        )
    return World(
        diagram=diagram,
        plant=plant,
        scene_graph=scene_graph,
        context=ctx,
        root=root,
        robot=robot,
        arm_q=tuple(j.position_start() for j in active),
        arm_v=tuple(j.velocity_start() for j in active),
        hand_q=tuple(j.position_start() for j in hand),
        hand_v=tuple(j.velocity_start() for j in hand),
        bodies=bodies,
        body_names=names,
        part_of_body=tuple(arm.part_of_link.get(n, "arm") for n in names),
        body_of_drake={int(b.index()): i for i, b in enumerate(bodies)},
        object_body=ob,
        object_q=ob.floating_positions_start() if ob is not None else -1,
        object_v=ob.floating_velocities_start_in_v() if ob is not None else -1,
        palm_joint=palm,
    )


def set_object(W: World, pos, rpy, v, w) -> None:
    """The free object's pose and velocity (world) in the plant's context."""
    p, body, ctx = W.plant, W.object_body, W.context
    X = RigidTransform(RotationMatrix(RollPitchYaw(vec(rpy))), vec(pos))
    p.SetFreeBodyPose(ctx, body, X)
    p.SetFreeBodySpatialVelocity(ctx, body, SpatialVelocity(vec(w), vec(v)))
