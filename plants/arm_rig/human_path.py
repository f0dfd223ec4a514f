"""A human hand moving the object on its constraint plane: a seeded, band-limited random path
and a compliant coupling to it.

The path (in the plane's two in-plane axes u, v and the roll about its normal) is a sum of
``components`` sinusoids per axis with frequencies drawn uniformly in ``[f_min, f_max]`` Hz,
random phases and amplitudes ~ 1/f (slower motions larger, as a hand moves), scaled so that the
RMS in-plane speed over time is ``speed`` (m/s) and the RMS roll rate is ``roll_rate`` (rad/s).
It starts at the object's initial pose. Irregular and not known to the robot (Sec. 5: "moved by
a human hand, its trajectory is irregular and difficult to predict").

Kicks (off unless ``kick_rate`` > 0; issue #38's harder motion): at the times of a Poisson process
of rate ``kick_rate`` (1/s, from the path's start) the path's in-plane velocity steps by
``kick_speed`` (m/s) in a uniformly random direction for ``kick_duration`` (s), then steps back:
the path is displaced by ``kick_speed * kick_duration`` within that time. Drawn from a generator
seeded by one draw of the run's, after the path's, only when kicks are on.

The hand holds the object compliantly (issue #20; the paper gives no model of the human): a
spring-damper to the path's pose plus the object's weight, applied at its centre of mass as an
external force and torque each step,

    F = m g_up + k (x_h - x) + c (v_h - v),     |F| <= max_force (the vector's magnitude),
    T = k_r rotvec(R_h R^T) + c_r (w_h - w),    |T| <= max_torque,

so the object follows the path unless something (the robot's grasp) holds it elsewhere, and
then the human pulls with ``k`` times the offset: a force the robot's wrist sensor feels. The
force and torque applied are read back for the log (``/human/state``, ``/human/wrench``).

No simulator here: ``human_hand.HumanHand`` applies the wrench in PyBullet, the MuJoCo plant
through ``xfrc_applied``.
"""

from __future__ import annotations

import math

import numpy as np

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


class HumanPath:
    """The path and the spring-damper coupling's force and torque; no simulator (a plant applies
    ``force_l`` / ``torque_l`` at the object's centre of mass each step)."""

    def __init__(
        self,
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
        mass: float,
        gravity: float,
        stiffness: float,
        damping: float,
        rot_stiffness: float,
        rot_damping: float,
        max_torque: float,
        kick_rate: float = 0.0,
        kick_speed: float = 0.0,
        kick_duration: float = 0.0,
    ) -> None:
        self.origin = np.asarray(origin, float)
        self.u, self.v, self.n = (np.asarray(x, float) for x in (u, v, n))
        self._n = self.n.tolist()
        self.start = float(start)
        self.max_force = float(max_force)
        self.max_torque = float(max_torque)
        self.k, self.c = float(stiffness), float(damping)
        self.k_r, self.c_r = float(rot_stiffness), float(rot_damping)
        self.weight = float(mass) * float(gravity)  # N, carried by the hand (world +z)
        self.w, self.a, self.phi = band_limited_path(
            rng, components=components, f_min=f_min, f_max=f_max, rms_rate=speed, axes=2
        )
        self.rw, self.ra, self.rphi = band_limited_path(
            rng, components=components, f_min=f_min, f_max=f_max, rms_rate=roll_rate, axes=1
        )
        # the three axes' sinusoids stacked (u, v, roll rows)
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
        self.velocity_l = [0.0, 0.0, 0.0]
        self.roll = 0.0
        self.roll_rate = 0.0
        self.force_l = [0.0, 0.0, 0.0]  # N, world: the hand's force on the object (last step)
        self.torque_l = [0.0, 0.0, 0.0]  # N m, world
        self.limited = False  # the force (or torque) was at its limit in the last step
        self.kicks = Kicks(rng, kick_rate, kick_speed, kick_duration) if kick_rate > 0.0 else None

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
        if self.kicks is not None:
            ku, kv = self.kicks.offset(tt)
            du, dv = du + ku, dv + kv
        return du, dv, r

    def rate(self, t: float) -> tuple[float, float, float]:
        """d/dt of :meth:`offset` (m/s, m/s, rad/s)."""
        if t < self.start:
            return 0.0, 0.0, 0.0
        tt = t - self.start
        cos = math.cos
        du, dv, r = (sum(a * w * cos(w * tt + phi) for w, a, phi, _ in row) for row in self._rows)
        if self.kicks is not None:
            ku, kv = self.kicks.rate(tt)
            du, dv = du + ku, dv + kv
        return du, dv, r

    @property
    def target(self) -> np.ndarray:
        """Where the hand's path is now (m, world)."""
        return np.array(self.target_l)

    def target_orientation(self) -> list[float]:
        """The path's orientation now: the start orientation turned by ``roll`` about the
        plane normal, q = q_n(roll) q0 ([qx, qy, qz, qw])."""
        s, c = math.sin(self.roll / 2.0), math.cos(self.roll / 2.0)
        ax, ay, az = (x * s for x in self._n)
        bx, by, bz, bw = self.q0
        return [
            c * bx + ax * bw + ay * bz - az * by,
            c * by - ax * bz + ay * bw + az * bx,
            c * bz + ax * by - ay * bx + az * bw,
            c * bw - ax * bx - ay * by - az * bz,
        ]

    def drive(self, t: float, pos, orn, vel, omega) -> None:
        """The path at ``t`` and the hand's force and torque on the object in state (pos, orn,
        vel, omega) (``force_l``, ``torque_l``), for the plant to apply in the next step."""
        du, dv, dr = self.offset(t)
        ru, rv, rr = self.rate(t)
        self.target_l = [o + du * a + dv * b for o, a, b in zip(self._origin, self._u, self._v)]
        self.velocity_l = [ru * a + rv * b for a, b in zip(self._u, self._v)]
        self.roll, self.roll_rate = dr, rr
        k, c = self.k, self.c
        F = [
            k * (x_h - x) + c * (v_h - v)
            for x_h, x, v_h, v in zip(self.target_l, pos, self.velocity_l, vel)
        ]
        F[2] += self.weight
        # rotation: the error q_h q^-1 (world) as a rotation vector, the roll rate about n
        hx, hy, hz, hw = self.target_orientation()
        bx, by, bz, bw = -orn[0], -orn[1], -orn[2], orn[3]  # q^-1 (unit q)
        ex = hw * bx + hx * bw + hy * bz - hz * by
        ey = hw * by - hx * bz + hy * bw + hz * bx
        ez = hw * bz + hx * by - hy * bx + hz * bw
        ew = hw * bw - hx * bx - hy * by - hz * bz
        if ew < 0.0:  # the shorter way round
            ex, ey, ez, ew = -ex, -ey, -ez, -ew
        sn = math.sqrt(ex * ex + ey * ey + ez * ez)
        g = 2.0 * math.atan2(sn, ew) / sn if sn > 1e-12 else 2.0
        kr, cr, n = self.k_r, self.c_r, self._n
        T = [kr * g * e + cr * (rr * nn - w) for e, nn, w in zip((ex, ey, ez), n, omega)]
        self.limited = False
        f = math.sqrt(F[0] * F[0] + F[1] * F[1] + F[2] * F[2])
        tq = math.sqrt(T[0] * T[0] + T[1] * T[1] + T[2] * T[2])
        if f > self.max_force:
            F = [x * (self.max_force / f) for x in F]
            self.limited = True
        if tq > self.max_torque:
            T = [x * (self.max_torque / tq) for x in T]
            self.limited = True
        self.force_l, self.torque_l = F, T

    def force(self) -> list[float]:
        """The hand's force on the object (N, world), applied in the last step."""
        return self.force_l[:]


class Kicks:
    """The kicks' in-plane (u, v) offset and rate at a time since the path's start: each kick
    (t_k, direction) adds ``speed`` along its direction during [t_k, t_k + ``duration``]. Kick
    times are drawn lazily (exponential gaps of mean 1 / ``rate``) as time passes them."""

    def __init__(self, rng: np.random.Generator, rate: float, speed: float, duration: float):
        if speed <= 0.0 or duration <= 0.0:
            raise ValueError("kicks need human_kick_speed > 0 and human_kick_duration > 0")
        self.rng = np.random.default_rng(int(rng.integers(2**63)))
        self.mean_gap, self.speed, self.duration = 1.0 / rate, float(speed), float(duration)
        self.times: list[float] = []
        self.dirs: list[tuple[float, float]] = []
        self._next = float(self.rng.exponential(self.mean_gap))

    def _draw(self, tt: float) -> None:
        while self._next <= tt:
            a = float(self.rng.uniform(0.0, 2.0 * math.pi))
            self.times.append(self._next)
            self.dirs.append((math.cos(a), math.sin(a)))
            self._next += float(self.rng.exponential(self.mean_gap))

    def offset(self, tt: float) -> tuple[float, float]:
        """(du, dv) m: the kicks' displacement of the path at ``tt`` s after its start."""
        self._draw(tt)
        du = dv = 0.0
        for t0, (cu, cv) in zip(self.times, self.dirs):
            d = self.speed * min(tt - t0, self.duration)
            du, dv = du + d * cu, dv + d * cv
        return du, dv

    def rate(self, tt: float) -> tuple[float, float]:
        """(du/dt, dv/dt) m/s of the kicks at ``tt``."""
        self._draw(tt)
        ru = rv = 0.0
        for t0, (cu, cv) in zip(self.times, self.dirs):
            if t0 <= tt < t0 + self.duration:
                ru, rv = ru + self.speed * cu, rv + self.speed * cv
        return ru, rv


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
