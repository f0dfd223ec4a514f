"""Closed forms of a stick hitting a fixed fingertip (Higashimori et al. 2007, Secs. II and IV-B).

No simulator: the numbers the claims table derives from the paper's stated parameters (Fig. 7), and
the quadratic both they and the method's contact solver (``replay.control.stick.collision``) use.
"""

from __future__ import annotations

import math


def quadratic_roots(a: float, b: float, c: float) -> tuple[float, ...]:
    """Real roots of a r^2 + b r + c = 0, ascending (one root when a ~ 0, none when complex)."""
    scale = max(abs(a), abs(b), abs(c), 1e-300)
    if abs(a) <= 1e-12 * scale:
        return () if abs(b) <= 1e-12 * scale else (-c / b,)
    disc = b * b - 4.0 * a * c
    if disc < 0.0:
        return ()
    q = -0.5 * (b + math.copysign(math.sqrt(disc), b))  # numerically stable pair
    if q == 0.0:
        return (0.0,)
    return tuple(sorted((q / a, c / q)))


# --------------------------------------------------------------------------------------------
# Derived numbers (Sec. IV-B, Fig. 7)
# --------------------------------------------------------------------------------------------


def spin_before_pure_rotation(
    m: float, inertia: float, e: float, speed: float, omega_1: float
) -> list[tuple[float, float]]:
    """The initial spins omega_0 for which the 3-step first collision (v_1 = 0 at
    theta_1 = alpha(v_0), eq. 34) of a stick moving at ``speed`` leaves ``omega_1``.

    Returns [(omega_0, d), ...], d = |^B r_x,1| (m), smaller d first; [] when none exists.
    With v_1 = 0, eq. 22 gives omega_1 = omega_0 - sgn(omega_1) m d |v_0| / I, and Newton's law
    (eq. 10) at the contact gives  e |v_0| m d^2 - (1 + e) I |omega_1| d + e |v_0| I = 0.
    """
    out = []
    for d in quadratic_roots(
        e * speed * m, -(1.0 + e) * inertia * abs(omega_1), e * speed * inertia
    ):
        if d > 0.0:
            out.append((omega_1 - math.copysign(1.0, omega_1) * m * d * speed / inertia, d))
    return sorted(out, key=lambda p: p[1])


def pure_rotation_min_spin(m: float, inertia: float, e: float, speed: float) -> float:
    """The least |omega_1| a 3-step first collision (v_1 = 0, eq. 34) can leave on a stick moving
    at ``speed``: 2 e |v_0| sqrt(m / I) / (1 + e), where the quadratic of
    :func:`spin_before_pure_rotation` has a double root."""
    return 2.0 * e * speed * math.sqrt(m / inertia) / (1.0 + e)


def pure_rotation_stop_distance(m: float, inertia: float, e: float) -> float:
    """|F_omega,2(0)| for a purely rotating stick (v_1 = 0): eq. 25 with b_1 = 0 gives
    r_x^2 = I / (m e), whatever omega_1 (the 3-step second collision, eq. 36)."""
    return math.sqrt(inertia / (m * e))


def pure_rotation_residual_spin(m: float, inertia: float, e: float, d: float) -> float:
    """omega_2 / omega_1 after a purely rotating stick hits a fingertip at |r_x| = d (eq. 22):
    (I - e m d^2) / (I + m d^2); zero at d = pure_rotation_stop_distance()."""
    return (inertia - e * m * d * d) / (inertia + m * d * d)
