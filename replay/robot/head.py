"""A 2-axis pan/tilt active-vision head (Namiki et al. 1999, Sec. 3.2) as a simulator-free model.

The head's base sits at ``position`` turned by ``yaw`` about world +z. Pan rotates about the
base's z axis (world vertical), then tilt about the panned y axis (positive tilt = looking
down); the camera sits ``camera_offset`` ahead of the tilt axis along the line of sight. At
pan = tilt = 0 the camera looks along the base's x axis with the image's up = world +z.

Camera frame (OpenCV, as ``replay.sensors.pinhole``): x right, y down, z along the line of sight;
``camera_pose`` returns the camera-to-world rotation and the optical centre. The plant, the
vision chip sensor and the method all use this one model; the paper gives no head geometry, so
every number of a ``HeadSpec`` is a scenario's assumption.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class HeadSpec:
    position: tuple[float, float, float]  # m, world: the pan/tilt axes' intersection
    yaw: float  # rad, base heading about world +z
    camera_offset: float  # m, camera ahead of the tilt axis
    lower: tuple[float, float]  # rad, (pan, tilt) limits
    upper: tuple[float, float]
    inertia: tuple[float, float]  # kg m^2, about each axis
    torque_limit: tuple[float, float]  # N m, each DC servo
    velocity_limit: tuple[float, float]  # rad/s


def camera_pose(head: HeadSpec, pan: float, tilt: float) -> tuple[np.ndarray, np.ndarray]:
    """(camera-to-world rotation 3x3, optical centre [3]) at joint angles (pan, tilt)."""
    a = head.yaw + pan
    ca, sa = math.cos(a), math.sin(a)
    ct, st = math.cos(tilt), math.sin(tilt)
    # line of sight: the base x axis panned by a, tilted down by ``tilt``
    # line of sight fwd = (ca ct, sa ct, -st), tilt axis left = (-sa, ca, 0), image up =
    # fwd x left = (st ca, st sa, ct); camera x = -left (right), y = -up (down), z = fwd
    R = np.array([[sa, -st * ca, ca * ct], [-ca, -st * sa, sa * ct], [0.0, -ct, -st]])
    p, k = head.position, head.camera_offset
    return R, np.array([p[0] + k * ca * ct, p[1] + k * sa * ct, p[2] - k * st])


def look_angles(head: HeadSpec, point) -> tuple[float, float]:
    """(pan, tilt) that put ``point`` (world) on the optical axis (ignoring the camera offset,
    exact when it is zero): for initial postures."""
    d = np.asarray(point, float) - np.asarray(head.position, float)
    pan = math.atan2(d[1], d[0]) - head.yaw
    tilt = math.atan2(-d[2], math.hypot(d[0], d[1]))
    return (math.atan2(math.sin(pan), math.cos(pan)), tilt)
