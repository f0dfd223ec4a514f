"""PyBullet's entry in the engine field (``plant.params.engine: {type: pybullet, ...}``,
plants/arm_rig/engine.py): the contact and solver settings only PyBullet reads, and its adapters.
The rig's own params (plants/arm_rig/params.py) hold what every engine reads; these were flat
there before (``migrate`` there moves an old scenario's or log's flat ones in here)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from replay.params import param


@dataclass
class PybulletSettings:
    type: str = param("pybullet", choices=("pybullet",), doc="the engine: PyBullet")
    object_rolling_friction: float = param(
        0.0, unit="m", ge=0.0, le=10, doc="PyBullet rolling friction of the object"
    )
    object_spinning_friction: float = param(
        0.0, unit="m", ge=0.0, le=10, doc="PyBullet spinning friction of the object"
    )
    object_restitution: float = param(
        0.6, unit="1", ge=0.0, le=1.0, doc="PyBullet restitution (multiplied with the robot's)"
    )
    hand_restitution: float = param(
        0.3, unit="1", ge=0.0, le=1.0, doc="PyBullet restitution of the robot's links"
    )
    contact_stiffness: float = param(
        0.0,
        unit="N/m",
        ge=0.0,
        le=1e12,
        doc="object contact stiffness; 0 = PyBullet's rigid contact",
    )
    contact_damping: float = param(
        0.0,
        unit="N*s/m",
        ge=0.0,
        le=1e9,
        doc="object contact damping (used with contact_stiffness)",
    )
    solver_iterations: int = param(50, ge=1, le=1000, doc="PyBullet constraint solver iterations")

    arm: ClassVar[str] = "plants.bullet_arm.plant:PybulletEngine"
    grasp: ClassVar[str] = "plants.bullet_arm.grasp_plant:PybulletGraspEngine"
