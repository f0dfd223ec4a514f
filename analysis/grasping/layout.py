"""The Foxglove layout of the grasp's logs (``replay layout namiki1999``; docs/foxglove.md)."""

from __future__ import annotations

from typing import Any

from replay.foxglove.layouts import camera, image, log, page, plot, split, three_d
from replay.foxglove.topics import camera_topic


def layout() -> dict[str, Any]:
    """WAM-7 + 14-joint hand, the object moved by the human."""
    three = three_d(
        "3-D: arm and hand (URDF + /tf), object and human hand (/scene)",
        camera(1.6, 60.0, -50.0, [0.55, 0.0, 0.45]),
        urdf=True,
        grid=2,
    )
    quantities = plot(
        "object and wrist force",
        [
            ("object x (m)", "/object/state.position[0]"),
            ("object y (m)", "/object/state.position[1]"),
            ("object z (m)", "/object/state.position[2]"),
            ("wrist F_z (N)", "/wrist/wrench.force[2]"),
        ],
    )
    right = split(
        "column",
        (1, image(camera_topic("chip", "image"), "vision chip (16 x 16, 1 kHz)")),
        (1, quantities),
        (1, log()),
    )
    return page(three, right)
