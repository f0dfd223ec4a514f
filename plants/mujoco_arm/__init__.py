"""MuJoCo arm plant: the arm rig's catching rig (WAM, hand, a free object) in a second
physics engine, from the same robot tables and URDF generator (``plants.models``).

``params``, ``settings`` and ``viewer_scene`` import no simulator; ``MujocoArmPlant`` (MuJoCo) is
imported when first asked for. docs/mujoco.md says what differs from PyBullet and why.
"""

from plants.mujoco_arm.params import Params

__all__ = ["MujocoArmPlant", "Params"]


def __getattr__(name: str):
    if name == "MujocoArmPlant":
        from plants.mujoco_arm.plant import MujocoArmPlant

        return MujocoArmPlant
    raise AttributeError(f"module 'plants.mujoco_arm' has no attribute {name!r}")
