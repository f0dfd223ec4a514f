"""PyBullet, imported once with its C build banner kept off the command line's output (its
import prints "pybullet build time: ..." to the process's stdout): every module of the plant
imports the engine from here."""

from plants.bullet_arm.quiet import quiet_c_output

with quiet_c_output():
    import pybullet
    from pybullet_utils import bullet_client

__all__ = ["bullet_client", "pybullet"]
