"""Oracles of the grasping arm task (test_grasping_loops.py), test-only: the arm's kinematics from
the chain's matrix products, the head camera's rays and image Jacobian, Self Windowing on NumPy images (the packed-row path's oracle), and eq. 2 of Namiki et al. 1999 written out in NumPy, against which
the task's float paths and command are held."""

from __future__ import annotations

import math

import numpy as np

from replay.control.grasping.arm_control import S_DIAG
from replay.control.grasping.recognition import Camera
from replay.robot.head import camera_pose
from replay.spatial import cross3, wrap_half_pi


# -- the head camera in NumPy (recognition.RecognitionTask._plane_geometry's oracle) ---------
class NumpyCamera(Camera):
    """:class:`Camera` with its rays, projections and image Jacobian as matrix products."""

    def ray(self, angles, pixel, pose=None) -> tuple[np.ndarray, np.ndarray]:
        """(origin, direction) of the ray through ``pixel``; ``pose``: the camera pose at
        ``angles`` if already known (``camera_pose(head, *angles)``)."""
        R, o = pose if pose is not None else camera_pose(self.head, *angles)
        d = R @ np.array([(pixel[0] - self.c[0]) / self.f, (pixel[1] - self.c[1]) / self.f, 1.0])
        return o, d

    def project(self, angles, point) -> np.ndarray:
        R, o = camera_pose(self.head, *angles)
        pc = R.T @ (np.asarray(point, float) - o)
        return self.c + self.f * pc[:2] / pc[2]

    def jacobian(self, angles, point, pose=None) -> np.ndarray:
        """d pixel / d (pan, tilt) at ``angles`` for a fixed world point. The camera turns about
        the head's centre h: about world z (pan) and the panned y axis (tilt, positive down), so
        the point in the camera frame moves by -R^T (k x (X - h)) per radian about axis k."""
        R, o = pose if pose is not None else camera_pose(self.head, *angles)
        X = np.asarray(point, float)
        pc = R.T @ (X - o)
        r = X - np.asarray(self.head.position, float)
        a = self.head.yaw + angles[0]
        J = np.zeros((2, 2))
        for i, k in enumerate(((0.0, 0.0, 1.0), (-math.sin(a), math.cos(a), 0.0))):
            kxr = np.array(
                [k[1] * r[2] - k[2] * r[1], k[2] * r[0] - k[0] * r[2], k[0] * r[1] - k[1] * r[0]]
            )
            d = -(R.T @ kxr)
            J[:, i] = self.f * (d[:2] * pc[2] - pc[:2] * d[2]) / (pc[2] * pc[2])
        return J


def meet_plane(o, d, point, normal) -> np.ndarray | None:
    denom = float(d @ normal)
    if abs(denom) < 1e-12:
        return None
    s = float((np.asarray(point) - o) @ normal) / denom
    return o + s * d if s > 0.0 else None


# -- Self Windowing on binary images (replay/control/grasping/self_window.py's equations) --
def dilate4(img: np.ndarray) -> np.ndarray:
    """Binary dilation by one pixel with the 4-neighbourhood (the chip's PE grid)."""
    out = img.copy()
    out[1:, :] |= img[:-1, :]
    out[:-1, :] |= img[1:, :]
    out[:, 1:] |= img[:, :-1]
    out[:, :-1] |= img[:, 1:]
    return out


def self_window(previous: np.ndarray, image: np.ndarray) -> np.ndarray:
    """The new target image: ``dilate4(previous) & image``."""
    return dilate4(previous) & image


def track(previous: np.ndarray | None, image: np.ndarray) -> tuple[np.ndarray, bool]:
    """(target, reacquired): Self Windowing, or the whole image when there is no previous target
    (``reacquired`` is then True)."""
    if previous is None or not previous.any():
        return image.copy(), True
    return self_window(previous, image), False


# -- the arm task ----------------------------------------------------------------------------
def kinematics(task, q) -> tuple[np.ndarray, np.ndarray]:
    """(tool transform, 6 x n geometric Jacobian at the tool origin) of ``task``'s arm at ``q``,
    from the chain's own matrix products (SerialChain.fk and .jacobian), against which the task's
    per-step float chain (``ArmControlTask._chain``) is held."""
    q = np.asarray(q, float)[: task.chain.n]
    return task.chain.fk(q), task.chain.jacobian(q)


def eq2_reference(task, q, qd, obj, state, F) -> dict[str, np.ndarray]:
    """Eq. 2's terms of ``task`` (an ArmControlTask) the NumPy way: ``F`` the external wrench
    as the task's ``external_wrench`` gives it."""
    P = task.params
    T, J = kinematics(task, q)
    R = T[:3, :3]
    gp = T[:3, 3] + P.grasp_point * R[:, 2]
    r = gp - T[:3, 3]
    Jg = J.copy()
    Jg[:3] -= cross3(r[:, None], J[3:])
    e_track = np.zeros(6)
    if obj is not None:
        e_track[:3] = np.asarray(obj.position, float) - gp
        if obj.roll is not None and obj.shape != "circle":
            e_track[3] = wrap_half_pi(obj.roll - math.atan2(float(R[2, 1]), float(R[1, 1])))
    e_reach = np.zeros(6)
    e_reach[:3] = np.asarray(state.x_d, float)[:3] - gp
    e_reach[3:] = cross3(R[:, 2], task._n_plane)
    JJt = Jg @ Jg.T + P.damping**2 * np.eye(6)
    Jpinv = Jg.T @ np.linalg.solve(JJt, np.eye(6))
    share = P.reach_tracking if state.phase == "reach" else 1.0
    out = {
        "track": P.K_ap * Jpinv @ (share * S_DIAG * task.K_a1 * e_track),
        "reach": P.K_ap * Jpinv @ ((1.0 - S_DIAG) * task.K_a2 * e_reach),
        "damp": -P.K_av * np.asarray(qd, float),
        "force": task.K_af * (J.T @ np.asarray(F, float)),
    }
    out["command"] = np.clip(sum(out.values()), -task.vlim, task.vlim)
    out["x_a"] = gp
    return out
