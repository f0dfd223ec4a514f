"""Foxglove layouts, one per paper (``replay layout PAPER -o FILE``; docs/foxglove.md): the
panels they are made of; each paper's layout is its registration's ``layout`` (replay.papers).

Plain JSON in the shape Foxglove imports (the keys are those the Foxglove SDK's typed layout API
writes: the catch layout was first made with it, and
``tests/replay/test_shipped_building_blocks.py`` holds it to that file). Each layout has a 3-D panel on ``world`` (the URDF from
``/robot_description`` where the plant has one, ``/tf`` and ``/scene``), the run's camera images
where it logs them, a plot of the paper's quantities and the events as log lines (``/log``).
"""

from __future__ import annotations

import json
from typing import Any


def panel(kind: str, title: str, config: dict[str, Any]) -> dict[str, Any]:
    return {"type": "panel", "panelType": kind, "config": config, "title": title, "version": 1}


def split(direction: str, *items: tuple[float, dict[str, Any]]) -> dict[str, Any]:
    return {
        "type": "split",
        "direction": direction,
        "items": [{"proportion": p, "content": c} for p, c in items],
    }


def three_d(title: str, camera: dict[str, Any], urdf: bool, grid: float) -> dict[str, Any]:
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
    return panel(
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


def image(topic: str, title: str) -> dict[str, Any]:
    return panel("Image", title, {"imageMode": {"imageTopic": topic}})


def plot(title: str, series: list[tuple[str, str]]) -> dict[str, Any]:
    paths = [{"enabled": True, "label": label, "value": value} for label, value in series]
    return panel("Plot", title, {"paths": paths, "showLegend": True})


def log() -> dict[str, Any]:
    return panel("Log", "events (/log)", {"topicToRender": "/log"})


def camera(distance: float, phi: float, theta: float, target: list[float]) -> dict[str, Any]:
    return {
        "distance": distance,
        "perspective": True,
        "phi": phi,
        "target": target,
        "thetaOffset": theta,
    }


def page(three: dict[str, Any], right: dict[str, Any]) -> dict[str, Any]:
    """A paper's layout: its 3-D panel on the left, ``right`` (images, plot, events) beside it."""
    return {"version": 1, "content": split("row", (3, three), (2, right))}


def layout(paper: str) -> dict[str, Any]:
    """The layout of ``paper`` (a registered paper's key) as a JSON-ready dict."""
    from replay.papers import papers, resolve

    with_layout = {key: p.layout for key, p in papers().items() if p.layout}
    if paper not in with_layout:
        raise KeyError(f"no layout for paper {paper!r} (one of {', '.join(with_layout)})")
    return resolve(with_layout[paper])()


def layout_json(paper: str) -> str:
    """The layout as the text of a file Foxglove imports (Layout -> Import from file)."""
    return json.dumps(layout(paper), ensure_ascii=False) + "\n"
