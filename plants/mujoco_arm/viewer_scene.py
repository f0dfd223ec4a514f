"""The MuJoCo arm plant in the browser viewer: the PyBullet arm plant's scene (the same URDF from
``plants.models``, the free object, cameras), the plant's own ``Params`` read from the log.
Registered under the plant's type (``paper_replay.viewer_scenes`` ``mujoco_arm``). No simulator
is imported."""

from __future__ import annotations

from plants.bullet_arm.viewer_scene import ArmScene
from plants.mujoco_arm.params import Params


class MujocoArmScene(ArmScene):
    Params = Params
