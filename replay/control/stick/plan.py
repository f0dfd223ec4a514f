"""Planning the hand's approach to one collision of a stick-capture strategy.

Higashimori et al. 2007, Sec. III: collision i happens at the orientation theta* = alpha(v_{i-1})
(eq. 23; alpha(lambda_2) for the 3-step second collision, eq. 36) at the fingertip position
(r_x, r_y) the strategy solved (``collision``: eqs. 25, 28 with 26, and the side rules 31,
35, 37). Here that contact becomes a hand plan:

- :meth:`ContactPlanner.crossings`: the future times the predicted orientation equals theta*
  modulo pi (Assumption 6: constant velocities between collisions), earliest first, up to
  ``horizon``.
- :meth:`ContactPlanner.reach`: at a crossing, the contact point R(theta*) r and the fingertip
  centre contact - tip_radius n; a base and finger joints (``hand2d.finger_ik``) reachable in
  time (``hand2d.travel_time`` plus ``arrive_margin``), and an idle-finger posture clear of the
  stick's predicted sweep before and ``post_horizon`` after the contact (the motion J_i predicts,
  eq. 22).
- :meth:`ContactPlanner.find_route`: waypoints that bring the hand there with no fingertip hit
  on the way: straight, or via a staging point ``stage_margin`` outside a spinning stick's
  reach, moving in just after its last pass; each after first pulling a tip out of the stick's
  reach. :meth:`ContactPlanner.route_clear` checks a route against the sweep along the hand's
  own motion (each axis at its speed limit, as the plant moves).

The result is a :class:`ContactPlan` (the approach phase's plan; its ``intent`` is the ``plan``
event's data). :class:`Shortfall` keeps the best time needed vs available of failed attempts
(the ``unreachable`` report).

NumPy (the sampled sweep checks: ``coverage``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from replay.robot import hand2d
from replay.robot.hand2d import HandSpec
from replay.spatial import wrap_half_pi
from replay.control.stick import collision as sc
from replay.control.stick.estimator import StickEstimate
from replay.control.stick.hand_model import (
    Config,
    HandModel,
    base_candidates,
    posture_grid,
    finger_tips,
    route_axes,
    route_target,
    travel,
)
from replay.control.stick.coverage import (
    Motion,
    Coverage,
    count_before,
    covered_fixed,
    covered_samples,
    first_covered,
    sample_count,
    sample_times_at,
)

CONTACT_GUARD = 0.003  # s, the sweep check of the waiting tip stops this long before the contact
GO_DELAY = 0.003  # s, a staged tip moves in this long after the stick's last pass


def _still_after(hand: HandSpec, start: float, a: Config, b: Config, t: float, row) -> bool:
    """The last segment (``start``, a -> b) of a route has every axis on its target at t
    (``route_axes``' clip no longer binds: so at every later sample too) and ``row`` (the
    axes at t) is that segment's."""
    if t < start:
        return False
    va = [*a.base, *a.joints[0], *a.joints[1]]
    vb = [*b.base, *b.joints[0], *b.joints[1]]
    tau = max(t - start, 0.0)
    speeds = [hand.base_speed] * 2 + [hand.joint_speed] * 4
    row = row.tolist()  # (the row's floats at once, not an array index each)
    for i in range(6):
        step, d = tau * speeds[i], float(vb[i]) - float(va[i])
        if not (-step <= d <= step) or row[i] != float(va[i]) + d:
            return False
    return True


# ------------------------------------------------------------------------------------------
# The plan and the shortfall of failed attempts
# ------------------------------------------------------------------------------------------


@dataclass
class ContactPlan:
    index: int  # collision number i
    finger: int
    t: float  # planned contact time (s)
    theta: float  # continuous orientation at the contact (estimator's frame)
    sol: sc.ContactSolution  # in the frame theta* = sol.theta (mod pi)
    raw_r_x: float | None  # the solved r_x when it was beyond the stick (sol is clamped)
    contact: np.ndarray  # world contact point (m)
    tip: np.ndarray  # world fingertip centre (m)
    config: Config  # the hand at the contact
    route: list = field(default_factory=list)  # [(t_start, Config)], the last one = config
    exit: Config | None = None  # just after the contact: the tip out of the stick's sweep

    @property
    def clamped(self) -> bool:
        return self.raw_r_x is not None

    def target(self, t: float) -> Config:
        """The waypoint to command at time ``t`` (``exit`` from GO_DELAY after the contact)."""
        if self.exit is not None and t >= self.t + GO_DELAY:
            return self.exit
        return route_target(self.route, t, self.config)

    def frame_flip(self) -> int:
        """+1 if the estimator's frame at the contact equals theta*'s, -1 if it differs by pi."""
        k = round((self.theta - self.sol.theta) / math.pi)
        return 1 if k % 2 == 0 else -1

    def intent(self, width: float) -> dict:
        f = self.frame_flip()
        return {
            "index": self.index,
            "finger": self.finger,
            "t": float(self.t),
            "theta": float(self.theta),
            "r_x": f * self.sol.r_x,
            "r_y": f * self.sol.side * width / 2.0,
            "side": f * self.sol.side,
            "v_after": [float(self.sol.u_after[0]), float(self.sol.u_after[1])],
            "omega_after": float(self.sol.u_after[2]),
            "contact": [float(x) for x in self.contact],
            "tip": [float(x) for x in self.tip],
            "clamped": self.clamped,
            "r_x_solved": f * (self.raw_r_x if self.raw_r_x is not None else self.sol.r_x),
        }


@dataclass
class Shortfall:
    """The attempt that came closest: time needed vs time available (s)."""

    t_needed: float = math.inf
    t_available: float = 0.0

    def note(self, needed: float, available: float) -> None:
        if needed - available < self.t_needed - self.t_available:
            self.t_needed, self.t_available = needed, available


# ------------------------------------------------------------------------------------------
# The planner
# ------------------------------------------------------------------------------------------


class ContactPlanner:
    """Crossings, hand configurations and routes for one planned collision, for a hand whose
    motion ``model`` tracks the controller's commands."""

    def __init__(self, params, hand: HandSpec, stick, model: HandModel) -> None:
        self.params = params
        self.hand = hand
        self.stick = stick
        self.model = model
        self._passive_grid = posture_grid(hand)
        q = np.array(self._passive_grid)
        self._grid_q = q
        l1, l2 = hand.link_lengths
        self._grid_reach = (
            l1 * np.cos(q[:, 0]),
            l1 * np.sin(q[:, 0]),
            l2 * np.cos(q[:, 0] + q[:, 1]),
            l2 * np.sin(q[:, 0] + q[:, 1]),
        )
        self._grid_reach_lists = tuple(a.tolist() for a in self._grid_reach)  # (_passive)

    def crossings(
        self, t: float, est: StickEstimate, theta_star: float, keep_past: bool = False
    ) -> list[float]:
        """Future times (<= t + horizon) at which theta(t) = theta* (mod pi)."""
        p = self.params
        t_min = t if keep_past else t + p.arrive_margin
        t_max = t + p.horizon
        if abs(est.omega) < 1e-6:
            if abs(wrap_half_pi(est.theta - theta_star)) < 0.02:
                return [float(x) for x in np.arange(t_min, t_max, 0.01)]  # aligned: any time
            return []
        w = est.omega
        delta = ((theta_star - est.theta) * math.copysign(1.0, w)) % math.pi
        period = math.pi / abs(w)
        out = []
        tau = delta / abs(w)
        while est.t_ref + tau <= t_max:
            if est.t_ref + tau >= t_min:
                out.append(est.t_ref + tau)
            tau += period
        return out

    def spot(
        self, est: StickEstimate, sol: sc.ContactSolution, t_c: float
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(contact point R(theta*) r + c, fingertip centre contact - tip_radius n, n) in the
        world for the contact ``sol`` at t_c, the stick moving as ``est`` predicts."""
        x, y, _ = est.at(t_c)
        c, s = math.cos(sol.theta), math.sin(sol.theta)
        r_x, r_y = sol.r_x, 0.5 * self.stick.width * sol.side
        contact = np.array([x + c * r_x - s * r_y, y + s * r_x + c * r_y])
        n = np.array([s, -c]) if sol.side > 0 else np.array([-s, c])  # eq. 4
        return contact, contact - self.hand.tip_radius * n, n

    def tip_at(
        self, est: StickEstimate, sol: sc.ContactSolution, t_c: float
    ) -> tuple[float, float]:
        """:meth:`spot`'s fingertip centre alone, as floats (the same operations)."""
        x, y, _ = est.at(t_c)
        c, s = math.cos(sol.theta), math.sin(sol.theta)
        r_x, r_y = sol.r_x, 0.5 * self.stick.width * sol.side
        px, py = x + c * r_x - s * r_y, y + s * r_x + c * r_y
        nx, ny = (s, -c) if sol.side > 0 else (-s, c)  # eq. 4
        r = self.hand.tip_radius
        return px - r * nx, py - r * ny

    def reach(
        self,
        index: int,
        t: float,
        est: StickEstimate,
        sol: sc.ContactSolution,
        raw: float | None,
        t_c: float,
        fingers,
        strict: bool,
        shortfall: Shortfall,
        bases=None,
    ) -> ContactPlan | None:
        """The quickest hand configuration that has finger k's tip at the contact spot for
        t_c with every check passed (the plan of collision ``index``), or None."""
        p, hand = self.params, self.hand
        c_c, th_c = Motion(est).pose(t_c)
        contact, tip, n = self.spot(est, sol, t_c)
        motion = Motion(est, t_c, sol.u_after)
        now = self.model.config
        sweep_all = Coverage(motion, t, t_c + p.post_horizon)
        # Every base is tried and the quickest arrival wins (ties: the earlier finger, then the
        # earlier base). A route arrives no sooner than t + the travel time to the contact
        # posture with the idle finger unmoved (``need``: travel times obey the triangle
        # inequality and the idle finger's move only adds), so bases are tried in order of that
        # bound and the search stops once it exceeds the best arrival found.
        best: tuple | None = None  # (arrival, finger rank, base rank, k, cfg, route)
        for rank, k in enumerate(fingers):
            j = 1 - k
            for need, i, cfg in self._postures(k, tip, now, bases):
                if best is not None and t + need > best[0]:
                    break  # no later base can arrive sooner
                if (
                    t + need > t_c - p.arrive_margin
                    and need + p.arrive_margin - (t_c - t)
                    >= shortfall.t_needed - shortfall.t_available
                ):
                    continue  # too late, and no nearer miss than the shortfall's best
                passive = self._passive(cfg, j, sweep_all, tip)
                if passive is None:
                    continue
                cfg = cfg.with_finger(j, passive)
                need = travel(hand, now, cfg)
                if t + need > t_c - p.arrive_margin:
                    shortfall.note(need + p.arrive_margin, t_c - t)
                    continue
                found = self.find_route(t, now, cfg, k, motion, t_c, tip, c_c)
                if found is None:
                    continue
                route, cost = found
                if best is None or (cost, rank, i) < best[:3]:
                    best = (cost, rank, i, k, cfg, route)
            if best is not None and strict:
                break
        if best is None:
            return None
        _, _, _, k, cfg, route = best
        return ContactPlan(
            index,
            k,
            t_c,
            th_c,
            sol,
            raw,
            contact,
            tip,
            cfg,
            route,
            self._exit_after(cfg, k, motion, t_c, tip, n),
        )

    def _postures(self, k: int, tip, now: Config, bases) -> list[tuple[float, int, Config]]:
        """(travel time, base rank, configuration) of each base (``bases``, else the candidates
        near ``tip``) from which finger k's tip reaches ``tip``, the idle finger unmoved; the
        quickest first (ties: the earlier base)."""
        hand = self.hand
        if bases is None:
            bases = base_candidates(hand, k, tip, tuple(self.model.target.base))
        cands = []
        for i, base in enumerate(bases):
            q = hand2d.finger_ik(hand, base, k, tip, q_near=now.joints[k])
            if q is None:
                continue
            cfg = Config(tuple(base), now.joints).with_finger(k, q)
            cands.append((travel(hand, now, cfg), i, cfg))
        cands.sort(key=lambda c: (c[0], c[1]))
        return cands

    def find_route(
        self, t: float, now: Config, cfg: Config, k: int, motion: Motion, t_c: float, tip, c_c
    ) -> tuple[list, float] | None:
        """Waypoints [(t_start, Config)] that bring the hand from ``now`` to ``cfg`` (finger k's
        tip at the spot) before t_c with no fingertip hit by the predicted sweep on the way,
        and the arrival time. Tried in order: straight there; via a staging point outside a
        spinning stick's reach, moving in after its last pass over the spot; each of these after
        first pulling any fingertip out of the stick's reach."""
        p, st, hand = self.params, self.stick, self.hand
        # straight there first: most routes are (the staging point and the pulled-out tips
        # below are made only when it is not clear; a refined plan's route is straight 60 of 91
        # times in stick_3step)
        straight = [(t, cfg)]
        arrival = self.route_clear(t, now, straight, k, motion, t_c)
        if arrival is not None:
            return straight, arrival
        half_l, half_w = 0.5 * st.length, 0.5 * st.width
        t_hit = first_covered(
            motion, t, t_c - CONTACT_GUARD, tip, half_l, half_w, hand.tip_radius - 5e-4, last=True
        )
        heads: list[list] = [[]]
        exit_cfg = self._exit_config(t, now, motion)
        if exit_cfg is not None:
            heads.append([(t, exit_cfg)])
        tails: list[list] = [[]]
        if t_hit is not None:
            t_go = t_hit + GO_DELAY
            u = np.asarray(tip) - c_c
            if np.linalg.norm(u) > 1e-9:
                stage = c_c + u / np.linalg.norm(u) * (half_l + hand.tip_radius + p.stage_margin)
                q_s = hand2d.finger_ik(hand, cfg.base, k, stage, q_near=cfg.joints[k])
                if q_s is not None:
                    tails.append([(None, cfg.with_finger(k, q_s)), (t_go, cfg)])
        for head in heads:
            for tail in tails:
                if not head and not tail:
                    continue  # (the straight route, tried above)
                route = list(head)
                t_free = t if not head else t + travel(hand, now, head[-1][1])
                for t_start, c in tail or [(None, cfg)]:
                    route.append((t_free if t_start is None else t_start, c))
                if not route or route[0][0] > t:
                    route.insert(0, (t, now))
                arrival = self.route_clear(t, now, route, k, motion, t_c)
                if arrival is not None:
                    return route, arrival
        return None

    def route_clear(
        self,
        t: float,
        now: Config,
        route: list,
        k: int,
        motion: Motion,
        t_c: float,
        check_idle: bool = True,
        tip_clear: float | None = None,
    ) -> float | None:
        """The arrival time of ``route`` if every segment finishes before the next starts, the
        last before t_c - arrive_margin, and no fingertip is hit by the predicted sweep: on the
        way (both tips) and, once arrived, finger k's tip until just before t_c and the idle
        tip (``sweep_margin`` clear) until t_c + post_horizon. Else None. Finger k's tip counts
        as hit within ``tip_clear`` of the stick (default tip_radius - 0.5 mm: a tip whose
        route ends at a contact may graze the stick just before it). The answer of the
        array oracle (tests/replay/control/stick/oracles.py): the samples while the hand moves
        in whole arrays, those after it stands still (on its last waypoint) as fixed points
        (``coverage.covered_fixed``: only the samples near the stick made)."""
        p, st, hand = self.params, self.stick, self.hand
        timed = self._route_timing(now, route, t_c)
        if timed is None:
            return None
        arrival, starts, frm, to = timed
        t1 = t_c + (p.post_horizon if check_idle else 0.0)
        n = sample_count(t, t1)
        # the samples before CONTACT_GUARD before t_c (finger k's check), before arrival, and
        # up to the first one after arrival that the hand stands still at (m2)
        a = count_before(t, t1, t_c - CONTACT_GUARD, inclusive=True)
        m = count_before(t, t1, arrival, inclusive=False)
        m2 = min(n, m + 1)
        times = sample_times_at(t, t1, 0, m2)
        q = route_axes(hand, starts, frm, to, times)
        if m2 < n and not _still_after(hand, starts[-1], frm[-1], to[-1], times[-1], q[-1]):
            m2 = n  # (rounding: not quite on the target yet) every sample in arrays
            times = sample_times_at(t, t1, 0, n)
            q = route_axes(hand, starts, frm, to, times)
        x, y, th = motion.poses_before_switch(times)
        half_l, half_w = 0.5 * st.length, 0.5 * st.width
        tip_r = hand.tip_radius - 5e-4 if tip_clear is None else tip_clear
        j = 1 - k
        ak = min(a, m2)
        tx, ty = finger_tips(hand, q[:ak], k)
        if covered_samples(x[:ak], y[:ak], th[:ak], tx, ty, half_l, half_w, tip_r).size:
            return None
        # (a > m2: ak = m2, and the arrays' last tip is where the hand stands from then on)
        if (
            a > m2
            and covered_fixed(motion, t, t1, m2, a, (tx[-1], ty[-1]), half_l, half_w, tip_r)
            is not None
        ):
            return None
        if check_idle:
            tx, ty = finger_tips(hand, q, j)
            on_way = self._idle_clearance(t, (tx[0], ty[0]), motion)
            far = hand.tip_radius + p.sweep_margin
            for lo, hi, grow in ((0, min(m, m2), on_way), (min(m, m2), m2, far)):
                if (
                    hi > lo
                    and covered_samples(
                        x[lo:hi], y[lo:hi], th[lo:hi], tx[lo:hi], ty[lo:hi], half_l, half_w, grow
                    ).size
                ):
                    return None
            if (
                m2 < n
                and covered_fixed(motion, t, t1, m2, n, (tx[-1], ty[-1]), half_l, half_w, far)
                is not None
            ):
                return None
        return arrival

    def _route_timing(self, now: Config, route: list, t_c: float) -> tuple | None:
        """(arrival, starts, froms, tos) of ``route`` when each segment finishes before the next
        starts and the last before t_c - arrive_margin, else None."""
        hand = self.hand
        starts, frm, to = [], [], []
        prev = now
        for i, (t_start, cfg) in enumerate(route):
            if i + 1 < len(route):
                if t_start + travel(hand, prev, cfg) > route[i + 1][0] + 1e-9:
                    return None
            starts.append(t_start)
            frm.append(prev)
            to.append(cfg)
            prev = cfg
        arrival = starts[-1] + travel(hand, frm[-1], to[-1])
        if arrival > t_c - self.params.arrive_margin:
            return None
        return arrival, starts, frm, to

    def _idle_clearance(self, t: float, tip, motion: Motion) -> float:
        """The grow of the idle tip's check on the way: at least the clearance it has at t
        (it may start at the stick it just hit: a route grazing the stick at speed is a hit),
        at most tip_radius + sweep_margin."""
        p, st, hand = self.params, self.stick, self.hand
        x0, y0, th0 = motion.pose_floats(t)
        dx, dy = float(tip[0]) - x0, float(tip[1]) - y0
        cs, sn = math.cos(th0), math.sin(th0)
        xb, yb = dx * cs + dy * sn, -dx * sn + dy * cs
        gap = max(abs(xb) - 0.5 * st.length, abs(yb) - 0.5 * st.width) - 1e-4
        return max(hand.tip_radius - 5e-4, min(hand.tip_radius + p.sweep_margin, gap))

    def _exit_after(self, cfg: Config, k: int, motion: Motion, t_c: float, tip, n) -> Config | None:
        """Finger k's tip backed away along -n (the way it came, away from the face the contact
        pushes off) out of the stick's reach just after the contact when
        the predicted motion after it (J_i u, eq. 22: e.g. a stick left spinning in place)
        would sweep over the tip within half a turn (or ``post_horizon``); the stick may be out of the camera's
        view then, so this cannot wait for the next estimate. None when not needed or not
        reachable (base kept)."""
        p, st, hand = self.params, self.stick, self.hand
        w = abs(motion.u_after[2])
        span = max(p.post_horizon, min(p.horizon, math.pi / w + 0.02 if w > 1e-6 else 0.0))
        # up to half a turn
        t0, t1 = t_c + 2.0 * GO_DELAY, t_c + span
        if (
            first_covered(motion, t0, t1, tip, 0.5 * st.length, 0.5 * st.width, hand.tip_radius)
            is None
        ):
            return None
        c, _ = motion.pose(t_c)
        d = np.asarray(tip) - c
        r_out = 0.5 * st.length + hand.tip_radius + p.stage_margin
        dn = float(np.dot(d, n))
        # |d - s n| = r_out, s > 0
        s = dn + math.sqrt(max(dn * dn + r_out * r_out - float(np.dot(d, d)), 0.0))
        q = hand2d.finger_ik(
            hand, cfg.base, k, np.asarray(tip) - s * np.asarray(n), q_near=cfg.joints[k]
        )
        return None if q is None else cfg.with_finger(k, q)

    def _exit_config(self, t: float, now: Config, motion: Motion) -> Config | None:
        """``now`` with every fingertip within the stick's reach moved radially out of it
        (base kept), or None when no tip is inside or a tip cannot get out. In floats: the
        operations of the array version (tests/replay/control/stick/oracles.py; a 2-vector's
        norm is sqrt(x x + y y), as NumPy's dot sums it here: test_stick_fast_paths.py)."""
        p, st, hand = self.params, self.stick, self.hand
        cx, cy, _ = motion.pose_floats(t)
        r_in = 0.5 * st.length + hand.tip_radius + p.sweep_margin
        r_out = 0.5 * st.length + hand.tip_radius + p.stage_margin
        cfg, moved = now, False
        for k in (0, 1):
            tx, ty = hand2d.finger_tip_xy(hand, now.base, k, now.joints[k])
            dx, dy = tx - cx, ty - cy
            dist = math.sqrt(dx * dx + dy * dy)
            if dist >= r_in or dist < 1e-9:
                continue
            out = (cx + dx / dist * r_out, cy + dy / dist * r_out)
            q = hand2d.finger_ik(hand, now.base, k, out, q_near=now.joints[k])
            if q is None:
                return None
            cfg, moved = cfg.with_finger(k, q), True
        return cfg if moved else None

    def _passive(self, cfg: Config, j: int, sweep: Coverage, active_tip):
        """The idle finger's joints nearest its current ones whose tip stays clear of the
        predicted sweep (and of the active tip); None when no posture is clear. Postures are
        checked nearest first (ties: current, then grid order), the first clear one wins; a
        posture's tip is worked out only when its turn comes (the floats of the array
        formulation, tests/replay/control/stick/oracles.py)."""
        hand, st, p = self.hand, self.stick, self.params
        cur = cfg.joints[j]
        ax, ay = float(active_tip[0]), float(active_tip[1])
        near = 2.0 * hand.tip_radius + p.sweep_margin
        half_l, half_w, grow = 0.5 * st.length, 0.5 * st.width, hand.tip_radius + p.sweep_margin

        def clear(tx: float, ty: float) -> bool:
            dx, dy = tx - ax, ty - ay
            return math.sqrt(dx * dx + dy * dy) > near and not sweep.hits(
                (tx, ty), half_l, half_w, grow
            )

        # the current posture (distance 0, first of the ties) comes first whatever the grid's
        # distances: the grid is sorted only when it is not clear (60 of stick_3step's 91 calls
        # keep it)
        if clear(*hand2d.finger_tip_xy(hand, cfg.base, j, cur)):
            return tuple(cur)
        c0, c1 = cur
        grid = self._passive_grid
        dist = [max(abs(q1 - c0), abs(q2 - c1)) for q1, q2 in grid]
        g0, g1, g2, g3 = self._grid_reach_lists
        rx, ry = cfg.base[0] + hand.root_offsets[j][0], cfg.base[1] + hand.root_offsets[j][1]
        for i in sorted(range(len(dist)), key=dist.__getitem__):  # (stable: ties in order)
            if clear((rx + g0[i]) + g2[i], (ry + g1[i]) + g3[i]):
                return grid[i]
        return None
