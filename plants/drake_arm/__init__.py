"""Drake arm plant: the arm rig's catching and grasping rigs (WAM, hand, a free object) in a third
physics engine, pydrake's MultibodyPlant, from the same robot tables and URDF (``plants.models``).

``params`` and ``viewer_scene`` import no simulator; ``DrakeArmPlant`` (pydrake) is imported when
first asked for. docs/drake.md says what differs from PyBullet and MuJoCo and why.
"""

from plants.drake_arm.params import Params

__all__ = ["DrakeArmPlant", "Params"]


def __getattr__(name: str):
    if name == "DrakeArmPlant":
        from plants.drake_arm.plant import DrakeArmPlant

        return DrakeArmPlant
    raise AttributeError(f"module 'plants.drake_arm' has no attribute {name!r}")
