"""The Drake arm plant in the browser viewer: the arm rig's scene (the same URDF from
``plants.models``, the free object, cameras), the plant's own ``Params`` read from the log.
Registered under the plants' types (``paper_replay.viewer_scenes`` ``drake_arm``,
``drake_grasp``). No simulator is imported."""

from __future__ import annotations

from plants.arm_rig.grasp_viewer_scene import GraspScene
from plants.arm_rig.viewer_scene import ArmScene
from plants.drake_arm.params import GraspParams, Params


class DrakeArmScene(ArmScene):
    Params = Params


class DrakeGraspScene(GraspScene):
    """The grasping rig in Drake (``drake_grasp``): the rig's scene (head, chip image, plane, the
    recognised object), the Drake rig's ``GraspParams`` read from the log."""

    Params = GraspParams  # type: ignore[assignment]  # the subclass adds Drake's fields
