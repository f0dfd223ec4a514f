"""A serial chain of revolute joints in standard (Spong) Denavit–Hartenberg form: NumPy for many
configurations, Python floats for one (its point and RNEA: cheaper than NumPy on 3-vectors).

Conventions (Spong, Hutchinson & Vidyasagar, *Robot Modeling and Control*, Sec. 3.2):

- Row i of the DH table is (alpha_i, a_i, d_i, theta_offset_i); joint i rotates about z_{i-1}, and
  ``T^{i-1}_i = Rz(q_i + theta_offset_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``.
- Frame 0 sits at ``base`` (a 4x4 world transform); frame i is fixed in link i.
- Link i's mass properties are given in frame i: ``com`` is the centre of mass, ``inertia`` the
  tensor about the centre of mass with axes aligned with frame i (libbarrett's convention).
- The tool frame is ``tool`` (a constant 4x4) after the last DH frame; it has no mass.
- Dynamics ``M(q) qdd + H(q, qd) qd + g(q) = tau`` (Namiki & Ishikawa eq. 15) computed by the
  recursive Newton–Euler algorithm in world coordinates (Spong Sec. 7.5 / Craig Sec. 6.5):
  ``g(q)`` is the torque that holds the arm still against gravity.
"""

from __future__ import annotations

import math
import operator
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np


def dh_transform(alpha: float, a: float, d: float, theta: float) -> np.ndarray:
    """Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    ct, st = np.cos(theta), np.sin(theta)
    ca, sa = np.cos(alpha), np.sin(alpha)
    return np.array(
        [
            [ct, -st * ca, st * sa, a * ct],
            [st, ct * ca, -ct * sa, a * st],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


@dataclass(frozen=True, eq=False)
class RigidBody:
    """Mass properties: ``com`` (m) in the body frame, ``inertia`` (kg*m^2) about the centre of
    mass with axes aligned with the body frame."""

    mass: float
    com: np.ndarray = field(default_factory=lambda: np.zeros(3))
    inertia: np.ndarray = field(default_factory=lambda: np.zeros((3, 3)))

    def __post_init__(self):
        object.__setattr__(self, "com", np.asarray(self.com, dtype=float).reshape(3))
        object.__setattr__(self, "inertia", np.asarray(self.inertia, dtype=float).reshape(3, 3))

    def transformed(self, T: np.ndarray) -> RigidBody:
        """The same body described in a frame F where ``T`` is this body frame's pose in F."""
        R = T[:3, :3]
        return RigidBody(self.mass, R @ self.com + T[:3, 3], R @ self.inertia @ R.T)

    def combined(self, other: RigidBody) -> RigidBody:
        """Two bodies in the same frame as one (parallel-axis theorem, Steiner)."""
        m = self.mass + other.mass
        if m <= 0.0:
            return RigidBody(0.0)
        c = (self.mass * self.com + other.mass * other.com) / m
        inertia = np.zeros((3, 3))
        for b in (self, other):
            r = b.com - c
            inertia += b.inertia + b.mass * (float(r @ r) * np.eye(3) - np.outer(r, r))
        return RigidBody(m, c, inertia)


@dataclass(frozen=True)
class DHRow:
    alpha: float
    a: float
    d: float
    theta_offset: float = 0.0


class SerialChain:
    """Kinematics and rigid-body dynamics of a revolute serial chain (see the module docstring).

    All joint-space arrays have length ``n`` (every joint of the chain). A locked joint is simply
    held at a value by the caller; the matching rows/columns can be dropped with ``active``.
    """

    def __init__(
        self,
        dh: Sequence[DHRow],
        links: Sequence[RigidBody],
        *,
        base: np.ndarray | None = None,
        tool: np.ndarray | None = None,
        gravity: Sequence[float] | np.ndarray = (0.0, 0.0, -9.81),
        joint_names: Sequence[str] | None = None,
    ) -> None:
        if len(dh) != len(links):
            raise ValueError(f"{len(dh)} DH rows but {len(links)} links")
        self.dh = tuple(dh)
        self.links = tuple(links)
        self.n = len(self.dh)
        self.base = np.eye(4) if base is None else np.asarray(base, dtype=float)
        self.tool = np.eye(4) if tool is None else np.asarray(tool, dtype=float)
        self.gravity = np.asarray(gravity, dtype=float)
        self.joint_names = (
            tuple(joint_names) if joint_names else tuple(f"J{i + 1}" for i in range(self.n))
        )
        self._masses = np.array([b.mass for b in self.links])
        self._coms = np.array([b.com for b in self.links])
        self._inertias = np.array([b.inertia for b in self.links])
        # the single-configuration path in Python floats (see _frames_f): per joint
        # (cos alpha, sin alpha, a, d, theta offset, mass, com, inertia rows)
        self._rows_f = tuple(
            (
                math.cos(r.alpha),
                math.sin(r.alpha),
                float(r.a),
                float(r.d),
                float(r.theta_offset),
                float(b.mass),
                tuple(b.com.tolist()),
                tuple(tuple(row) for row in b.inertia.tolist()),
            )
            for r, b in zip(self.dh, self.links)
        )
        B = self.base
        self._base_f = (
            tuple(B[:3, 0].tolist()),
            tuple(B[:3, 1].tolist()),
            tuple(B[:3, 2].tolist()),
            tuple(B[:3, 3].tolist()),
        )
        self._g_f = tuple(float(x) for x in self.gravity)
        self._frames_last: tuple = ((None,), [])  # _frames_f's last (q, frames); none yet

    # ------------------------------------------------------------------ variants
    def with_payload(self, body: RigidBody) -> SerialChain:
        """The chain with ``body`` (given in the tool frame) rigidly added to the last link."""
        last = self.links[-1].combined(body.transformed(self.tool))
        return SerialChain(
            self.dh,
            self.links[:-1] + (last,),
            base=self.base,
            tool=self.tool,
            gravity=self.gravity,
            joint_names=self.joint_names,
        )

    # ------------------------------------------------------------------ kinematics
    def _floats(self, q) -> list[float]:
        """n joint values (a list, tuple or array) as a list of Python floats."""
        out = q.tolist() if isinstance(q, np.ndarray) else [float(x) for x in q]
        if len(out) != self.n or (out and isinstance(out[0], list)):
            out = self._q(q).tolist()  # (the shape check and its message)
        return out

    def _q(self, q) -> np.ndarray:
        q = np.asarray(q, dtype=float).reshape(-1)
        if q.shape[0] != self.n:
            raise ValueError(f"expected {self.n} joint values, got {q.shape[0]}")
        return q

    def frames(self, q) -> list[np.ndarray]:
        """World transforms of frames 0..n (n+1 matrices; frame 0 is the base)."""
        q = self._q(q)
        T = [self.base]
        for row, qi in zip(self.dh, q):
            T.append(T[-1] @ dh_transform(row.alpha, row.a, row.d, qi + row.theta_offset))
        return T

    def _frames_f(self, q) -> list[tuple]:
        """Frames 0..n as (X, Y, Z, o): the world axes and origin of each, 3-tuples of floats.

        The same products as :meth:`frames` (T_i = T_{i-1} Rz(q_i + offset) Tz(d) Tx(a) Rx(alpha),
        Spong Sec. 3.2) written per column, for one configuration (:meth:`point`,
        :meth:`rnea`). The last result is kept (shared: never mutated) and given again for the
        same float objects (the controller's RNEA and l(q_d) of one posture, a step apart):
        identity, not ==, so -0.0 is never taken for 0.0."""
        key = tuple(q)
        last_q, last = self._frames_last
        if len(key) == len(last_q) and all(map(operator.is_, key, last_q)):
            return last
        (xx, xy, xz), (yx, yy, yz), (zx, zy, zz), (px, py, pz) = self._base_f
        out = [self._base_f]
        cos, sin = math.cos, math.sin
        for qi, (ca, sa, a, d, off, _, _, _) in zip(key, self._rows_f):
            th = qi + off
            ct, st = cos(th), sin(th)
            x1x, x1y, x1z = ct * xx + st * yx, ct * xy + st * yy, ct * xz + st * yz
            y1x, y1y, y1z = ct * yx - st * xx, ct * yy - st * xy, ct * yz - st * xz
            px, py, pz = px + d * zx + a * x1x, py + d * zy + a * x1y, pz + d * zz + a * x1z
            yx, yy, yz, zx, zy, zz = (
                ca * y1x + sa * zx,
                ca * y1y + sa * zy,
                ca * y1z + sa * zz,
                ca * zx - sa * y1x,
                ca * zy - sa * y1y,
                ca * zz - sa * y1z,
            )
            xx, xy, xz = x1x, x1y, x1z
            out.append(((xx, xy, xz), (yx, yy, yz), (zx, zy, zz), (px, py, pz)))
        self._frames_last = (key, out)
        return out

    def point(self, q, point_in_last=(0.0, 0.0, 0.0)) -> np.ndarray:
        """World position of a point given in the last DH frame (for a tool point: ``tool`` @
        the point), one configuration."""
        return np.array(self.point_tuple(q, point_in_last))

    def point_tuple(self, q, point_in_last=(0.0, 0.0, 0.0)) -> tuple[float, float, float]:
        """:meth:`point` as a 3-tuple of floats (q: n floats, a list, tuple or array), on the
        frames of :meth:`_frames_f`."""
        (xx, xy, xz), (yx, yy, yz), (zx, zy, zz), (px, py, pz) = self._frames_f(self._floats(q))[-1]
        u, v, w = point_in_last
        return (
            px + u * xx + v * yx + w * zx,
            py + u * xy + v * yy + w * zy,
            pz + u * xz + v * yz + w * zz,
        )

    def fk(self, q) -> np.ndarray:
        """World transform of the tool frame."""
        return self.frames(q)[-1] @ self.tool

    def jacobian(self, q, point_in_tool=(0.0, 0.0, 0.0)) -> np.ndarray:
        """Geometric Jacobian (6 x n: linear velocity of the point, then angular velocity)."""
        Ts = self.frames(q)
        p = (Ts[-1] @ self.tool @ np.array([*point_in_tool, 1.0]))[:3]
        J = np.zeros((6, self.n))
        for i in range(self.n):
            z, o = Ts[i][:3, 2], Ts[i][:3, 3]
            J[:3, i] = np.cross(z, p - o)
            J[3:, i] = z
        return J

    def position_jacobian(self, q, point_in_tool=(0.0, 0.0, 0.0)) -> np.ndarray:
        """d(point)/dq, 3 x n."""
        return self.jacobian(q, point_in_tool)[:3]

    # ------------------------------------------------------------------ dynamics
    def rnea(self, q, qd, qdd, gravity: Sequence[float] | np.ndarray | None = None) -> np.ndarray:
        """Inverse dynamics tau = M qdd + H qd + g (n,): :meth:`rnea_tuple` as an array."""
        return np.array(self.rnea_tuple(q, qd, qdd, gravity))

    def rnea_tuple(self, q, qd, qdd, gravity: Sequence[float] | np.ndarray | None = None) -> tuple:
        """Inverse dynamics tau = M qdd + H qd + g as a tuple of n floats (q, qd, qdd: n floats
        each, lists or arrays): recursive Newton–Euler in world coordinates.

        Forward pass: angular velocity/acceleration of link i and linear acceleration of o_{i-1}
        (on joint i's axis, fixed in links i-1 and i); gravity enters as a base acceleration -g.
        Backward pass: force and moment (about o_{i-1}) that link i-1 exerts on link i.
        One configuration in Python floats on the frames of :meth:`_frames_f` (inertia applied
        as R I R^T v without forming R I R^T); the same recursion in NumPy matrices over many
        states is the tests' oracle (tests/replay/robot/oracles.py). One function, 86 lines: the
        two passes read as the recursive Newton–Euler algorithm only together.
        """
        qf, qdf, qddf = self._floats(q), self._floats(qd), self._floats(qdd)
        gx, gy, gz = self._g_f if gravity is None else (float(x) for x in gravity)
        F = self._frames_f(qf)
        wx = wy = wz = dwx = dwy = dwz = 0.0
        ax, ay, az = -gx, -gy, -gz  # acceleration of o_{i-1}
        fwd = []
        for i, (qdi, qddi) in enumerate(zip(qdf, qddf)):
            (zx, zy, zz), (ox, oy, oz) = F[i][2], F[i][3]
            X, Y, Z, (o1x, o1y, o1z) = F[i + 1]
            row = self._rows_f[i]
            c0, c1, c2 = row[6]
            cx = o1x + c0 * X[0] + c1 * Y[0] + c2 * Z[0]
            cy = o1y + c0 * X[1] + c1 * Y[1] + c2 * Z[1]
            cz = o1z + c0 * X[2] + c1 * Y[2] + c2 * Z[2]
            zqx, zqy, zqz = zx * qdi, zy * qdi, zz * qdi
            dwx += zx * qddi + wy * zqz - wz * zqy
            dwy += zy * qddi + wz * zqx - wx * zqz
            dwz += zz * qddi + wx * zqy - wy * zqx
            wx, wy, wz = wx + zqx, wy + zqy, wz + zqz
            # a_c = a_o + dw x rc + w x (w x rc)
            rx, ry, rz = cx - ox, cy - oy, cz - oz
            ux, uy, uz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx
            acx = ax + dwy * rz - dwz * ry + wy * uz - wz * uy
            acy = ay + dwz * rx - dwx * rz + wz * ux - wx * uz
            acz = az + dwx * ry - dwy * rx + wx * uy - wy * ux
            rx, ry, rz = o1x - ox, o1y - oy, o1z - oz
            ux, uy, uz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx
            ax += dwy * rz - dwz * ry + wy * uz - wz * uy
            ay += dwz * rx - dwx * rz + wz * ux - wx * uz
            az += dwx * ry - dwy * rx + wx * uy - wy * ux
            fwd.append((cx, cy, cz, acx, acy, acz, wx, wy, wz, dwx, dwy, dwz))
        n = self.n
        tau = [0.0] * n
        fx = fy = fz = nx = ny = nz = 0.0  # force on link i+1, moment about o_i
        for i in range(n - 1, -1, -1):
            cx, cy, cz, acx, acy, acz, wx, wy, wz, dwx, dwy, dwz = fwd[i]
            (zx, zy, zz), (ox, oy, oz) = F[i][2], F[i][3]
            X, Y, Z, (o1x, o1y, o1z) = F[i + 1]
            row = self._rows_f[i]
            m, I = row[5], row[7]
            # I_w w and I_w dw with I_w = R I R^T (R = [X Y Z] of frame i+1)
            lw0 = X[0] * wx + X[1] * wy + X[2] * wz
            lw1 = Y[0] * wx + Y[1] * wy + Y[2] * wz
            lw2 = Z[0] * wx + Z[1] * wy + Z[2] * wz
            ld0 = X[0] * dwx + X[1] * dwy + X[2] * dwz
            ld1 = Y[0] * dwx + Y[1] * dwy + Y[2] * dwz
            ld2 = Z[0] * dwx + Z[1] * dwy + Z[2] * dwz
            (i00, i01, i02), (i10, i11, i12), (i20, i21, i22) = I
            u0 = i00 * lw0 + i01 * lw1 + i02 * lw2
            u1 = i10 * lw0 + i11 * lw1 + i12 * lw2
            u2 = i20 * lw0 + i21 * lw1 + i22 * lw2
            e0 = i00 * ld0 + i01 * ld1 + i02 * ld2
            e1 = i10 * ld0 + i11 * ld1 + i12 * ld2
            e2 = i20 * ld0 + i21 * ld1 + i22 * ld2
            Iwx, Iwy, Iwz = (
                u0 * X[0] + u1 * Y[0] + u2 * Z[0],
                u0 * X[1] + u1 * Y[1] + u2 * Z[1],
                u0 * X[2] + u1 * Y[2] + u2 * Z[2],
            )
            Idx, Idy, Idz = (
                e0 * X[0] + e1 * Y[0] + e2 * Z[0],
                e0 * X[1] + e1 * Y[1] + e2 * Z[1],
                e0 * X[2] + e1 * Y[2] + e2 * Z[2],
            )
            max_, may, maz = m * acx, m * acy, m * acz
            rcx, rcy, rcz = cx - ox, cy - oy, cz - oz
            rx, ry, rz = o1x - ox, o1y - oy, o1z - oz
            nx, ny, nz = (
                Idx + wy * Iwz - wz * Iwy + rcy * maz - rcz * may + nx + ry * fz - rz * fy,
                Idy + wz * Iwx - wx * Iwz + rcz * max_ - rcx * maz + ny + rz * fx - rx * fz,
                Idz + wx * Iwy - wy * Iwx + rcx * may - rcy * max_ + nz + rx * fy - ry * fx,
            )
            fx, fy, fz = max_ + fx, may + fy, maz + fz
            tau[i] = zx * nx + zy * ny + zz * nz
        return tuple(tau)

    def _link_jacobians(self, q):
        """Per link i: COM Jacobian Jv (n, n, 3), angular Jw (n, n, 3), world inertia (n, 3, 3)."""
        Ts = self.frames(q)
        n = self.n
        z = np.array([T[:3, 2] for T in Ts[:-1]])  # joint axes z_0..z_{n-1}
        o = np.array([T[:3, 3] for T in Ts[:-1]])
        R = np.array([T[:3, :3] for T in Ts[1:]])
        c = np.einsum("ijk,ik->ij", R, self._coms) + np.array([T[:3, 3] for T in Ts[1:]])
        mask = np.tril(np.ones((n, n)))[:, :, None]  # joint j moves link i>=j
        Jv = np.cross(np.broadcast_to(z, (n, n, 3)), c[:, None, :] - o[None, :, :]) * mask
        Jw = np.broadcast_to(z, (n, n, 3)) * mask
        Iw = np.einsum("iab,ibc,idc->iad", R, self._inertias, R)
        return Jv, Jw, Iw

    def mass_matrix(self, q) -> np.ndarray:
        """M(q) = sum_i m_i Jv_i^T Jv_i + Jw_i^T I_i Jw_i (Spong eq. 7.50); an algorithm
        independent of :meth:`rnea`, so the two check each other."""
        Jv, Jw, Iw = self._link_jacobians(self._q(q))
        M = np.einsum("i,ijk,ilk->jl", self._masses, Jv, Jv) + np.einsum(
            "ijk,ikm,ilm->jl", Jw, Iw, Jw
        )
        return 0.5 * (M + M.T)

    def gravity_torque(self, q) -> np.ndarray:
        """g(q) = dV/dq = -sum_i m_i Jv_i^T g: the joint torques that hold the chain still."""
        Jv, _, _ = self._link_jacobians(self._q(q))
        return -np.einsum("i,ijk,k->j", self._masses, Jv, self.gravity)


def active_block(x: np.ndarray, active: Sequence[int]) -> np.ndarray:
    """Rows (and columns, for a square matrix) of the active joints."""
    idx = np.asarray(active, dtype=int)
    x = np.asarray(x)
    if x.ndim == 2 and x.shape[0] == x.shape[1]:
        return x[np.ix_(idx, idx)]
    return x[idx]


__all__ = ["DHRow", "RigidBody", "SerialChain", "active_block", "dh_transform"]
