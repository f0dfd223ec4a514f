"""The MuJoCo world of the arm plant, built from the generated URDF (``plants.models``: the one
source of the robot) and the plant's ``Params``: no second robot description.

MuJoCo facts used (MuJoCo 4.0, checked by tests/plants/mujoco_arm):
- the URDF is compiled with ``fusestatic`` off, so every URDF link (the zero-mass ``wam_tool``,
  the palm, a locked joint's link) stays a body of the same name, for contacts and ``/tf``;
- URDF joint limits become limited joint ranges (constraints, as PyBullet's), without damping,
  friction or armature: the arm follows M qdd + H qd + g = tau (our RNEA's);
- PyBullet does not collide a body's links with each other: here the robot's geoms only collide
  with the object (contype/conaffinity bits), and there is no floor in either;
- PyBullet combines two bodies' friction coefficients by their product, MuJoCo by their maximum:
  both the robot's and the object's geoms get the product, so the pair has the same mu;
- the hand joints are velocity servos (``set_to_velocity``) with their torque clipped to
  ``hand_max_torque``, the PyBullet plant's rate-limited velocity motors (plant.py
  ``_hand_caps``: when the clip applies);
- a hand servo is clipped while its link's geoms' bounding spheres are within ``NEAR`` of the
  object's: the object may touch it within the step;
- the wrist F/T sensor: MuJoCo's ``force``/``torque`` sensors on a site at the palm's origin give
  the flange's wrench on the palm about that point in the palm frame (``wrist_wrench`` negates it
  to the PyBullet rig's convention; tests/plants/mujoco_arm/test_wrist_mujoco.py and
  test_cross_engine.py: the same static loads as PyBullet's).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from plants.arm_rig.params import Params as ArmParams
from plants.arm_rig.settings import ArmSettings
from plants.models.arm import ArmModel
from plants.mujoco_arm.params import MujocoSettings
from plants.mujoco_arm.params import Params as MujocoParams
from replay.spatial import matrix_to_quaternion, rpy_to_matrix

ROBOT_BITS, OBJECT_BITS = 2, 1  # contype of each; conaffinity the other's: robot-robot never
OBJECT_BODY = "object"
WRIST_SITE = "wrist_ft"
NEAR = 0.02  # m: an object this near a link may touch it within a 1 ms step (20 m/s relative)
INTEGRATORS = {
    "Euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "RK4": mujoco.mjtIntegrator.mjINT_RK4,
}
CONES = {"pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL, "elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC}


def wxyz(xyzw) -> list[float]:
    x, y, z, w = (float(v) for v in xyzw)
    return [w, x, y, z]


@dataclass(frozen=True)
class World:
    """The compiled model and where the plant finds things in it."""

    model: mujoco.MjModel
    data: mujoco.MjData
    arm_qpos: tuple[int, ...]  # qpos address per active arm joint (in ``active`` order)
    arm_dof: tuple[int, ...]
    hand_qpos: tuple[int, ...]
    hand_dof: tuple[int, ...]
    hand_act: tuple[int, ...]  # actuator per hand joint
    body_names: tuple[str, ...]  # by body id (0: world)
    part_of_body: tuple[str | None, ...]  # "arm", "palm", a finger's name; None: not the robot
    object_body: int  # -1: none
    object_qpos: int
    object_dof: int
    wrist_adr: int = -1  # sensordata address of the wrist's force (3) then torque (3); -1: none


def build_world(
    P: ArmParams, S: ArmSettings, arm: ArmModel, dt: float, E: MujocoSettings | MujocoParams
) -> World:
    """The MuJoCo world of the rig's params ``P`` (settings ``S``, robot ``arm``) at steps of
    ``dt``, MuJoCo's settings from ``E`` (the engine field's, or the mujoco_arm params')."""
    spec = mujoco.MjSpec.from_string(arm.urdf)
    spec.compiler.fusestatic = False
    opt = spec.option
    opt.timestep = dt
    opt.gravity = [0.0, 0.0, -float(P.gravity)]
    opt.integrator = INTEGRATORS[E.mj_integrator]
    opt.cone = CONES[E.mj_cone]
    opt.iterations = int(E.mj_iterations)
    opt.noslip_iterations = int(E.mj_noslip_iterations)
    base = spec.body("wam_base")
    base.pos = [float(x) for x in P.base_position]
    base.quat = wxyz(matrix_to_quaternion(rpy_to_matrix(P.base_rpy)))
    mu = float(P.hand_lateral_friction) * float(P.object_lateral_friction)  # PyBullet's product
    solref, solimp = [float(x) for x in E.mj_solref], [float(x) for x in E.mj_solimp]
    for g in spec.geoms:
        g.contype, g.conaffinity = ROBOT_BITS, OBJECT_BITS
        g.friction = [mu, 0.0, 0.0]
        g.condim, g.solref, g.solimp = int(E.mj_condim), solref, solimp
    for j in spec.joints:
        j.solref_limit = [float(x) for x in E.mj_limit_solref]  # MuJoCo's default: 0.02 s
        # the URDF's effort limit becomes a joint-level clip of actuator force, applied outside
        # the implicit step: the plant clips the arm's torques and the hand servos' itself
        j.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
    for name in arm.hand_joints:
        a = spec.add_actuator(name=f"{name}_servo", target=name)
        a.trntype = mujoco.mjtTrn.mjTRN_JOINT
        a.set_to_velocity(kv=float(E.hand_servo_gain))
        a.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        a.forcerange = [-float(P.hand_max_torque), float(P.hand_max_torque)]
    if arm.palm_link is not None:
        _add_wrist_sensor(spec, arm.palm_link)
    if P.object != "none":
        _add_object(spec, P, E, mu, solref, solimp)
    model = spec.compile()
    return _index(model, mujoco.MjData(model), S, arm)


def _add_wrist_sensor(spec, palm_link: str) -> None:
    """The wrist's 6-axis F/T sensor on the flange-palm joint (fixed, identity: the palm frame is
    the tool frame): a site at the palm body's origin, MuJoCo's force and torque sensors there
    (the palm's interaction with its parent, wam_tool; wrist_wrench)."""
    site = spec.body(palm_link).add_site(name=WRIST_SITE)
    spec.add_sensor(
        name="wrist_force", type=mujoco.mjtSensor.mjSENS_FORCE,
        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site.name,
    )  # fmt: skip
    spec.add_sensor(
        name="wrist_torque", type=mujoco.mjtSensor.mjSENS_TORQUE,
        objtype=mujoco.mjtObj.mjOBJ_SITE, objname=site.name,
    )  # fmt: skip


def _add_object(
    spec, P: ArmParams, E: MujocoSettings | MujocoParams, mu: float, solref: list, solimp: list
) -> None:
    """The free object (ball or box) on a free joint, with the robot's contact settings."""
    body = spec.worldbody.add_body(
        name=OBJECT_BODY,
        pos=[float(x) for x in P.object_position],
        quat=wxyz(matrix_to_quaternion(rpy_to_matrix(P.object_rpy))),
    )
    body.add_freejoint(name="object_free")
    if P.object == "ball":
        kind, size = mujoco.mjtGeom.mjGEOM_SPHERE, [float(P.object_radius), 0.0, 0.0]
    else:
        kind, size = mujoco.mjtGeom.mjGEOM_BOX, [float(s) / 2 for s in P.object_size]
    body.add_geom(
        name="object",
        type=kind,
        size=size,
        mass=float(P.object_mass),
        friction=[mu, 0.0, 0.0],
        contype=OBJECT_BITS,
        conaffinity=ROBOT_BITS,
        condim=int(E.mj_condim),
        solref=solref,
        solimp=solimp,
    )
    if not P.object_gravity:
        body.gravcomp = 1.0


def _index(model, data, S: ArmSettings, arm: ArmModel) -> World:
    """The compiled world with the addresses the plant reads every step."""
    jid = lambda n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)  # noqa: E731
    active = [S.joint_names[i] for i in S.active]
    arm_j = [jid(n) for n in active]
    hand_j = [jid(n) for n in arm.hand_joints]
    names = tuple(model.body(i).name for i in range(model.nbody))
    part = tuple(
        None if n in ("world", OBJECT_BODY) else arm.part_of_link.get(n, "arm") for n in names
    )
    ob = names.index(OBJECT_BODY) if OBJECT_BODY in names else -1
    oj = int(model.body_jntadr[ob]) if ob >= 0 else -1
    return World(
        model=model,
        data=data,
        arm_qpos=tuple(int(model.jnt_qposadr[j]) for j in arm_j),
        arm_dof=tuple(int(model.jnt_dofadr[j]) for j in arm_j),
        hand_qpos=tuple(int(model.jnt_qposadr[j]) for j in hand_j),
        hand_dof=tuple(int(model.jnt_dofadr[j]) for j in hand_j),
        hand_act=tuple(
            mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, f"{n}_servo")
            for n in arm.hand_joints
        ),
        body_names=names,
        part_of_body=part,
        object_body=ob,
        object_qpos=int(model.jnt_qposadr[oj]) if oj >= 0 else -1,
        object_dof=int(model.jnt_dofadr[oj]) if oj >= 0 else -1,
        wrist_adr=(
            int(
                model.sensor_adr[
                    mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SENSOR, "wrist_force")
                ]
            )
            if arm.palm_link is not None
            else -1
        ),
    )


def free_velocity(R: np.ndarray, v, w) -> list[float]:
    """A free joint's qvel: linear velocity (world), angular velocity in the body frame
    (MuJoCo's convention), from world ``v`` and ``w`` with the body's rotation ``R``."""
    return [float(x) for x in v] + (R.T @ np.asarray(w, float)).tolist()


def wrist_wrench(world: World, data: mujoco.MjData) -> list[float]:
    """The wrist sensor's reading, as the PyBullet plant's (bullet_arm/ft_sensor.py): the force
    and torque the hand exerts on the flange, moment about the joint origin, palm frame
    [Fx, Fy, Fz, Mx, My, Mz]. MuJoCo's force/torque sensors give the parent's (the flange's)
    wrench on the site's body, about the site, in the site frame: negated here."""
    a = world.wrist_adr
    return [-float(x) for x in data.sensordata[a : a + 6]]
