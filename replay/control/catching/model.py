"""What the catching method needs of a robot model, in the active coordinates p = (q1, q2, q4).

Wraps either ``replay.robot.SerialChain`` (``ArmModel.from_chain``) or four plain callables on the
full joint vector (``ArmModel(fk, mass_matrix, bias, gravity)``): fk(q) -> the catch point
l(q) (3,), mass_matrix(q) -> M (n, n), bias(q, qd) -> H(q, qd) qd + g(q) (n,), gravity(q) -> g (n,)
(eq. 15). Locked joints are held at ``q_fixed`` with zero speed and acceleration.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np


class ArmModel:
    def __init__(
        self,
        fk: Callable,
        mass_matrix: Callable,
        bias: Callable,
        gravity: Callable,
        *,
        n: int = 4,
        active: Sequence[int] = (0, 1, 3),
        q_fixed=None,
        inverse_dynamics: Callable | None = None,
        axis: Callable | None = None,
        fk_tuple: Callable | None = None,
        inverse_dynamics_tuple: Callable | None = None,
    ) -> None:
        self._fk, self._M, self._bias, self._g = fk, mass_matrix, bias, gravity
        self._id = inverse_dynamics
        # the per-step forms on floats (a chain's compiled point and RNEA), if there are any
        self._fk_t, self._id_t = fk_tuple, inverse_dynamics_tuple
        self._axis = axis  # q -> the tool z axis (the palm normal), world (3,)
        self.n = n
        self.active = np.asarray(active, dtype=int)
        self.q_fixed = np.zeros(n) if q_fixed is None else np.asarray(q_fixed, float).copy()

    @classmethod
    def from_chain(cls, chain, *, active=(0, 1, 3), q_fixed=None, point_in_tool=(0.0, 0.0, 0.0)):
        """A ``replay.robot.SerialChain``; l(q) is the point ``point_in_tool`` of its tool frame."""
        pt = np.array([*point_in_tool, 1.0])
        pt_last = tuple((chain.tool @ pt)[:3].tolist())  # the point in the last DH frame

        def fk(q):
            return chain.point(q, pt_last)

        def fk_tuple(q):
            return chain.point_tuple(q, pt_last)

        def axis(q):
            return (chain.frames(q)[-1] @ chain.tool)[:3, 2]

        return cls(
            fk,
            chain.mass_matrix,
            lambda q, qd: chain.rnea(q, qd, np.zeros(chain.n)),
            chain.gravity_torque,
            n=chain.n,
            active=active,
            q_fixed=q_fixed,
            inverse_dynamics=chain.rnea,
            axis=axis,
            fk_tuple=fk_tuple,
            inverse_dynamics_tuple=chain.rnea_tuple,
        )

    # ---- coordinates
    def full(self, p) -> np.ndarray:
        q = self.q_fixed.copy()
        q[self.active] = p
        return q

    def full_rate(self, pd) -> np.ndarray:
        q = np.zeros(self.n)
        q[self.active] = pd
        return q

    # ---- kinematics (full q)
    def fk(self, q) -> np.ndarray:
        return np.asarray(self._fk(np.asarray(q, float)), float)

    def fk_tuple(self, q) -> tuple[float, float, float]:
        """:meth:`fk` as a 3-tuple of floats, q n floats (a list or tuple): the per-step path."""
        if self._fk_t is not None:
            return self._fk_t(q)
        x, y, z = self.fk(q).tolist()
        return x, y, z

    def point(self, p) -> np.ndarray:
        """l(q) (eq. 3) at active coordinates p."""
        return self.fk(self.full(p))

    def tool_axis(self, p) -> np.ndarray:
        """The tool frame's z axis (the palm normal) at active coordinates p."""
        if self._axis is None:
            raise ValueError("this ArmModel was built without the tool axis")
        return np.asarray(self._axis(self.full(p)), float)

    def point_acceleration(self, p, pd, pdd, h: float = 1e-4) -> tuple[np.ndarray, np.ndarray]:
        """d^2 l/dt^2 = J pdd + pd^T H pd (central differences) and J = dl/dp (3, 3)."""
        p, pd = np.asarray(p, float), np.asarray(pd, float)
        J = np.empty((3, len(p)))
        for k in range(len(p)):
            e = np.zeros(len(p))
            e[k] = h
            J[:, k] = (self.point(p + e) - self.point(p - e)) / (2 * h)
        w = float(np.linalg.norm(pd))
        quad = np.zeros(3)
        if w > 0:
            u = pd / w * h
            quad = (self.point(p + u) + self.point(p - u) - 2 * self.point(p)) / (h * h) * w * w
        return J @ np.asarray(pdd, float) + quad, J

    # ---- dynamics: eq. 15, full joint vector in and out
    def inverse_dynamics_full(self, q, qd, qdd) -> np.ndarray:
        if self._id is not None:
            return np.asarray(self._id(q, qd, qdd), float)
        return self._M(q) @ qdd + self._bias(q, qd)

    def inverse_dynamics_tuple(self, q, qd, qdd) -> tuple:
        """:meth:`inverse_dynamics_full` as a tuple of n floats (lists or tuples in): the
        per-step path."""
        if self._id_t is not None:
            return self._id_t(q, qd, qdd)
        return tuple(self.inverse_dynamics_full(np.array(q), np.array(qd), np.array(qdd)).tolist())

    def tau(self, p, pd, pdd) -> np.ndarray:
        """Active joint torques of eq. 15 / 17 (the locked joint's holding torque dropped)."""
        return self.inverse_dynamics_full(self.full(p), self.full_rate(pd), self.full_rate(pdd))[
            self.active
        ]

    def mass(self, p) -> np.ndarray:
        M = np.asarray(self._M(self.full(p)), float)
        return M[np.ix_(self.active, self.active)]

    def gravity_full(self, q) -> np.ndarray:
        return np.asarray(self._g(np.asarray(q, float)), float)

    def tau_and_partials(self, p, pd, pdd, h: float = 1e-6):
        """tau, d tau/dp, d tau/dpd (forward differences) and M (active blocks)."""
        tau = self.tau(p, pd, pdd)
        Tq = np.empty((len(p), len(p)))
        Tqd = np.empty_like(Tq)
        for k in range(len(p)):
            e = np.zeros(len(p))
            e[k] = h
            Tq[:, k] = (self.tau(p + e, pd, pdd) - tau) / h
            Tqd[:, k] = (self.tau(p, pd + e, pdd) - tau) / h
        return tau, Tq, Tqd, self.mass(p)


ARM_JOINTS = tuple(f"J{i}" for i in range(1, 8))  # an arm's joints as ArmSpec names them


def active_joints(names: tuple[str, ...], held, selected: str, who: str) -> tuple[int, ...]:
    """Indices of the three moving joints (Sec. IV-A: axes 1, 2, 4), the last being ``selected``."""
    unknown = [j for j in [*held, selected] if j not in names]
    if unknown:
        raise ValueError(
            f"{who}: the arm has no joint {', '.join(map(str, unknown))} (its joints: "
            f"{', '.join(names)})"
        )
    held_i = [names.index(j) for j in held]
    active = tuple(i for i in range(len(names)) if i not in held_i)
    if len(active) != 3 or names.index(selected) != active[-1]:
        raise ValueError(
            f"{who} needs 3 active joints ending with {selected}; got {[names[i] for i in active]}"
        )
    return active


def catch_point_offset(spec, catch_offset: float) -> float:
    """The catch point along the tool z axis: ``catch_offset``, or (< 0) the palm's thickness
    plus the ball's radius, so that the ball centre rests on the palm."""
    if catch_offset >= 0:
        return catch_offset
    off = 0.0
    if getattr(spec, "hand", None) is not None:
        off += float(spec.hand.table.palm_thickness)
    if getattr(spec, "object", None) is not None:
        off += float(spec.object.radius)
    return off
