"""The MuJoCo arm plant in the browser viewer: the PyBullet arm plant's scene (the same URDF from
``plants.models``, the free object, cameras), the plant's own ``Params`` read from the log.
Registered under the plants' types (``paper_replay.viewer_scenes`` ``mujoco_arm``,
``mujoco_grasp``). No simulator is imported."""

from __future__ import annotations

from plants.arm_rig.grasp_viewer_scene import GraspScene
from plants.arm_rig.viewer_scene import ArmScene
from plants.mujoco_arm.params import GraspParams, Params


class MujocoArmScene(ArmScene):
    Params = Params


class MujocoGraspScene(GraspScene):
    """The grasping rig in MuJoCo (``mujoco_grasp``): the PyBullet rig's scene (head, chip image,
    plane, the recognised object), the MuJoCo rig's ``GraspParams`` read from the log."""

    Params = GraspParams  # type: ignore[assignment]  # the subclass adds MuJoCo's fields
