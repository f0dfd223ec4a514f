"""The grasping rig as the plant tests build it (shared by the plant, vision and loop tests)."""

from __future__ import annotations

import numpy as np

from plants.bullet_arm.grasp_plant import BulletGraspPlant
from plants.bullet_arm.params import GraspParams

DT = 1e-3
Q0 = [0.0, 0.533482, 0.0, 2.134676, 0.0, -1.0973, 0.0]  # scenarios/grasp_hexahedron.yaml


def rig(**kw) -> BulletGraspPlant:
    base = dict(
        arm="wam7",
        hand="grasp4",
        object="box",
        object_size=[0.05, 0.10, 0.05],
        object_mass=0.1,
        object_position=[0.75, 0.0, 0.55],
        initial_q=Q0,
        head_position=[0.0, 0.15, 0.70],
        human_speed=0.0,
        human_roll_rate=0.0,
        velocity_limits=[3.0] * 7,
    )
    base.update(kw)
    return BulletGraspPlant(GraspParams(**base), dt=DT, rng=np.random.default_rng(0))
