"""Test oracles for the stick method, each written the plain way the package's fast path
replaced; the tests hold the fast path to them. Test-only: the package keeps one implementation.

- Sec. II of Higashimori et al. in matrix form (eqs. 3-5, 9, 22, 26), against the closed forms of
  replay/control/stick/collision.py.
- ContactPlanner's scalar paths (replay/control/stick/plan.py) in whole-array NumPy
  (test_coverage_paths.py, test_stick_fast_paths.py).
"""

from __future__ import annotations

import math

import numpy as np

from replay.control.stick import collision as sc
from replay.control.stick.hand_model import Config, route_configs, route_tips
from replay.control.stick.plan import CONTACT_GUARD
from replay.control.stick.coverage import Motion, Coverage, covered_along, sample_times
from replay.robot import hand2d


# -- Sec. II in matrix form -----------------------------------------------------------------
def rotation(theta: float) -> np.ndarray:
    """R_B(theta): the posture of Sigma_B in Sigma_R."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def tangent_normal(theta: float, side: int) -> tuple[np.ndarray, np.ndarray]:
    """s_i and n_i in Sigma_R (eqs. 3, 4): n_i = R_B [0, -side] points into the stick."""
    n = rotation(theta) @ np.array([0.0, -1.0 if side > 0 else 1.0])
    return np.array([-n[1], n[0]]), n  # s_i = n_i turned by -90 degrees


def contact_jacobian(theta: float, r_b) -> np.ndarray:
    """H_i of eq. 5: v_C = H_i u (eqs. 6, 7), with [a x] = [-a_y, a_x]."""
    a = rotation(theta) @ np.asarray(r_b, dtype=float)
    return np.array([[1.0, 0.0, -a[1]], [0.0, 1.0, a[0]]])


def collision_map(m: float, inertia: float, e: float, theta: float, r_b, side: int) -> np.ndarray:
    """Eq. 22 as written: J_i = E_3 - (1 + e) M^-1 H^T K^-1 n n^T H, K = H M^-1 H^T (eq. 9)."""
    M_inv = np.linalg.inv(np.diag([m, m, inertia]))
    H = contact_jacobian(theta, r_b)
    n = tangent_normal(theta, side)[1]
    K = H @ M_inv @ H.T
    return np.eye(3) - (1.0 + e) * M_inv @ H.T @ np.linalg.solve(K, np.outer(n, n) @ H)


def axis_map(m: float, inertia: float, e: float, theta: float, r_x: float, side: int):
    """J_i for a contact on the stick's axis, ^B r = [r_x, 0] (W ~ 0, Assumption 5)."""
    return collision_map(m, inertia, e, theta, (r_x, 0.0), side)


def contact_condition(m, inertia, e, theta, r_x, side, u_prev) -> float:
    """C_i of eq. 26: n_i^T H_i J_i u_{i-1}, the contact point's normal velocity after."""
    n = tangent_normal(theta, side)[1]
    H = contact_jacobian(theta, (r_x, 0.0))
    J = axis_map(m, inertia, e, theta, r_x, side)
    return float(n @ H @ J @ np.asarray(u_prev, dtype=float))


def solve_contact(m, inertia, e, theta, side, u_prev, **target) -> sc.ContactSolution | None:
    """The package's solutions on one ``side`` (omega= or speed=, length=), the one with the
    smaller |r_x| (None when no root passes eq. 26)."""
    opts = sc.contact_options(m, inertia, e, theta, u_prev, sides=(side,), **target)
    return min(opts, key=lambda sol: abs(sol.r_x)) if opts else None


# -- ContactPlanner's scalar paths in whole-array NumPy -------------------------------------


def route_clear(
    planner,
    t: float,
    now: Config,
    route: list,
    k: int,
    motion: Motion,
    t_c: float,
    check_idle: bool = True,
) -> float | None:
    """``planner.route_clear`` in whole-array NumPy."""
    p, st, hand = planner.params, planner.stick, planner.hand
    timed = planner._route_timing(now, route, t_c)
    if timed is None:
        return None
    arrival, starts, frm, to = timed
    # sampled every SAMPLE_DT from t: the hand along the route (route_configs, route_tips);
    # finger k's tip must stay out of the sweep (coverage.covered_along) until CONTACT_GUARD
    # before t_c; the idle tip, with check_idle, until t_c + post_horizon, keeping
    # sweep_margin, or on the way at least the clearance it has now
    times = sample_times(t, t_c + (p.post_horizon if check_idle else 0.0))
    base, joints = route_configs(hand, starts, frm, to, times)
    tips = route_tips(hand, base, joints)
    half_l, half_w = 0.5 * st.length, 0.5 * st.width
    act = times <= t_c - CONTACT_GUARD
    c, th = poses = motion.poses(times)
    tip_r = hand.tip_radius - 5e-4
    if covered_along(
        motion, times[act], tips[act, k], half_l, half_w, tip_r, poses=(c[act], th[act])
    ).any():
        return None
    if check_idle:
        on_way = planner._idle_clearance(t, tips[0, 1 - k], motion)
        grow = np.where(times < arrival, on_way, hand.tip_radius + p.sweep_margin)
        if covered_along(motion, times, tips[:, 1 - k], half_l, half_w, grow, poses).any():
            return None
    return arrival


def exit_config(planner, t: float, now: Config, motion: Motion) -> Config | None:
    """``planner._exit_config`` on arrays."""
    p, st, hand = planner.params, planner.stick, planner.hand
    c, _ = motion.pose(t)
    r_in = 0.5 * st.length + hand.tip_radius + p.sweep_margin
    r_out = 0.5 * st.length + hand.tip_radius + p.stage_margin
    cfg, moved = now, False
    for k in (0, 1):
        d = now.tip(hand, k) - c
        dist = float(np.linalg.norm(d))
        if dist >= r_in or dist < 1e-9:
            continue
        q = hand2d.finger_ik(hand, now.base, k, c + d / dist * r_out, q_near=now.joints[k])
        if q is None:
            return None
        cfg, moved = cfg.with_finger(k, q), True
    return cfg if moved else None


def passive(planner, cfg: Config, j: int, sweep: Coverage, active_tip):
    """``planner._passive`` on arrays: every posture's tip and distance, then the first clear
    one in order."""
    hand, st, p = planner.hand, planner.stick, planner.params
    cur = cfg.joints[j]
    g = planner._grid_reach  # (l1 cos q1, l1 sin q1, l2 cos q12, l2 sin q12) of the grid
    rx, ry = cfg.base[0] + hand.root_offsets[j][0], cfg.base[1] + hand.root_offsets[j][1]
    tips = np.empty((1 + len(g[0]), 2))
    tips[0] = hand2d.finger_tip(hand, cfg.base, j, cur)
    tips[1:, 0] = (rx + g[0]) + g[2]
    tips[1:, 1] = (ry + g[1]) + g[3]
    d = tips - np.asarray(active_tip)[None, :]
    far = np.sqrt(d[:, 0] ** 2 + d[:, 1] ** 2) > 2.0 * hand.tip_radius + p.sweep_margin
    grid = planner._grid_q
    dist = np.empty(len(tips))
    dist[0] = 0.0
    dist[1:] = np.maximum(np.abs(grid[:, 0] - cur[0]), np.abs(grid[:, 1] - cur[1]))
    half_l, half_w, grow = 0.5 * st.length, 0.5 * st.width, hand.tip_radius + p.sweep_margin
    for i in np.lexsort((np.arange(len(tips)), dist)):
        if far[i] and not sweep.hits(tips[i], half_l, half_w, grow):
            return tuple(cur) if i == 0 else planner._passive_grid[i - 1]
    return None
