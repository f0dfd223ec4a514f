"""PyBullet arm plant: a WAM (4/7 axes, torque control), a hand (position control), an object.

Its ``Params``, settings and viewer scene are the engine-free rig's (``plants.arm_rig``);
``BulletArmPlant`` (PyBullet) is imported when first asked for.
"""

from plants.arm_rig.params import Params

__all__ = ["BulletArmPlant", "Params"]


def __getattr__(name: str):
    if name == "BulletArmPlant":
        from plants.bullet_arm.plant import BulletArmPlant

        return BulletArmPlant
    raise AttributeError(f"module 'plants.bullet_arm' has no attribute {name!r}")
