"""PyBullet arm plant: a WAM (4/7 axes, torque control), a hand (position control), an object.

``params``, ``settings`` and ``viewer_scene`` import no simulator; ``BulletArmPlant`` (PyBullet)
is imported when first asked for.
"""

from plants.bullet_arm.params import Params

__all__ = ["BulletArmPlant", "Params"]


def __getattr__(name: str):
    if name == "BulletArmPlant":
        from plants.bullet_arm.plant import BulletArmPlant

        return BulletArmPlant
    raise AttributeError(f"module 'plants.bullet_arm' has no attribute {name!r}")
