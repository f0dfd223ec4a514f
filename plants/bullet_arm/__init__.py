"""PyBullet arm plant: a WAM (4/7 axes, torque control), a hand (position control), an object."""

import os
import sys


def _import_pybullet_quietly() -> None:
    """PyBullet's C module prints a build banner on stdout at import: keep it off our output."""
    sys.stdout.flush()
    saved = os.dup(1)
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        import pybullet  # noqa: F401
    finally:
        os.dup2(saved, 1)
        os.close(saved)
        os.close(devnull)


_import_pybullet_quietly()

from plants.bullet_arm.plant import BulletArmPlant, Params  # noqa: E402

__all__ = ["BulletArmPlant", "Params"]
