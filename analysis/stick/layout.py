"""The Foxglove layout of the stick's logs (``replay layout higashimori2007``; docs/foxglove.md)."""

from __future__ import annotations

from typing import Any

from replay.foxglove.layouts import camera, log, page, plot, split, three_d


def layout() -> dict[str, Any]:
    """The stick on the air table, two fingertips (no URDF)."""
    three = three_d(
        "3-D: air table, stick and fingertips (/scene)",
        camera(0.9, 10.0, 0.0, [0.0, 0.2, 0.0]),
        urdf=False,
        grid=1,
    )
    quantities = plot(
        "stick state",
        [
            ("x (m)", "/stick/state.x"),
            ("y (m)", "/stick/state.y"),
            ("vx (m/s)", "/stick/state.vx"),
            ("vy (m/s)", "/stick/state.vy"),
            ("ω (rad/s)", "/stick/state.omega"),
        ],
    )
    return page(three, split("column", (2, quantities), (1, log())))
