"""MuJoCo's contact and solver settings: ``MujocoSettings``, the engine field's
(``plant.params.engine: {type: mujoco, ...}``, plants/arm_rig/engine.py), and the same fields
flat in the params of the plant types ``mujoco_arm``/``mujoco_grasp`` (``Params``,
``GraspParams``: the scenarios and logs made before the engine field). PyBullet's settings
(``solver_iterations``, ``*_restitution``, ``contact_stiffness``/``contact_damping``,
rolling/spinning friction, flat in the logs of then) are dropped from a log and refused in a
scenario (plants/arm_rig/engine.py ``migrate_flat_settings``): MuJoCo has no restitution
coefficient; the bounce is set by ``mj_solref``'s damping ratio."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from plants.arm_rig.params import GraspParams as BulletGraspParams
from plants.arm_rig.params import Params as ArmParams
from replay.params import ParamError, param


@dataclass
class _EngineType:
    type: str = param("mujoco", choices=("mujoco",), doc="the engine: MuJoCo")


@dataclass
class _MujocoFields:
    mj_solref: list[float] = param(
        [0.002, 1.0],
        unit="s, 1",
        length=2,
        gt=0.0,
        le=10.0,
        doc="contact solref (time constant, damping ratio) of every object-robot contact. "
        "Assumed (MuJoCo's default 0.02 s lets a 9 m/s ball sink ~3 cm into the palm): 2 ms, "
        "2 physics steps (the least MuJoCo advises), damping ratio 1 (a ball dropped on the "
        "palm at 1.3 m/s comes back at ~0.3 m/s, PyBullet's restitution 0.6 * 0.3 ~0.2)",
    )
    mj_limit_solref: list[float] = param(
        [0.002, 2.0],
        unit="s, 1",
        length=2,
        gt=0.0,
        le=10.0,
        doc="solref of the joint limits (stops). Assumed: 2 ms, overdamped (ratio 2), so a joint "
        "driven into its stop stays there as PyBullet's (ratio 1 bounces it out of the stop "
        "once at 1 ms steps; MuJoCo's default 0.02 s lets J4 pass its stop by 5 deg)",
    )
    mj_solimp: list[float] = param(
        [0.9, 0.95, 0.001, 0.5, 2.0],
        unit="1, 1, m, 1, 1",
        length=5,
        gt=0.0,
        le=10.0,
        doc="contact solimp (d0, dwidth, width, midpoint, power): MuJoCo's default",
    )
    mj_cone: str = param(
        "pyramidal",
        choices=("pyramidal", "elliptic"),
        doc="friction cone (MuJoCo's default pyramidal)",
    )
    mj_condim: int = param(
        3,
        choices=(1, 3, 4, 6),
        doc="contact dimensionality: 3 = sliding friction only (as PyBullet's with rolling and "
        "spinning friction 0); 4 adds torsional, 6 rolling friction",
    )
    mj_iterations: int = param(
        50, ge=1, le=1000, doc="constraint solver iterations (as the PyBullet plant's 50)"
    )
    mj_noslip_iterations: int = param(
        0,
        ge=0,
        le=1000,
        doc="MuJoCo's noslip solver iterations after the main solve (0: off, MuJoCo's default); "
        "without it MuJoCo's soft friction lets a held object creep under a sustained "
        "tangential load, inside the friction cone, where Coulomb friction would stick",
    )
    mj_integrator: str = param(
        "implicitfast",
        choices=("Euler", "implicitfast", "implicit", "RK4"),
        doc="MuJoCo's integrator; implicitfast integrates the hand servos' velocity gain "
        "implicitly (PyBullet's velocity motor is an implicit constraint)",
    )
    hand_servo_gain: float = param(
        100.0,
        unit="N*m*s/rad",
        gt=0.0,
        le=1e6,
        doc="velocity gain of each hand joint's servo (integrated implicitly), its torque "
        "capped at hand_max_torque: stiff, as PyBullet's velocity motor (a constraint). "
        "Assumed: gain * dt is 2000 times a finger's inertia (~5e-5 kg*m^2), so the fingers "
        "follow the palm within 1e-4 of a step's acceleration (1 N*m*s/rad: 0.5 %); 30 and "
        "1000 catch the same throws (docs/mujoco.md)",
    )

    def __post_init__(self) -> None:
        for name in ("mj_solref", "mj_limit_solref"):
            if getattr(self, name)[0] < 0.002 * 0.999:
                # MuJoCo advises >= 2 steps; the plant runs at 1 ms (a finer step allows less,
                # but no scenario uses one)
                raise ParamError(name, "the time constant must be >= 0.002 s (2 physics steps)")


@dataclass
class MujocoSettings(_MujocoFields, _EngineType):
    """``plant.params.engine`` of type mujoco: its settings and adapters."""

    arm: ClassVar[str] = "plants.mujoco_arm.plant:MujocoEngine"
    grasp: ClassVar[str] = "plants.mujoco_arm.grasp_plant:MujocoGraspEngine"


@dataclass
class Params(_MujocoFields, ArmParams):
    """The mujoco_arm plant type's params: the rig's with MuJoCo's settings flat."""

    own_engine: ClassVar[str] = "mujoco"

    def __post_init__(self) -> None:
        ArmParams.__post_init__(self)
        _MujocoFields.__post_init__(self)


@dataclass
class GraspParams(BulletGraspParams, Params):
    """The grasping rig's parameters (plants/arm_rig/params.py ``GraspParams``: servos, head,
    human, verdict) with MuJoCo's contact and solver settings (``Params`` above), so a grasp
    scenario changes only ``plant.type``."""
