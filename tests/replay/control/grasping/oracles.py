"""Oracles of the grasping arm task (test_grasping_loops.py), test-only: the arm's kinematics from
the chain's matrix products, and eq. 2 of Namiki et al. 1999 written out in NumPy, against which
the task's float paths and command are held."""

from __future__ import annotations

import math

import numpy as np

from replay.control.grasping.arm_control import S_DIAG
from replay.spatial import cross3, wrap_half_pi


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
