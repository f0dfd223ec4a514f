"""PyBullet arm plant: a WAM (4/7 axes, torque control), a hand (position control), an object."""

from plants.bullet_arm.quiet import quiet_c_output

with quiet_c_output():
    import pybullet  # noqa: F401  (its import prints a build banner)

from plants.bullet_arm.plant import BulletArmPlant, Params  # noqa: E402

__all__ = ["BulletArmPlant", "Params"]
