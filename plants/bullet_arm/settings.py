"""PyBullet's entry in the engine field (``plant.params.engine: {type: pybullet}``,
plants/arm_rig/engine.py): no settings of its own yet (its contact and solver fields are the rig's
params: ``solver_iterations``, ``*_restitution``, ``contact_stiffness``, ...), and its adapters."""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from replay.params import param


@dataclass
class PybulletSettings:
    type: str = param("pybullet", choices=("pybullet",), doc="the engine: PyBullet")

    arm: ClassVar[str] = "plants.bullet_arm.plant:PybulletEngine"
    grasp: ClassVar[str] = "plants.bullet_arm.grasp_plant:PybulletGraspEngine"
