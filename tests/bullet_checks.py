"""PyBullet's own dynamics of the arm rig's arm (PyBullet engine), to cross-check the NumPy model in tests
(moved out of the plant: only tests need it)."""

from __future__ import annotations

import numpy as np


def _full_dofs(plant, q_arm, qd_arm=None, qdd_arm=None):
    hq, _, _ = plant.hand_state()
    pos, vel, acc = [], [], []
    arm_of = {plant.engine.jidx[plant.joint_names[i]]: i for i in plant.active}
    hand_of = {j: k for k, j in enumerate(plant.engine.hand_j)}
    for j in plant.engine.dofs:
        if j in arm_of:
            i = arm_of[j]
            pos.append(float(q_arm[i]))
            vel.append(0.0 if qd_arm is None else float(qd_arm[i]))
            acc.append(0.0 if qdd_arm is None else float(qdd_arm[i]))
        else:
            pos.append(float(hq[hand_of[j]]))
            vel.append(0.0)
            acc.append(0.0)
    return (
        pos,
        vel,
        acc,
        [plant.engine.dofs.index(plant.engine.jidx[plant.joint_names[i]]) for i in plant.active],
    )


def inverse_dynamics(plant, q, qd, qdd) -> np.ndarray:
    """PyBullet's inverse dynamics for the arm (hand joints frozen at their current angles);
    locked joints' entries are NaN."""
    pos, vel, acc, cols = _full_dofs(plant, q, qd, qdd)
    tau = np.array(plant.engine.bc.calculateInverseDynamics(plant.engine.robot, pos, vel, acc))
    out = np.full(plant.dof, np.nan)
    out[list(plant.active)] = tau[cols]
    return out


def mass_matrix(plant, q) -> np.ndarray:
    """PyBullet's mass matrix of the active arm joints (hand frozen), len(active) square."""
    pos, _, _, cols = _full_dofs(plant, q)
    M = np.array(plant.engine.bc.calculateMassMatrix(plant.engine.robot, pos))
    return M[np.ix_(cols, cols)]
