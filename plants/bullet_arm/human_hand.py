"""A human hand moving the object on its constraint plane: a seeded, band-limited random path
applied through a force-limited constraint.

The path (in the plane's two in-plane axes u, v and the roll about its normal) is a sum of
``components`` sinusoids per axis with frequencies drawn uniformly in ``[f_min, f_max]`` Hz,
random phases and amplitudes ~ 1/f (slower motions larger, as a hand moves), scaled so that the
RMS in-plane speed over time is ``speed`` (m/s) and the RMS roll rate is ``roll_rate`` (rad/s).
It starts at the object's initial pose. Irregular and not known to the robot (Sec. 5: "moved by
a human hand, its trajectory is irregular and difficult to predict").

The hand holds the object with a PyBullet fixed constraint to the path's pose whose force is
limited to ``max_force`` (a human's grip-and-arm strength): the object follows the path unless
something (the robot's grasp) resists harder; the constraint force is read back.
"""

from __future__ import annotations

import math

import numpy as np
import pybullet as p

from replay.spatial import matrix_to_quaternion, rpy_to_matrix


def band_limited_path(
    rng: np.random.Generator,
    *,
    components: int,
    f_min: float,
    f_max: float,
    rms_rate: float,
    axes: int,
):
    """(omega (axes, n), amplitude (axes, n), phase (axes, n)): sum_i a_i sin(w_i t + phi_i) per
    axis, with sum over axes and components of (a w)^2 / 2 = rms_rate^2."""
    f = rng.uniform(f_min, f_max, size=(axes, components))
    w = 2.0 * math.pi * f
    a = 1.0 / f
    phi = rng.uniform(0.0, 2.0 * math.pi, size=(axes, components))
    ms = float(np.sum((a * w) ** 2) / 2.0)
    a *= rms_rate / math.sqrt(ms) if ms > 0.0 else 0.0
    return w, a, phi


class HumanHand:
    def __init__(
        self,
        bc,
        obj: int,
        rng: np.random.Generator,
        *,
        origin,
        rpy0,
        u,
        v,
        n,
        speed: float,
        roll_rate: float,
        f_min: float,
        f_max: float,
        components: int,
        max_force: float,
        start: float,
    ) -> None:
        self.bc, self.obj = bc, obj
        self.origin = np.asarray(origin, float)
        self.u, self.v, self.n = (np.asarray(x, float) for x in (u, v, n))
        self._n = self.n.tolist()
        self.start = float(start)
        self.max_force = float(max_force)
        self.w, self.a, self.phi = band_limited_path(
            rng, components=components, f_min=f_min, f_max=f_max, rms_rate=speed, axes=2
        )
        self.rw, self.ra, self.rphi = band_limited_path(
            rng, components=components, f_min=f_min, f_max=f_max, rms_rate=roll_rate, axes=1
        )
        # the three axes' sinusoids stacked (u, v, roll rows): one sin a step; each row's sum is
        # the same reduction as the separate ones
        self._W = np.concatenate([self.w, self.rw])
        self._A = np.concatenate([self.a, self.ra])
        self._PHI = np.concatenate([self.phi, self.rphi])
        self._S0 = np.sin(self._PHI)
        # per row (u, v, roll) as floats for offset(): (omega, amplitude, phase, sin(phase))
        self._rows = [
            list(zip(*row))
            for row in zip(
                self._W.tolist(), self._A.tolist(), self._PHI.tolist(), self._S0.tolist()
            )
        ]
        self.R0 = _rpy_matrix(rpy0)
        self.q0 = _quat(self.R0)
        self._origin, self._u, self._v = self.origin.tolist(), self.u.tolist(), self.v.tolist()
        self.target_l = self.origin.tolist()
        self.roll = 0.0
        self.cid = bc.createConstraint(
            obj,
            -1,
            -1,
            -1,
            p.JOINT_FIXED,
            [0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
            self.origin.tolist(),
            childFrameOrientation=_quat(self.R0),
        )
        bc.changeConstraint(self.cid, maxForce=self.max_force)

    def offset(self, t: float) -> tuple[float, float, float]:
        """(du, dv, droll) of the path from the start pose at time ``t``."""
        tt = max(t - self.start, 0.0)
        sin = math.sin
        # sum_i a_i (sin(w_i tt + phi_i) - sin(phi_i)) per axis, in floats; the sum in NumPy's
        # order (numpy_row_sum), so the path is the array form's to the bit
        du, dv, r = (
            numpy_row_sum([a * (sin(w * tt + phi) - s0) for w, a, phi, s0 in row])
            for row in self._rows
        )
        return du, dv, r

    @property
    def target(self) -> np.ndarray:
        """Where the hand pulls the object now (m, world)."""
        return np.array(self.target_l)

    def drive(self, t: float) -> None:
        du, dv, dr = self.offset(t)
        # origin + du u + dv v per axis in floats (the vector form's operations and order)
        self.target_l = [o + du * a + dv * b for o, a, b in zip(self._origin, self._u, self._v)]
        self.roll = dr
        # the start orientation turned by dr about the plane normal: q = q_n(dr) q0
        s, c = math.sin(dr / 2.0), math.cos(dr / 2.0)
        ax, ay, az = (x * s for x in self._n)
        bx, by, bz, bw = self.q0
        q = [
            c * bx + ax * bw + ay * bz - az * by,
            c * by - ax * bz + ay * bw + az * bx,
            c * bz + ax * by - ay * bx + az * bw,
            c * bw - ax * bx - ay * by - az * bz,
        ]
        self.bc.changeConstraint(
            self.cid,
            jointChildPivot=self.target_l,
            jointChildFrameOrientation=q,
            maxForce=self.max_force,
        )

    def force(self) -> list[float]:
        """The constraint's force on the object (N, world), from the last step."""
        st = self.bc.getConstraintState(self.cid)
        return [float(st[0]), float(st[1]), float(st[2])]


def numpy_row_sum(xs: list) -> float:
    """sum(xs) in the order of NumPy's pairwise summation of a contiguous float64 row
    (numpy/_core/src/umath/loops_utils.h: sequential below 8 terms, eight running sums up to
    its 128-term block); longer rows are left to NumPy itself."""
    n = len(xs)
    if n < 8:
        acc = 0.0
        for x in xs:
            acc += x
        return acc
    if n > 128:
        return float(np.sum(np.asarray(xs, float)))
    r = xs[:8]
    m = n - n % 8
    for i in range(8, m, 8):
        for j in range(8):
            r[j] += xs[i + j]
    acc = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]))
    for x in xs[m:]:
        acc += x
    return acc


def _rpy_matrix(rpy) -> np.ndarray:
    return rpy_to_matrix(rpy)


def _quat(R) -> list[float]:
    return [float(x) for x in matrix_to_quaternion(R)]
