"""Cameras from the run's resolved scenario, as the viewer draws them.

No simulator is imported here: each camera sensor's pose comes from its own model (its
``make_camera`` / ``make_cameras`` of its typed ``Params``, rebuilt by the scenario loader).
What a plant's scene is made of (sizes, URDFs) is its own viewer scene's business
(e.g. ``plants/airtable/viewer_scene.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from replay.spatial import matrix_to_wxyz


# --------------------------------------------------------------------------- cameras
@dataclass(frozen=True)
class CameraPose:
    name: str
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]  # camera-to-world, OpenCV axes (z forward, y down)
    fov_y: float  # rad, vertical
    aspect: float  # width / height


def _pose(name: str, cam) -> CameraPose:
    """A pinhole camera (replay.sensors.pinhole) as the viewer draws it."""
    k = cam.intrinsics
    fov_y = 2.0 * math.atan((k.height / 2.0) / k.fy)
    x, y, z = (float(v) for v in cam.position)
    return CameraPose(name, (x, y, z), matrix_to_wxyz(cam.rotation), fov_y, k.width / k.height)


def cameras(sensors: dict) -> tuple[list[CameraPose], list[str]]:
    """The camera poses of a scenario's ``sensors`` (the resolved YAML as a dict), from each camera
    sensor's own model (its ``make_camera`` / ``make_cameras`` of its Params), and the names of
    camera sensors whose pose could not be had (unknown type, invalid params)."""
    from replay import registry
    from replay.scenario import ScenarioError, params_from_data

    found: list[CameraPose] = []
    missing: list[str] = []
    for name, spec in (sensors or {}).items():
        if not isinstance(spec, dict):
            continue
        try:
            cls = registry.load("sensor", str(spec.get("type", "")))
        except registry.UnknownPlugin:
            missing.append(str(name))
            continue
        make = getattr(cls, "make_cameras", None) or getattr(cls, "make_camera", None)
        if make is None:  # not a camera (e.g. joint encoders)
            continue
        try:
            params = params_from_data(cls.Params, spec.get("params"), f"sensors.{name}.params")
        except ScenarioError:
            missing.append(str(name))
            continue
        made = make(params)
        made = list(made) if isinstance(made, (list, tuple)) else [made]
        found += [
            _pose(str(name) if len(made) == 1 else f"{name}/{i}", cam) for i, cam in enumerate(made)
        ]
    return found, missing
