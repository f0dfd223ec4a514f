"""The human hand of the grasping rig in PyBullet: ``human_path.HumanPath`` (the seeded path and
the spring-damper coupling, engine-free) with its force and torque applied to the object's base
each step."""

from __future__ import annotations

import numpy as np
from plants.bullet_arm.engine import pybullet as p

from plants.arm_rig.human_path import HumanPath, band_limited_path, numpy_row_sum

__all__ = ["HumanHand", "HumanPath", "band_limited_path", "numpy_row_sum"]


class HumanHand(HumanPath):
    def __init__(self, bc, obj: int, rng: np.random.Generator, **kw) -> None:
        super().__init__(rng, **kw)
        self.bc, self.obj = bc, obj

    def drive(self, t: float, pos, orn, vel, omega) -> None:
        """The coupling's wrench at ``t`` (HumanPath.drive), applied for the next physics step."""
        super().drive(t, pos, orn, vel, omega)
        self.bc.applyExternalForce(self.obj, -1, self.force_l, list(pos), p.WORLD_FRAME)
        self.bc.applyExternalTorque(self.obj, -1, self.torque_l, p.WORLD_FRAME)
