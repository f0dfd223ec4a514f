"""Friction independent collision of a stick with a fixed fingertip (Higashimori et al. 2007, Sec. II).

Closed forms in floats (the matrix forms of eqs. 3-5, 9, 22 and 26 are the tests' oracles,
tests/replay/control/stick/oracles.py). Velocities u = [vx, vy, omega] of the stick's centre of mass in the reference frame
Sigma_R; theta is the stick's orientation (its x_B axis along the length); the contact point
^B r = [r_x, r_y] is in the stick frame Sigma_B. ``side`` = +1 for a fingertip touching from
y_B >= 0 (^B r_y = +W/2), -1 from y_B <= 0 (^B r_y = -W/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass


from replay.robot.stick_impact import quadratic_roots as _roots


def normal(theta: float, side: int) -> tuple[float, float]:
    """n_i in Sigma_R (eq. 4) as floats: R_B(theta) [0, -side]."""
    c, s = math.cos(theta), math.sin(theta)
    return (s, -c) if side > 0 else (-s, c)


def _impulse_terms(
    m: float, inertia: float, theta: float, r_x: float, r_y: float, side: int
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(g, h) with J_i = E_3 - (1 + e) g h^T (eq. 22), in closed form: h = H_i^T n_i and
    g = M^-1 H_i^T K_i^-1 n_i, M = diag(m, m, I) and K_i = H_i M^-1 H_i^T (eqs. 5, 9), K_i
    inverted as a 2 x 2."""
    return _terms(m, inertia, math.cos(theta), math.sin(theta), r_x, r_y, side)


def _terms(
    m: float, inertia: float, c: float, s: float, r_x: float, r_y: float, side: int
) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """:func:`_impulse_terms` with c, s = cos(theta), sin(theta) already made."""
    ax, ay = c * r_x - s * r_y, s * r_x + c * r_y  # a = R_B(theta) ^B r
    nx, ny = (s, -c) if side > 0 else (-s, c)
    k11, k12, k22 = 1.0 / m + ay * ay / inertia, -ax * ay / inertia, 1.0 / m + ax * ax / inertia
    det = k11 * k22 - k12 * k12
    wx, wy = (k22 * nx - k12 * ny) / det, (k11 * ny - k12 * nx) / det  # K^-1 n
    g = (wx / m, wy / m, (-ay * wx + ax * wy) / inertia)
    h = (nx, ny, -ay * nx + ax * ny)
    return g, h


def _after(g, h, e: float, u) -> tuple[float, float, float]:
    """u_i = J_i u_{i-1} = u - (1 + e) g (h . u) (eq. 22)."""
    k = (1.0 + e) * (h[0] * u[0] + h[1] * u[1] + h[2] * u[2])
    return (u[0] - k * g[0], u[1] - k * g[1], u[2] - k * g[2])


def alpha(a) -> float:
    """alpha(a) of eq. 23: the orientation that makes the stick perpendicular to the vector a."""
    ax, ay = float(a[0]), float(a[1])
    if ay != 0.0:
        return math.atan(-ax / ay)
    return math.pi / 2.0


def friction_independent(theta: float, v, side: int = 1, tol: float = 1e-9) -> bool:
    """Eq. 12: s_i^T v_{B,i-1} = 0 (within ``tol`` of |v|)."""
    nx, ny = normal(theta, side)
    vx, vy = float(v[0]), float(v[1])
    return abs(-ny * vx + nx * vy) <= tol * max(1.0, math.hypot(vx, vy))  # s = (-n_y, n_x)


# --------------------------------------------------------------------------------------------
# Sec. II-D: the fingertip position for a desired velocity after a friction independent collision
#
# The quadratics of eqs. 25 and 28 are derived for W ~ 0 (Assumption 5): the contact is taken on
# the stick's axis, ^B r = [r_x, 0], in H_i, J_i and C_i below. The paper writes b_1 and b_2 for
# the side ^B r_y = +W/2; for ^B r_y = -W/2 its r_x is measured along s_i = -x_B. We write them in
# ^B r_x for both sides, which multiplies b_1 and b_2 by ``side`` (the roots then satisfy eqs. 24
# and 27 through J_i exactly on either side).
# --------------------------------------------------------------------------------------------


def _sign(side: int) -> float:
    return 1.0 if side > 0 else -1.0


def _u3(u) -> tuple[float, float, float]:
    return float(u[0]), float(u[1]), float(u[2])


def f_omega(
    m: float, inertia: float, e: float, theta: float, side: int, u_prev, omega_d: float
) -> tuple[float, ...]:
    """F_omega,i(omega_d) of eq. 25: both r_x (ascending) giving omega_i = omega_d (eq. 24)."""
    vx, vy, w = _u3(u_prev)
    nx, ny = normal(theta, side)
    a1 = m * (omega_d + e * w)
    b1 = -(1.0 + e) * m * _sign(side) * (nx * vx + ny * vy)
    c1 = inertia * (omega_d - w)
    return _roots(a1, b1, c1)


def f_v(
    m: float, inertia: float, e: float, theta: float, side: int, u_prev, speed_d: float
) -> tuple[float, ...]:
    """F_V,i(V_d) of eq. 28: both r_x (ascending) giving V_i = V_d (eq. 27).

    V_i is the speed along -v_{i-1}/|v_{i-1}| (V_d = 0 stops the translation); valid for a
    friction independent collision, theta = alpha(v_{i-1}), and v_{i-1} != 0.
    """
    vx, vy, w = _u3(u_prev)
    speed = math.hypot(vx, vy)
    if speed == 0.0:
        return ()
    nx, ny = normal(theta, side)
    a2 = m * (speed_d + speed)
    b2 = (1.0 + e) * inertia * w * _sign(side) * (nx * vx + ny * vy) / speed
    c2 = inertia * (speed_d - e * speed)
    return _roots(a2, b2, c2)


def approach_speed(theta: float, r_x: float, side: int, u_prev) -> float:
    """-n_i^T H_i u_{i-1}: how fast the contact point moves into the fingertip before (m/s)."""
    vx, vy, w = _u3(u_prev)
    nx, ny = normal(theta, side)
    ax, ay = math.cos(theta) * r_x, math.sin(theta) * r_x  # R_B(theta) [r_x, 0]
    return -(nx * vx + ny * vy + (-ay * nx + ax * ny) * w)


@dataclass(frozen=True, init=False)
class ContactSolution:
    """One planned friction independent collision: where, from which side, and what it does."""

    theta: float  # theta_B,i (rad), in (-pi/2, pi/2] as alpha() returns it
    side: int  # +1: ^B r_y = +W/2, -1: ^B r_y = -W/2
    r_x: float  # ^B r_x,i (m)
    u_before: tuple  # u_{i-1} = (vx, vy, omega)
    u_after: tuple  # u_i = J_i u_{i-1} (eq. 22)
    roots: tuple  # both roots of eq. 25 / 28 (m)
    condition: float  # C_i (eq. 26) of the chosen root (m/s)
    length: float | None = None

    def __init__(
        self,
        theta: float,
        side: int,
        r_x: float,
        u_before: tuple,
        u_after: tuple,
        roots: tuple,
        condition: float,
        length: float | None = None,
    ) -> None:
        # the fields straight into the instance's dict (a frozen dataclass's generated __init__ sets
        # each through object.__setattr__, ~1 us a field on Python 3.11; test_stick_fast_paths.py
        # holds this one to the generated one's result)
        d = self.__dict__
        d["theta"], d["side"], d["r_x"], d["u_before"] = theta, side, r_x, u_before
        d["u_after"], d["roots"], d["condition"], d["length"] = u_after, roots, condition, length

    @property
    def within(self) -> bool:
        """|r_x| <= L/2 (always True when no length was given)."""
        return self.length is None or abs(self.r_x) <= 0.5 * self.length + 1e-12


def contact_options(
    m: float,
    inertia: float,
    e: float,
    theta: float,
    u_prev,
    *,
    omega: float | None = None,
    speed: float | None = None,
    length: float | None = None,
    sides=(1, -1),
) -> list[ContactSolution]:
    """Every (side, root) giving omega_i = ``omega`` (eq. 25) or V_i = ``speed`` (eq. 28) that
    passes C_i > 0 (eq. 26), each with u_i = J_i u_{i-1}.

    Both roots of one side can pass eq. 26 (e.g. F_V,1(0) for the Fig. 7 numbers: r_x = -25.8 mm
    gives omega_1 = -10 rad/s, r_x = +10.5 mm gives +18 rad/s): the strategy's own rule (eq. 31,
    35 or 37) then chooses. Roots beyond the stick (|r_x| > L/2) are kept, ``within`` False.
    """
    if (omega is None) == (speed is None):
        raise ValueError("give exactly one of omega, speed")
    u = _u3(u_prev)
    out = []
    c, s = math.cos(theta), math.sin(theta)
    tol = 1e-12 * max(1.0, math.sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]))
    for side in sides:
        if omega is not None:
            roots = f_omega(m, inertia, e, theta, side, u, omega)
        elif speed is not None:
            roots = f_v(m, inertia, e, theta, side, u, speed)
        roots = tuple(float(r) for r in roots)
        for r in roots:
            # contact_at, with eq. 26 checked before the solution is made: C_i > 0; for e = 0
            # C_i vanishes, so the approach before is tested instead
            g, h = _terms(m, inertia, c, s, r, 0.0, side)
            after = _after(g, h, e, u)
            condition = h[0] * after[0] + h[1] * after[1] + h[2] * after[2]
            if e > 0.0:
                if not condition > tol:
                    continue
            elif not approach_speed(theta, r, side, u) > 1e-12:
                continue
            sign = 1 if side > 0 else -1
            out.append(ContactSolution(theta, sign, r, u, after, roots, condition, length))
    return out


def contact_at(
    m: float,
    inertia: float,
    e: float,
    theta: float,
    side: int,
    u_prev,
    r_x: float,
    *,
    length: float | None = None,
    roots: tuple = (),
) -> ContactSolution:
    """The collision at a given r_x (e.g. a clamped one), predicted with J_i (eq. 22)."""
    u = _u3(u_prev)
    r_x = float(r_x)
    g, h = _impulse_terms(m, inertia, theta, r_x, 0.0, side)
    u_after = _after(g, h, e, u)
    return ContactSolution(
        theta=theta,
        side=1 if side > 0 else -1,
        r_x=r_x,
        u_before=u,
        u_after=u_after,
        roots=tuple(float(r) for r in roots),
        condition=h[0] * u_after[0] + h[1] * u_after[1] + h[2] * u_after[2],  # C_i (eq. 26)
        length=length,
    )


# --------------------------------------------------------------------------------------------
# Sec. III: the contact conditions of the 2-step and 3-step strategies (side selection)
# --------------------------------------------------------------------------------------------


def two_step_first(
    m: float, inertia: float, e: float, u0, length: float | None = None
) -> ContactSolution | None:
    """Eq. 30: theta_1 = alpha(v_0), r_x = F_omega,1(0) with C_1 > 0, and the side giving p = -1
    in eq. 31 (v_1 against v_0). Preference: within the stick, then p = -1, then small |r_x|."""
    u = _u3(u0)
    theta = alpha(u[:2])
    sols = contact_options(m, inertia, e, theta, u, omega=0.0, length=length)
    if not sols:
        return None
    return min(
        sols,
        key=lambda s: (
            not s.within,
            s.u_after[0] * u[0] + s.u_after[1] * u[1] >= 0.0,
            abs(s.r_x),
        ),
    )


def three_step_first(
    m: float, inertia: float, e: float, u0, length: float | None = None
) -> ContactSolution | None:
    """Eq. 34: theta_1 = alpha(v_0), r_x = F_V,1(0) with C_1 > 0; the side satisfying eq. 35
    (omega_1 against omega_0) is preferred after being within the stick."""
    u = _u3(u0)
    theta = alpha(u[:2])
    sols = contact_options(m, inertia, e, theta, u, speed=0.0, length=length)
    if not sols:
        return None
    return min(sols, key=lambda s: (not s.within, s.u_after[2] * u[2] >= 0.0, abs(s.r_x)))


def three_step_second(
    m: float, inertia: float, e: float, u1, lambda_2, length: float | None = None
) -> ContactSolution | None:
    """Eq. 36: theta_2 = alpha(lambda_2), r_x = F_omega,2(0) with C_2 > 0, and the side for which
    v_2 / |v_2| = lambda_2 (eq. 37). None when no side sends the stick along lambda_2."""
    u = _u3(u1)
    lx, ly = float(lambda_2[0]), float(lambda_2[1])
    theta = alpha((lx, ly))
    sols = [
        s
        for s in contact_options(m, inertia, e, theta, u, omega=0.0, length=length)
        if s.u_after[0] * lx + s.u_after[1] * ly > 0.0
    ]
    if not sols:
        return None
    return min(sols, key=lambda s: (not s.within, abs(s.r_x)))


def closing_contact(
    m: float, inertia: float, e: float, u_prev, length: float | None = None
) -> ContactSolution | None:
    """Eqs. 32 / 38: ^B r_x = 0 on the side the stick moves into (n_i = -n_{i-1} alternately),
    so v_i = -e v_{i-1} (eq. 33) and no rotation. None when the stick does not translate."""
    u = _u3(u_prev)
    if u[0] == 0.0 and u[1] == 0.0:
        return None
    theta = alpha(u[:2])
    for side in (1, -1):
        if approach_speed(theta, 0.0, side, u) > 0.0:
            return contact_at(m, inertia, e, theta, side, u, 0.0, length=length, roots=(0.0,))
    return None
