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
        finger, by ``replay.hand2d``'s kinematics."""
        l1, l2 = self.link_lengths
        out = np.zeros((2, 3, 2))
        for k in range(2):
            q1, q2 = joints[k]
            root = np.asarray(base, float) + np.asarray(self.root_offsets[k])
            elbow = root + l1 * np.array([math.cos(q1), math.sin(q1)])
            tip = elbow + l2 * np.array([math.cos(q1 + q2), math.sin(q1 + q2)])
            out[k] = (root, elbow, tip)
        return out


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
    """URDF roll-pitch-yaw (fixed axes x, y, z) as a [w, x, y, z] quaternion."""
    r, p, y = (float(v) / 2.0 for v in rpy)
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), \
        math.cos(y), math.sin(y)
    return (cr * cp * cy + sr * sp * sy, sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy, cr * cp * sy - sr * sp * cy)


# --------------------------------------------------------------------------- cameras
@dataclass(frozen=True)
class CameraPose:
    name: str
    position: tuple[float, float, float]
    wxyz: tuple[float, float, float, float]    # camera-to-world, OpenCV axes (z forward, y down)
    fov_y: float                               # rad, vertical
    aspect: float                              # width / height


_POS_KEYS = ("position", "eye", "camera_position", "pos", "origin")
_TARGET_KEYS = ("target", "look_at", "lookat", "center")
_FOVX_KEYS = ("fov_x", "fov", "hfov", "fov_horizontal")


def _vec3(v):
    if isinstance(v, (list, tuple)) and len(v) == 3 and all(isinstance(x, (int, float))
                                                           for x in v):
        return np.asarray(v, dtype=float)
    return None


def _look_at_matrix(eye, target, up) -> np.ndarray | None:
    z = target - eye
    if np.linalg.norm(z) == 0:
        return None
    z = z / np.linalg.norm(z)
    x = np.cross(-np.asarray(up, float), z)
    if np.linalg.norm(x) < 1e-9:                      # looking straight along "up"
        x = np.cross([0.0, -1.0, 0.0], z) if abs(z[1]) < 0.9 else np.cross([-1.0, 0, 0], z)
    x = x / np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _matrix_to_wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    import viser.transforms as vtf
    w, x, y, z = vtf.SO3.from_matrix(R).wxyz
    return (float(w), float(x), float(y), float(z))


def _camera_from_dict(name: str, d: dict) -> CameraPose | None:
    eye = next((_vec3(d[k]) for k in _POS_KEYS if _vec3(d.get(k)) is not None), None)
    if eye is None:
        return None
    R = None
    target = next((_vec3(d[k]) for k in _TARGET_KEYS if _vec3(d.get(k)) is not None), None)
    if target is not None:
        up = _vec3(d.get("up"))
        R = _look_at_matrix(eye, target, up if up is not None else np.array([0.0, 0.0, 1.0]))
    elif isinstance(d.get("rotation"), list) and np.shape(d["rotation"]) == (3, 3):
        R = np.asarray(d["rotation"], dtype=float)
    if R is None:
        return None
    w, h = d.get("width"), d.get("height")
    res = d.get("resolution") or d.get("image_size")
    if (w is None or h is None) and isinstance(res, list) and len(res) == 2:
        w, h = res
    w, h = float(w or 128), float(h or 128)
    fov_x = next((float(d[k]) for k in _FOVX_KEYS if isinstance(d.get(k), (int, float))), None)
    if fov_x is None and isinstance(d.get("fov_deg"), (int, float)):
        fov_x = math.radians(float(d["fov_deg"]))
    fx = d.get("fx") or d.get("focal_px")
    if isinstance(fx, (int, float)) and fx > 0:
        fov_y = 2.0 * math.atan((h / 2.0) / float(d.get("fy") or fx))
    elif fov_x is not None and 0 < fov_x < math.pi:
        fov_y = 2.0 * math.atan(math.tan(fov_x / 2.0) * h / w)
    else:
        fov_y = math.radians(40.0)
    return CameraPose(name, tuple(float(v) for v in eye), _matrix_to_wxyz(R), fov_y, w / h)


def _walk_cameras(name: str, obj, out: list) -> None:
    if isinstance(obj, dict):
        cam = _camera_from_dict(name, obj)
        if cam is not None:
            out.append(cam)
            return
        for k, v in obj.items():
            if isinstance(v, (dict, list)):
                _walk_cameras(f"{name}/{k}", v, out)
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            _walk_cameras(f"{name}/{i}", v, out)


def cameras(sensors: dict) -> tuple[list[CameraPose], list[str]]:
    """Camera poses found in ``sensors.*.params`` (a position plus a target or rotation, any
    nesting, e.g. a stereo pair's list), and the names of camera-like sensors without one."""
    found: list[CameraPose] = []
    missing: list[str] = []
    for name, spec in (sensors or {}).items():
        if not isinstance(spec, dict):
            continue
        params = spec.get("params") or {}
        before = len(found)
        _walk_cameras(str(name), params, found)
        kind = str(spec.get("type", ""))
        if len(found) == before and any(w in kind for w in ("camera", "vision", "stereo")):
            missing.append(str(name))
    return found, missing
