"""Planning the closing of a stick capture: the two fingertips close on the translating stick.

Higashimori et al. 2007, Sec. III-B Step 2 and III-C Step 3 (eqs. 32, 33, 38): once the stick
translates perpendicular to its axis, the fingertips close along the line through the centre of
mass along v; a contact there (r_x = 0, normal through the centre of mass) leaves no spin, so
the translation can be removed by simply closing the gap (``collision.closing_contact``
gives the contact's predicted outcome).

The finger that made the last collision is behind the stick; the other waits on that line,
ahead of the stick, at the point the stick reaches first that the hand can get to in time
(going around an end of the stick when it starts behind it, :meth:`ClosePlanner.around`). The
rear fingertip waits behind the stick while the slider moves (finger joints cannot hold a tip
still against a moving slider), then follows the stick along the line (``follow_gap`` behind)
to the final gap W + 2 tip_radius + grip_clearance (:meth:`ClosePlanner.command`). The front
tip's route keeps a full tip radius clear of the predicted stick until just before the meeting
(a collision's route may graze it by 0.5 mm: its tip ends at a contact; a front tip touching the
stick early pushes it into the rear tip). Whatever spin is left is ignored by the closing plan
(the fingers then squeeze a turning stick: not friction independent). The waiting front tip is moved onto the refined line of motion while the stick
has touched nothing (:meth:`ClosePlanner.refine`).

The result is a :class:`ClosePlan` (the closing phase's plan; its ``intent`` is the ``plan``
event's data). Routes are checked with the contact planner's
:meth:`~replay.control.stick.plan.ContactPlanner.route_clear`.

Pure NumPy.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from replay.robot import hand2d
from replay.control.stick import collision as sc
from replay.control.stick.estimator import StickEstimate, StickEstimator
from replay.control.stick.hand_model import Config, close_bases, route_target, travel
from replay.control.stick.plan import CONTACT_GUARD, ContactPlanner, Shortfall
from replay.control.stick.coverage import Motion


@dataclass
class ClosePlan:
    index: int
    front: int
    rear: int
    t_meet: float
    d: np.ndarray  # unit direction of motion along the closing line
    meet: np.ndarray  # stick centre at the meeting (m)
    half_gap: float  # fingertip centre to the stick centre at the end (m)
    config: Config  # base and front finger; rear finger updated while following
    sol: sc.ContactSolution | None
    theta: float
    n_breaks: int = 0  # the estimator's break count when planned
    route: list = field(default_factory=list)  # [(t_start, Config)] for base and front finger

    def target(self, t: float) -> Config:
        return route_target(self.route, t, self.config)

    def intent(self, width: float) -> dict:
        out = {
            "index": self.index,
            "finger": self.front,
            "t": float(self.t_meet),
            "theta": float(self.theta),
            "r_x": 0.0,
            "clamped": False,
            "contact": [float(x) for x in self.meet + self.d * width / 2.0],
            "tip": [float(x) for x in self.meet + self.d * self.half_gap],
        }
        if self.sol is not None:
            k = round((self.theta - self.sol.theta) / math.pi)
            f = 1 if k % 2 == 0 else -1
            out.update(
                {
                    "r_y": f * self.sol.side * width / 2.0,
                    "side": f * self.sol.side,
                    "v_after": [float(self.sol.u_after[0]), float(self.sol.u_after[1])],
                    "omega_after": float(self.sol.u_after[2]),
                }
            )
        return out


class ClosePlanner:
    """The closing for the hand that ``planner`` plans for (its params, hand, stick and hand
    model)."""

    def __init__(self, planner: ContactPlanner) -> None:
        self.planner = planner
        self.params = planner.params
        self.hand = planner.hand
        self.stick = planner.stick
        self.model = planner.model

    def plan(
        self,
        t: float,
        est: StickEstimate,
        last_finger: int | None,
        index: int,
        n_breaks: int,
        shortfall: Shortfall,
    ) -> ClosePlan | None:
        """The closing plan (number ``index``; the estimator has seen ``n_breaks`` breaks), or
        None with the closest miss noted in ``shortfall``. ``last_finger`` made the last
        collision (None: none did). The first meeting time on the stick's path (every 20 ms up
        to ``horizon``; now, for a stick at rest) that some base posture reaches in time wins."""
        p, st, hand = self.params, self.stick, self.hand
        moving, d, front, rear = self._closing_direction(t, est, last_finger)
        h = 0.5 * st.width + hand.tip_radius + 0.5 * p.grip_clearance
        # a spin left by a clamped contact is ignored here: the sweep of a spinning stick covers
        # every spot near the line, so the closing could never be planned (not friction free)
        pre = Motion(dataclasses.replace(est, omega=0.0))
        taus = np.arange(0.02, p.horizon + 1e-9, 0.02) if moving else np.array([0.02])
        for tau in taus:
            t_m = t + float(tau)
            meet = pre.pose(t_m)[0] if moving else np.array(est.at(t)[:2])
            best = self._reach_meeting(t, t_m, meet, d, h, front, rear, pre, moving, shortfall)
            if best is not None:
                sol = (
                    sc.closing_contact(st.mass, st.inertia, st.restitution, est.u, st.length)
                    if moving
                    else None
                )
                return ClosePlan(
                    index,
                    front,
                    rear,
                    t_m,
                    d,
                    meet,
                    h,
                    best[1],
                    sol,
                    pre.pose(t_m)[1],
                    n_breaks,
                    best[2],
                )
        return None

    def _closing_direction(
        self, t: float, est: StickEstimate, last_finger: int | None
    ) -> tuple[bool, np.ndarray, int, int]:
        """(moving, d, front, rear): the direction the fingers close along (the stick's motion,
        or across it at rest) and which finger meets the stick first (``front``) and which
        closes behind it (``rear``: the one that made the last collision)."""
        p, hand = self.params, self.hand
        x, y, th = est.at(t)
        speed = est.speed
        moving = speed >= p.capture_speed
        if moving:
            d = np.array([est.vx, est.vy]) / speed
        else:
            d = np.array([-math.sin(th), math.cos(th)])
        rear = last_finger
        if rear is None:
            proj = [float(np.dot(hand.root_offsets[k], d)) for k in (0, 1)]
            rear = int(np.argmin(proj))
        elif not moving:
            if np.dot(d, np.array([x, y]) - self.model.config.tip(hand, rear)) < 0.0:
                d = -d
        return moving, d, 1 - rear, rear

    def _reach_meeting(self, t, t_m, meet, d, h, front, rear, pre, moving, shortfall):
        """(arrival, configuration, route) of the first base posture whose front tip is at
        ``meet + d h`` and rear tip at ``meet - d h`` by ``t_m`` along a clear route, else
        None."""
        p, hand = self.params, self.hand
        now = self.model.config
        F, Rr = meet + d * h, meet - d * h
        for base in close_bases(hand, F, Rr, front, rear, tuple(self.model.target.base)):
            qf = hand2d.finger_ik(hand, base, front, F, q_near=now.joints[front])
            qr = hand2d.finger_ik(hand, base, rear, Rr, q_near=now.joints[rear])
            if qf is None or qr is None:
                continue
            cfg = Config(tuple(base), now.joints).with_finger(front, qf)
            need = travel(hand, now, cfg)
            if t + need > t_m - p.arrive_margin and moving:
                shortfall.note(need + p.arrive_margin, t_m - t)
                continue
            if not moving:
                return (need, cfg.with_finger(rear, qr), [(t, cfg.with_finger(rear, qr))])
            # while the base moves the rear finger is parked behind the stick (its joints
            # cannot hold the tip still against a moving slider); it follows once the base has
            # arrived
            park = pre.pose(t + need)[0] - d * (h + p.follow_gap)
            qp = hand2d.finger_ik(hand, base, rear, park, q_near=now.joints[rear])
            if qp is None:
                continue
            cfg = cfg.with_finger(rear, qp)
            for route in [[(t, cfg)]] + self.around(t, now, cfg, front, F, pre):
                # the front tip waits ahead of the stick: a touch before the meeting pushes
                # the stick into the rear tip, so its route keeps a full tip radius clear
                arrival = self.planner.route_clear(
                    t, now, route, front, pre, t_m, tip_clear=hand.tip_radius
                )
                if arrival is not None:
                    return (arrival, cfg, route)
        return None

    def around(self, t: float, now: Config, cfg: Config, k: int, target, motion: Motion) -> list:
        """Routes taking finger k's tip around an end of a translating stick to ``target``:
        sideways beyond the end, along the stick's motion, then in (base already at cfg's)."""
        p, st, hand = self.params, self.stick, self.hand
        c, th = motion.pose(t)
        s_hat = np.array([math.cos(th), math.sin(th)])
        n_hat = np.array([-s_hat[1], s_hat[0]])
        w = 0.5 * st.length + hand.tip_radius + p.stage_margin
        tip = now.tip(hand, k)
        routes = []
        for sgn in (1.0, -1.0):
            a1 = c + sgn * w * s_hat + n_hat * float(np.dot(tip - c, n_hat))
            a2 = np.asarray(target) + s_hat * (
                sgn * w - float(np.dot(np.asarray(target) - c, s_hat))
            )
            q2 = hand2d.finger_ik(hand, cfg.base, k, a2, q_near=cfg.joints[k])
            if q2 is None:
                continue
            c2 = cfg.with_finger(k, q2)
            for base1 in (cfg.base, now.base):  # sideways first, the base moving or not
                q1 = hand2d.finger_ik(hand, base1, k, a1, q_near=now.joints[k])
                if q1 is not None:
                    break
            if q1 is None:
                continue
            c1 = (
                cfg if tuple(base1) == tuple(cfg.base) else Config(tuple(base1), now.joints)
            ).with_finger(k, q1)
            t1 = t + travel(hand, now, c1)
            t2 = t1 + travel(hand, c1, c2)
            routes.append([(t, c1), (t1, c2), (t2, cfg)])
        return routes

    def refine(self, t: float, est: StickEstimate, c: ClosePlan, n_breaks: int) -> None:
        """Move the waiting front tip of ``c`` onto the refined line of motion (same base and
        meeting time) while the stick has not touched anything since the closing was planned
        (the estimator's break count is still ``n_breaks``)."""
        p = self.params
        if (
            n_breaks != c.n_breaks
            or est.speed < p.capture_speed
            or (c.route and t < c.route[-1][0])
        ):  # still going around the stick
            return
        d = np.array([est.vx, est.vy]) / est.speed
        if float(np.dot(d, c.d)) < 0.9:
            return
        meet = Motion(est).pose(c.t_meet)[0]
        q = hand2d.finger_ik(
            self.hand,
            c.config.base,
            c.front,
            meet + d * c.half_gap,
            q_near=c.config.joints[c.front],
        )
        if q is None:
            return
        cfg = c.config.with_finger(c.front, q)
        if t + travel(self.hand, self.model.config, cfg) > c.t_meet - CONTACT_GUARD:
            return
        c.d, c.meet, c.config = d, meet, cfg
        c.route = c.route[:-1] + [(c.route[-1][0] if c.route else t, cfg)]
        c.theta = Motion(est).pose(c.t_meet)[1]
        if c.sol is not None:
            st = self.stick
            c.sol = (
                sc.closing_contact(st.mass, st.inertia, st.restitution, est.u, st.length) or c.sol
            )

    def command(self, t: float, c: ClosePlan, estimator: StickEstimator) -> Config:
        """The hand target at ``t`` for the closing ``c``: its route's waypoint, with the rear
        fingertip following the stick along the line once the base has arrived."""
        cfg = c.target(t)
        (bx, by), (cx, cy) = self.model.config.base, c.config.base
        if max(abs(bx - cx), abs(by - cy)) > 1e-9:
            return cfg  # the base is still moving: the rear finger is parked
        px, py, _ = estimator.predict(t)
        # in floats: the operations of the 2-vectors' (c.meet + c.d * s_rear), without them
        (dx, dy), (mx, my) = c.d.tolist(), c.meet.tolist()
        s_now = dx * (px - mx) + dy * (py - my)
        s_rear = (
            -c.half_gap
            if t >= c.t_meet
            else min(-c.half_gap, s_now - c.half_gap - self.params.follow_gap)
        )
        point = (mx + dx * s_rear, my + dy * s_rear)
        q = hand2d.finger_ik(
            self.hand, cfg.base, c.rear, point, q_near=self.model.target.joints[c.rear]
        )
        if q is None:
            return cfg.with_finger(c.rear, self.model.target.joints[c.rear])
        return cfg.with_finger(c.rear, q)
