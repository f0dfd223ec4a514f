"""PyBullet arm plant: a WAM (4/7 axes, torque control), a hand (position control), an object."""

from plants.bullet_arm.plant import BulletArmPlant, Params

__all__ = ["BulletArmPlant", "Params"]
