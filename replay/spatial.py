"""Rotations and poses, one home for every convention used in the project. Pure NumPy.

- Quaternions are [qx, qy, qz, qw] (scalar last: the log contract, PyBullet, ``replay.scene``);
  Viser wants [w, x, y, z]: the ``*_wxyz`` helpers give that order.
- Roll-pitch-yaw is URDF's (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll).
- ``transform`` builds a 4x4 homogeneous transform.
"""

from __future__ import annotations

import math

import numpy as np


# ------------------------------------------------------------------ rotation matrices
def rot_x(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a: float) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def transform(rotation: np.ndarray | None = None, translation=(0.0, 0.0, 0.0)) -> np.ndarray:
    """A 4x4 homogeneous transform."""
    T = np.eye(4)
    if rotation is not None:
        T[:3, :3] = rotation
    T[:3, 3] = translation
    return T


# ------------------------------------------------------------------ roll-pitch-yaw
def rpy_to_matrix(rpy) -> np.ndarray:
    """URDF roll-pitch-yaw (fixed axes x, y, z): R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    return rot_z(y) @ rot_y(p) @ rot_x(r)


def matrix_to_rpy(R: np.ndarray) -> tuple[float, float, float]:
    """Inverse of :func:`rpy_to_matrix` (pitch in [-pi/2, pi/2])."""
    R = np.asarray(R, dtype=float)
    sp = -R[2, 0]
    if abs(sp) < 1.0 - 1e-12:
        pitch = float(np.arcsin(np.clip(sp, -1.0, 1.0)))
        roll = float(np.arctan2(R[2, 1], R[2, 2]))
        yaw = float(np.arctan2(R[1, 0], R[0, 0]))
    else:  # gimbal lock: put everything in yaw
        pitch = float(np.copysign(np.pi / 2, sp))
        roll = 0.0
        yaw = float(np.arctan2(-R[0, 1], R[1, 1]))
    return roll, pitch, yaw


# ------------------------------------------------------------------ quaternions [qx, qy, qz, qw]
def matrix_to_quaternion(R: np.ndarray) -> np.ndarray:
    """3x3 rotation matrix -> [qx, qy, qz, qw] with qw >= 0 (inverse of
    :func:`quaternion_matrix`)."""
    m = np.asarray(R, dtype=float)
    tr = m[0, 0] + m[1, 1] + m[2, 2]
    if tr > 0:
        s = 2.0 * np.sqrt(tr + 1.0)
        q = [(m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, 0.25 * s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = [0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s]
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = [(m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s]
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = [(m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s]
    qa = np.array(q)
    qa /= np.linalg.norm(qa)
    return -qa if qa[3] < 0 else qa


def quaternion_matrix(q) -> np.ndarray:
    """Rotation matrix of a quaternion [qx, qy, qz, qw] (normalised here)."""
    x, y, z, w = (float(v) for v in q)
    n = x * x + y * y + z * z + w * w
    if n == 0.0:
        raise ValueError("zero quaternion")
    s = 2.0 / n
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def yaw_quaternion(yaw: float) -> tuple[float, float, float, float]:
    """Rotation about +z by ``yaw`` rad as [qx, qy, qz, qw]."""
    return (0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


# ------------------------------------------------------------------ Viser's order [w, x, y, z]
def xyzw_to_wxyz(q) -> tuple[float, float, float, float]:
    """[qx, qy, qz, qw] -> a unit [w, x, y, z]."""
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    return (w / n, x / n, y / n, z / n)


def matrix_to_wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    x, y, z, w = matrix_to_quaternion(R)
    return (float(w), float(x), float(y), float(z))


def rpy_to_wxyz(rpy) -> tuple[float, float, float, float]:
    """URDF roll-pitch-yaw (fixed axes x, y, z) as a [w, x, y, z] quaternion."""
    return matrix_to_wxyz(rpy_to_matrix(rpy))


def yaw_wxyz(theta: float) -> tuple[float, float, float, float]:
    """Rotation about +z by ``theta`` rad as [w, x, y, z]."""
    return (math.cos(theta / 2.0), 0.0, 0.0, math.sin(theta / 2.0))


# ------------------------------------------------------------------ angles
def wrap_half_pi(angle: float) -> float:
    """An axis angle (known modulo pi, as a symmetric marker shows it) in (-pi/2, pi/2]."""
    a = math.fmod(angle, math.pi)
    if a <= -math.pi / 2.0:
        a += math.pi
    elif a > math.pi / 2.0:
        a -= math.pi
    return a


def cross3(a, b) -> np.ndarray:
    """a x b for 3-vectors, or column by column for (3, n) arrays: np.cross's speed for small
    arrays is dominated by its axis handling (~10 us a call)."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )
