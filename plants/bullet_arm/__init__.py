"""The arm rig's PyBullet engine adapter (``plant.params.engine: {type: pybullet, ...}``):
``engine.PybulletEngine`` and ``grasp_plant.PybulletGraspEngine``, their settings
(``settings.PybulletSettings``), motors, wrist F/T sensor and human hand. The rig itself is
engine-free (``plants.arm_rig``)."""
