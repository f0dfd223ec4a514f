"""Foxglove layouts, one per paper (``replay layout PAPER -o FILE``; docs/foxglove.md).

Plain JSON in the shape Foxglove imports (the keys are those the Foxglove SDK's typed layout API
writes: the catch layout was first made with it, and ``tests/replay/foxglove/test_layouts.py``
holds this module to that file). Each layout has a 3-D panel on ``world`` (the URDF from
``/robot_description`` where the plant has one, ``/tf`` and ``/scene``), the run's camera images
where it logs them, a plot of the paper's quantities and the events as log lines (``/log``).
"""

from __future__ import annotations

import json
from typing import Any

from replay.foxglove.topics import camera_topic

PAPERS = ("higashimori2007", "namiki2003", "namiki1999")


def _panel(kind: str, title: str, config: dict[str, Any]) -> dict[str, Any]:
    return {"type": "panel", "panelType": kind, "config": config, "title": title, "version": 1}


def _split(direction: str, *items: tuple[float, dict[str, Any]]) -> dict[str, Any]:
    return {
        "type": "split",
        "direction": direction,
        "items": [{"proportion": p, "content": c} for p, c in items],
    }


def _three_d(title: str, camera: dict[str, Any], urdf: bool, grid: float) -> dict[str, Any]:
    layers: dict[str, Any] = {}
    if urdf:
        layers["robot"] = {
            "instanceId": "robot",
            "layerId": "foxglove.Urdf",
            "label": "robot (/robot_description)",
            "sourceType": "topic",
            "topic": "/robot_description",
            "displayMode": "visual",
        }
    layers["grid"] = {
        "instanceId": "grid",
        "layerId": "foxglove.Grid",
        "frameId": "world",
        "size": grid,
        "divisions": 40,
    }
    return _panel(
        "ThreeDee",
        title,
        {
            "layers": layers,
            "topics": {"/scene": {"visible": True}},
            "cameraState": camera,
            "followTf": "world",
            "followMode": "follow-none",
        },
    )


def _image(topic: str, title: str) -> dict[str, Any]:
    return _panel("Image", title, {"imageMode": {"imageTopic": topic}})


def _plot(title: str, series: list[tuple[str, str]]) -> dict[str, Any]:
    paths = [{"enabled": True, "label": label, "value": value} for label, value in series]
    return _panel("Plot", title, {"paths": paths, "showLegend": True})


def _log() -> dict[str, Any]:
    return _panel("Log", "events (/log)", {"topicToRender": "/log"})


def _camera(distance: float, phi: float, theta: float, target: list[float]) -> dict[str, Any]:
    return {
        "distance": distance,
        "perspective": True,
        "phi": phi,
        "target": target,
        "thetaOffset": theta,
    }


def layout(paper: str) -> dict[str, Any]:
    """The layout of ``paper`` (a key of :data:`PAPERS`) as a JSON-ready dict."""
    if paper == "namiki2003":  # the catch: WAM-4 + hand, ball from x = 3.2 m, stereo cameras
        three = _three_d(
            "3-D: arm (URDF + /tf), ball and scene (/scene)",
            _camera(3.2, 65.0, -40.0, [1.1, 0.0, 0.6]),
            urdf=True,
            grid=4,
        )
        images = _split(
            "row",
            (1, _image(camera_topic("stereo", "cam0"), "stereo cam0")),
            (1, _image(camera_topic("stereo", "cam1"), "stereo cam1")),
        )
        plot = _plot(
            "ball height and joint angles",
            [
                ("ball z (m)", "/object/state.position[2]"),
                ("J1 (rad)", "/joint_states.joints[0].position"),
                ("J2 (rad)", "/joint_states.joints[1].position"),
                ("J4 (rad)", "/joint_states.joints[3].position"),
            ],
        )
        right = _split("column", (1, images), (1, plot), (1, _log()))
    elif paper == "namiki1999":  # the grasp: WAM-7 + 14-joint hand, object moved by the human
        three = _three_d(
            "3-D: arm and hand (URDF + /tf), object and human hand (/scene)",
            _camera(1.6, 60.0, -50.0, [0.55, 0.0, 0.45]),
            urdf=True,
            grid=2,
        )
        plot = _plot(
            "object and wrist force",
            [
                ("object x (m)", "/object/state.position[0]"),
                ("object y (m)", "/object/state.position[1]"),
                ("object z (m)", "/object/state.position[2]"),
                ("wrist F_z (N)", "/wrist/wrench.force[2]"),
            ],
        )
        right = _split(
            "column",
            (1, _image(camera_topic("chip", "image"), "vision chip (16 x 16, 1 kHz)")),
            (1, plot),
            (1, _log()),
        )
    elif paper == "higashimori2007":  # the stick on the air table, two fingertips (no URDF)
        three = _three_d(
            "3-D: air table, stick and fingertips (/scene)",
            _camera(0.9, 10.0, 0.0, [0.0, 0.2, 0.0]),
            urdf=False,
            grid=1,
        )
        plot = _plot(
            "stick state",
            [
                ("x (m)", "/stick/state.x"),
                ("y (m)", "/stick/state.y"),
                ("vx (m/s)", "/stick/state.vx"),
                ("vy (m/s)", "/stick/state.vy"),
                ("ω (rad/s)", "/stick/state.omega"),
            ],
        )
        right = _split("column", (2, plot), (1, _log()))
    else:
        raise KeyError(f"no layout for paper {paper!r} (one of {', '.join(PAPERS)})")
    return {"version": 1, "content": _split("row", (3, three), (2, right))}


def layout_json(paper: str) -> str:
    """The layout as the text of a file Foxglove imports (Layout -> Import from file)."""
    return json.dumps(layout(paper), ensure_ascii=False) + "\n"
