"""The Foxglove layout of the catch's logs (``replay layout namiki2003``; docs/foxglove.md)."""

from __future__ import annotations

from typing import Any

from replay.foxglove.layouts import camera, image, log, page, plot, split, three_d
from replay.foxglove.topics import camera_topic


def layout() -> dict[str, Any]:
    """WAM-4 + hand, ball from x = 3.2 m, stereo cameras."""
    three = three_d(
        "3-D: arm (URDF + /tf), ball and scene (/scene)",
        camera(3.2, 65.0, -40.0, [1.1, 0.0, 0.6]),
        urdf=True,
        grid=4,
    )
    images = split(
        "row",
        (1, image(camera_topic("stereo", "cam0"), "stereo cam0")),
        (1, image(camera_topic("stereo", "cam1"), "stereo cam1")),
    )
    quantities = plot(
        "ball height and joint angles",
        [
            ("ball z (m)", "/object/state.position[2]"),
            ("J1 (rad)", "/joint_states.joints[0].position"),
            ("J2 (rad)", "/joint_states.joints[1].position"),
            ("J4 (rad)", "/joint_states.joints[3].position"),
        ],
    )
    return page(three, split("column", (1, images), (1, quantities), (1, log())))
