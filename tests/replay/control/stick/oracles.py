"""The stick planner's array oracles: each fast scalar path of ContactPlanner
(replay/control/stick/plan.py) written again in whole-array NumPy, the formulation it replaced,
for the tests that hold the fast path to it (test_sweep_paths.py, test_stick_fast_paths.py).
Test-only: the package keeps one implementation of each."""

from __future__ import annotations

import numpy as np

from replay.control.stick.hand_model import Config, route_configs, route_tips
from replay.control.stick.plan import CONTACT_GUARD
from replay.control.stick.sweep import Motion, Sweep, covered_along, sample_times
from replay.robot import hand2d


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
    # finger k's tip must stay out of the sweep (sweep.covered_along) until CONTACT_GUARD
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


def passive(planner, cfg: Config, j: int, sweep: Sweep, active_tip):
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
