"""What the scene is made of, from the run's resolved scenario (with the plants' defaults).

No simulator is imported here: the air table's sizes come from ``plant.params``; an arm's URDF
is built by ``plants.models`` (pure NumPy, the very file the PyBullet plant loads); cameras'
poses from ``sensors.*.params``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from replay.robot.hand2d import finger_chain
from replay.robot.serial_chain import matrix_to_quaternion, rpy_to_matrix
from replay.robot.wam import DEFAULT_VELOCITY_LIMIT
from replay.viewer.errors import ViewerError


def _get(d: dict, path: str, default):
    cur = d
    for key in path.split("."):
        if not isinstance(cur, dict) or key not in cur:
            return default
        cur = cur[key]
    return default if cur is None else cur


# --------------------------------------------------------------------------- air table
@dataclass(frozen=True)
class StickGeometry:
    """Air table sizes (m); defaults are the air-table plant's (Higashimori et al. 2007)."""
    length: float = 0.100
    visual_width: float = 0.010
    thickness: float = 0.005
    marker_length: float = 0.080
    marker_width: float = 0.006
    tip_radius: float = 0.005
    tip_height: float = 0.020
    link_lengths: tuple[float, float] = (0.07, 0.07)
    root_offsets: tuple[tuple[float, float], tuple[float, float]] = ((-0.03, 0.0), (0.03, 0.0))

    @classmethod
    def from_params(cls, p: dict) -> "StickGeometry":
        d = cls()
        f = lambda path, default: float(_get(p, path, default))  # noqa: E731
        lengths = _get(p, "hand.link_lengths", d.link_lengths)
        r0 = _get(p, "hand.root_offset0", d.root_offsets[0])
        r1 = _get(p, "hand.root_offset1", d.root_offsets[1])
        return cls(length=f("stick.length", d.length),
                   visual_width=f("stick.visual_width", d.visual_width),
                   thickness=f("stick.thickness", d.thickness),
                   marker_length=f("stick.marker_length", d.marker_length),
                   marker_width=f("stick.marker_width", d.marker_width),
                   tip_radius=f("hand.tip_radius", d.tip_radius),
                   tip_height=f("hand.tip_height", d.tip_height),
                   link_lengths=(float(lengths[0]), float(lengths[1])),
                   root_offsets=((float(r0[0]), float(r0[1])), (float(r1[0]), float(r1[1]))))

    def finger_points(self, base, joints) -> np.ndarray:
        """(2 fingers, 3 points: root, elbow, tip, 2) from the slider base and (q1, q2) per
        finger, by ``replay.robot.hand2d``'s kinematics."""
        return np.array([finger_chain(base, self.root_offsets[k], self.link_lengths, joints[k])
                         for k in range(2)])


# --------------------------------------------------------------------------- arms
@dataclass(frozen=True)
class FreeObject:
    kind: str                                  # ball | box | none
    radius: float = 0.0175
    size: tuple[float, float, float] = (0.05, 0.05, 0.05)


def free_object(p: dict) -> FreeObject:
    kind = str(_get(p, "object", "ball"))
    return FreeObject(kind=kind, radius=float(_get(p, "object_radius", 0.0175)),
                      size=tuple(float(s) for s in _get(p, "object_size", [0.05, 0.05, 0.05])))


def plant_models_urdf(p: dict) -> Path:
    """The arm plant's URDF for these ``plant.params``, built the way the plant builds it
    (``plants.bullet_arm.plant.BulletArmPlant.__init__``), so it lands at the same cached path."""
    from plants.models.arm import build_arm
    from replay.robot.hand import HANDS
    from replay.robot.wam import (TORQUE_LIMIT_SETS, default_tool_d, load_wam_table,
                                  wam_joint_names)
    arm = str(_get(p, "arm", "wam4"))
    dof = 4 if arm == "wam4" else 7
    table = load_wam_table()
    tool_d = float(_get(p, "tool_d", -1.0))
    tool_d = default_tool_d(dof, table) if tool_d < 0 else tool_d
    hand_name = str(_get(p, "hand", "catch3"))
    hand = None if hand_name == "none" else HANDS[hand_name]
    names = wam_joint_names(dof, table)
    q0 = list(_get(p, "initial_q", [])) or [0.0] * dof
    locked = {n: float(q0[names.index(n)]) for n in _get(p, "locked_joints", [])}
    tau = list(_get(p, "torque_limits", [])) or \
        list(TORQUE_LIMIT_SETS[str(_get(p, "torque_limit_set", "public_urdf"))][:dof])
    vel = list(_get(p, "velocity_limits", [])) or [DEFAULT_VELOCITY_LIMIT] * dof
    model = build_arm(dof, tool_d=tool_d, hand=hand, locked=locked, torque_limits=tau,
                      velocity_limits=vel, table=table)
    return Path(model.write())


# Where an arm run's URDF comes from: ``plant.params`` -> path. Tests and other plants may
# point this elsewhere (``Viewer(urdf_for=...)`` takes precedence).
URDF_FOR: Callable[[dict], Path] = plant_models_urdf


def arm_urdf(p: dict, urdf_for: Callable[[dict], Path] | None = None) -> Path:
    fn = urdf_for or URDF_FOR
    try:
        path = Path(fn(p))
    except Exception as exc:  # noqa: BLE001 - any failure is one line in the view
        raise ViewerError(f"cannot build the arm's URDF ({exc.__class__.__name__}: {exc})") \
            from None
    if not path.is_file():
        raise ViewerError(f"arm URDF {path} not found")
    return path


def rpy_to_wxyz(rpy) -> tuple[float, float, float, float]:
    """URDF roll-pitch-yaw (fixed axes x, y, z) as a [w, x, y, z] quaternion (viser's order)."""
    return _matrix_to_wxyz(rpy_to_matrix(rpy))


# --------------------------------------------------------------------------- cameras
@dataclass(frozen=True)
class CameraPose:
    name: str
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]    # camera-to-world, OpenCV axes (z forward, y down)
    fov_y: float                               # rad, vertical
    aspect: float                              # width / height


def _matrix_to_wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    x, y, z, w = matrix_to_quaternion(R)
    return (float(w), float(x), float(y), float(z))


def _pose(name: str, cam) -> CameraPose:
    """A pinhole camera (replay.sensors.pinhole) as the viewer draws it."""
    k = cam.intrinsics
    fov_y = 2.0 * math.atan((k.height / 2.0) / k.fy)
    return CameraPose(name, tuple(float(v) for v in cam.position), _matrix_to_wxyz(cam.rotation),
                      fov_y, k.width / k.height)


def cameras(sensors: dict) -> tuple[list[CameraPose], list[str]]:
    """The camera poses of a scenario's ``sensors`` (the resolved YAML as a dict), from each camera
    sensor's own model (its ``make_camera`` / ``make_cameras`` of its Params), and the names of
    camera sensors whose pose could not be had (unknown type, invalid params)."""
    import yaml

    from replay import registry
    from replay.scenario.loader import ScenarioError, build_dataclass

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
        if make is None:                       # not a camera (e.g. joint encoders)
            continue
        try:
            node = yaml.compose(yaml.safe_dump(spec.get("params") or {}))
            params = build_dataclass(node, cls.Params, f"sensors.{name}.params")
        except ScenarioError:
            missing.append(str(name))
            continue
        made = make(params)
        made = list(made) if isinstance(made, (list, tuple)) else [made]
        found += [_pose(str(name) if len(made) == 1 else f"{name}/{i}", cam)
                  for i, cam in enumerate(made)]
    return found, missing
