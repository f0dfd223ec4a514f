"""Oracles of the arm model (replay/robot/serial_chain.py), test-only: the chain's motion of a
tool point, H(q, qd) qd, forward dynamics and world link bodies, which the tests use to check
the model's physics identities, and the RNEA vectorised over many states in 4 x 4 matrices, the
form the per-column float path (SerialChain.rnea) is held to."""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from replay.robot.serial_chain import RigidBody, SerialChain


def tool_position(chain: SerialChain, q) -> np.ndarray:
    """World position of the tool frame's origin."""
    return chain.fk(q)[:3, 3]


def tool_motion(chain, q, qd, qdd=None, point_in_tool=(0.0, 0.0, 0.0)):
    """World position, velocity (J qd) and acceleration (J qdd + Jdot qd) of a tool point."""
    q, qd = chain._q(q), chain._q(qd)
    qdd = np.zeros(chain.n) if qdd is None else chain._q(qdd)
    Ts = chain.frames(q)
    w = np.zeros(3)
    dw = np.zeros(3)
    v = np.zeros(3)  # of the origin o_{i-1}
    a = np.zeros(3)
    for i in range(chain.n):
        z, o0, o1 = Ts[i][:3, 2], Ts[i][:3, 3], Ts[i + 1][:3, 3]
        dw = dw + z * qdd[i] + np.cross(w, z * qd[i])
        w = w + z * qd[i]
        r = o1 - o0
        v = v + np.cross(w, r)
        a = a + np.cross(dw, r) + np.cross(w, np.cross(w, r))
    p = (Ts[-1] @ chain.tool @ np.array([*point_in_tool, 1.0]))[:3]
    r = p - Ts[-1][:3, 3]
    return p, v + np.cross(w, r), a + np.cross(dw, r) + np.cross(w, np.cross(w, r))


def coriolis(chain, q, qd) -> np.ndarray:
    """H(q, qd) qd: Coriolis and centrifugal torques."""
    return chain.rnea(q, qd, np.zeros(chain.n), gravity=np.zeros(3))


def forward_dynamics(chain, q, qd, tau) -> np.ndarray:
    """qdd = M^-1 (tau - H qd - g)."""
    return np.linalg.solve(
        chain.mass_matrix(q), np.asarray(tau, float) - chain.rnea(q, qd, np.zeros(chain.n))
    )


def frames_batch(chain, Q) -> np.ndarray:
    """World transforms of frames 0..n for many configurations: Q (N, n) -> (N, n+1, 4, 4)."""
    Q = np.asarray(Q, dtype=float).reshape(-1, chain.n)
    N = Q.shape[0]
    out = np.empty((N, chain.n + 1, 4, 4))
    out[:, 0] = chain.base
    for i, row in enumerate(chain.dh):
        th = Q[:, i] + row.theta_offset
        ct, st = np.cos(th), np.sin(th)
        ca, sa = math.cos(row.alpha), math.sin(row.alpha)
        A = np.zeros((N, 4, 4))
        A[:, 0, 0], A[:, 0, 1], A[:, 0, 2], A[:, 0, 3] = ct, -st * ca, st * sa, row.a * ct
        A[:, 1, 0], A[:, 1, 1], A[:, 1, 2], A[:, 1, 3] = st, ct * ca, -ct * sa, row.a * st
        A[:, 2, 1], A[:, 2, 2], A[:, 2, 3] = sa, ca, row.d
        A[:, 3, 3] = 1.0
        out[:, i + 1] = out[:, i] @ A
    return out


def rnea_batch(
    chain, Q, QD, QDD, gravity: Sequence[float] | np.ndarray | None = None
) -> np.ndarray:
    """tau = M qdd + H qd + g for many states: each (N, n) -> (N, n). Same recursion as
    :meth:`rnea`, vectorised over the leading axis."""
    Q = np.asarray(Q, dtype=float).reshape(-1, chain.n)
    QD = np.asarray(QD, dtype=float).reshape(Q.shape)
    QDD = np.asarray(QDD, dtype=float).reshape(Q.shape)
    g = chain.gravity if gravity is None else np.asarray(gravity, dtype=float)
    Ts = frames_batch(chain, Q)
    N, n = Q.shape
    w = np.zeros((N, 3))
    dw = np.zeros((N, 3))
    a_o = np.broadcast_to(-g, (N, 3)).copy()
    keep = []
    for i in range(n):
        z, o0, o1 = Ts[:, i, :3, 2], Ts[:, i, :3, 3], Ts[:, i + 1, :3, 3]
        R1 = Ts[:, i + 1, :3, :3]
        zq = z * QD[:, i : i + 1]
        dw = dw + z * QDD[:, i : i + 1] + np.cross(w, zq)
        w = w + zq
        c = R1 @ chain.links[i].com + o1
        rc = c - o0
        a_c = a_o + np.cross(dw, rc) + np.cross(w, np.cross(w, rc))
        Iw = R1 @ chain.links[i].inertia @ np.swapaxes(R1, 1, 2)
        keep.append((z, o0, o1, c, a_c, w, dw, Iw))
        r = o1 - o0
        a_o = a_o + np.cross(dw, r) + np.cross(w, np.cross(w, r))
    tau = np.zeros((N, n))
    f_next = np.zeros((N, 3))
    n_next = np.zeros((N, 3))
    for i in reversed(range(n)):
        z, o0, o1, c, a_c, w_i, dw_i, Iw = keep[i]
        ma = chain.links[i].mass * a_c
        f = ma + f_next
        nm = (
            np.einsum("nab,nb->na", Iw, dw_i)
            + np.cross(w_i, np.einsum("nab,nb->na", Iw, w_i))
            + np.cross(c - o0, ma)
            + n_next
            + np.cross(o1 - o0, f_next)
        )
        tau[:, i] = np.einsum("na,na->n", z, nm)
        f_next, n_next = f, nm
    return tau


def link_bodies_world(chain, q) -> list[RigidBody]:
    """Each link's mass properties in world coordinates (for checks and drawing)."""
    Ts = chain.frames(q)
    return [b.transformed(Ts[i + 1]) for i, b in enumerate(chain.links)]
