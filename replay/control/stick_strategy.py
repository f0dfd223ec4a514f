"""The 2-step and 3-step capturing strategies (Higashimori et al. 2007, Sec. III) as controllers.

Pure NumPy. The controller sees only ``/vision/stick`` measurements (x, y, theta mod pi; already
delayed by the camera latency) and the :class:`~replay.hand2d.AirTableSpec` (hand kinematics and
the stick's m, I, L, W, e; never the friction mu). It has no hand feedback: it tracks its own
commands with a model that moves every axis toward its target at the spec's speed limit, starting
from where the spec says the hand was homed (``HandSpec.start_base`` / ``start_joints``).

Cycle of one planned collision i:

1. Observe until the :class:`~replay.control.stick_estimator.StickEstimator` is ready.
2. Solve the contact (r_x, side) from the estimated u_{i-1} (stick_collision: eqs. 25, 28, 26 and
   the side rules 31, 35, 37), at the target orientation theta* (alpha(v_{i-1}), eq. 23, or
   alpha(lambda_2) for the 3-step second collision).
3. Walk the future times at which the predicted orientation equals theta* modulo pi, earliest
   first, up to ``horizon``; at each, put the fingertip centre at contact - tip_radius n, find a
   base position and finger joints (``hand2d.finger_ik``) reachable in time (``hand2d.travel_time``
   plus ``arrive_margin``) for which the stick's predicted sweep does not hit the waiting tip
   before the contact, and an idle-finger posture clear of the sweep before and
   ``post_horizon`` after the contact (the J-predicted motion). A tip inside the sweep of a
   spinning stick waits outside it (``stage_margin``) and moves in just after the stick's last
   pass; a fingertip inside the stick's reach is first pulled out of it. Every route is checked
   against the predicted sweep along the hand's own motion (each axis at its speed limit, as
   the plant moves). The first crossing that works is the plan; it is refined with every new
   estimate until ``freeze`` before the contact.
4. A model break of the estimator within ``detect_window`` of the planned time is the planned
   collision; the plan for the next step is then made from fresh estimates. A break much earlier,
   or none by ``detect_window`` after the plan, is reported (``missed``) and the step re-planned.

Closing (eqs. 32, 33, 38): once the stick translates, the finger that made the last collision is
behind it; the other waits on the line through the centre of mass along v, ahead of the stick, at
the point the stick reaches first that the hand can get to in time (going around an end of the
stick when it starts behind it); the rear fingertip waits behind the stick while the slider
moves (finger joints cannot hold a tip still against a moving slider), then follows the stick
along that line (``follow_gap`` behind) to the final gap W + 2 tip_radius + grip_clearance.
Whatever spin is left is ignored by the closing plan (the fingers then squeeze a turning stick:
not friction independent).
A ``capture`` event is emitted once the estimated speed stays below ``capture_speed`` and spin
below ``capture_spin`` for ``capture_hold`` with both modelled fingertips at the stick's two faces.

Infeasibility and fallbacks (each reported once per step as an ``infeasible`` event; the
``r_x_beyond_stick`` one with the plan's final numbers, when it freezes or the collision happens):

- ``r_x_beyond_stick``: the solved |r_x| exceeds L/2 (e.g. the 3-step second collision with the
  paper's m, I, e needs sqrt(I / (m e)) = 86.5 mm > 50 mm). Fallback: clamp |r_x| to
  L/2 - ``tip_margin`` on the same side and predict the outcome with J_i (eq. 22); for a purely
  rotating stick this leaves omega_2 / omega_1 = (I - e m r^2) / (I + m r^2), the least spin any
  contact on the stick can leave. The next step proceeds from the measured result; when the
  strategy's last contact was clamped and J predicts |omega| >= ``min_spin``, up to ``max_extra``
  spin-stop collisions (the 2-step first collision, eq. 30, on the current u) are added before
  the closing.
- ``unreachable``: an orientation crossing passed without a plan that reaches it in time (data:
  t_contact, and the best t_needed vs t_available of the last attempt; t_needed null when no hand
  configuration reaches the spot or keeps clear of the stick at all); for the closing, after
  ``close_retry`` of failed attempts. Fallback: keep the hand where it is and try again every
  ``retry_interval`` (later crossings enter the horizon; one beyond it is simply waited for).
- ``no_solution`` / ``no_crossing``: no root of eq. 25 / 28 passes eq. 26, or the stick does not
  spin while not perpendicular to its motion (theta never reaches alpha(v)). Fallback: go to the
  closing step with the stick as it moves (not friction independent).

A step whose job is to stop the spin is skipped when |omega| < ``min_spin`` already (``skip``).

Events (``pop_events``): ``plan`` (a contact is committed; data = the intent), ``infeasible``,
``missed`` (the model broke well before the planned time, or not by ``detect_window`` after it),
``skip``, ``capture``. ``intent()``: index, finger, t, theta, r_x, r_y, side, v_after,
omega_after, contact and tip (world, m), clamped, r_x_solved. theta is the estimator's continuous
orientation (it starts from the camera's first reading in (-pi/2, pi/2]); r_x, r_y and side are
in that body frame (the solution's frame theta* = alpha(.) may differ from it by pi).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from replay import hand2d
from replay.hand2d import AirTableSpec, HandCommand, HandSpec
from replay.interfaces import Controller, Occurrence
from replay.params import param
from replay.control import stick_collision as sc
from replay.control.stick_estimator import StickEstimate, StickEstimator

TOPIC_VISION = "/vision/stick"
TOPIC_ESTIMATE = "/control/stick_estimate"
SAMPLE_DT = 0.001      # s, time step of the predicted-sweep checks
CONTACT_GUARD = 0.003  # s, the sweep check of the waiting tip stops this long before the contact
GO_DELAY = 0.003       # s, a staged tip moves in this long after the stick's last pass


# ------------------------------------------------------------------------------------------
# Parameters
# ------------------------------------------------------------------------------------------


@dataclass
class StickCaptureParams:
    window: int = param(30, unit="1", ge=2, le=1000,
                        doc="samples in the sliding least-squares window (0.1 s at 300 fps)")
    min_samples: int = param(6, unit="1", ge=2, le=1000,
                             doc="samples since the last collision before the estimate is used")
    pos_tol: float = param(0.002, unit="m", gt=0.0, le=0.1,
                           doc="position deviation from the prediction that breaks the model")
    theta_tol: float = param(0.03, unit="rad", gt=0.0, le=1.0,
                             doc="orientation deviation from the prediction that breaks the model")
    confirm: int = param(2, unit="1", ge=1, le=5,
                         doc="consecutive deviating samples that confirm a collision")
    horizon: float = param(1.0, unit="s", gt=0.0, le=10.0,
                           doc="how far ahead a contact is searched")
    arrive_margin: float = param(0.01, unit="s", ge=0.0, le=0.5,
                                 doc="the fingertip must be at the spot this long before contact")
    freeze: float = param(0.01, unit="s", ge=0.0, le=0.5,
                          doc="the target is no longer refined this long before the contact")
    detect_window: float = param(0.04, unit="s", gt=0.0, le=1.0,
                                 doc="a model break this close to the planned time is the plan's")
    min_spin: float = param(0.2, unit="rad/s", ge=0.0, le=100.0,
                            doc="below this |omega| a spin-stopping step is skipped")
    max_extra: int = param(2, unit="1", ge=0, le=10,
                           doc="spin-stop collisions (eq. 30) added when a clamped contact left "
                               "|omega| >= min_spin, before closing")
    tip_margin: float = param(0.005, unit="m", ge=0.0, le=0.05,
                              doc="fallback: |r_x| is clamped to L/2 - tip_margin")
    sweep_margin: float = param(0.003, unit="m", ge=0.0, le=0.05,
                                doc="clearance between an idle fingertip and the predicted sweep")
    stage_margin: float = param(0.01, unit="m", ge=0.0, le=0.2,
                                doc="a staged tip waits this far outside a spinning stick's reach")
    post_horizon: float = param(0.1, unit="s", ge=0.0, le=2.0,
                                doc="after a contact the idle finger stays clear this long")
    grip_clearance: float = param(0.002, unit="m", ge=0.0, le=0.05,
                                  doc="final fingertip gap = W + 2 tip_radius + grip_clearance")
    follow_gap: float = param(0.01, unit="m", ge=0.0, le=0.1,
                              doc="the rear fingertip follows this far behind the stick")
    retry_interval: float = param(0.02, unit="s", ge=0.0, le=1.0,
                                  doc="after a failed plan, wait this long before trying again")
    close_retry: float = param(0.3, unit="s", gt=0.0, le=5.0,
                               doc="the closing is re-planned when no capture this long after "
                                   "the planned meeting")
    capture_speed: float = param(0.02, unit="m/s", gt=0.0, le=1.0,
                                 doc="capture: estimated speed below this")
    capture_spin: float = param(0.5, unit="rad/s", gt=0.0, le=50.0,
                                doc="capture: estimated |omega| below this")
    capture_hold: float = param(0.05, unit="s", ge=0.0, le=5.0,
                                doc="capture: conditions held this long")


@dataclass
class TwoStepParams(StickCaptureParams):
    pass


@dataclass
class ThreeStepParams(StickCaptureParams):
    lambda_2: list = param([1.0, 0.0], unit="1", length=2, ge=-1.0, le=1.0,
                           doc="selection vector lambda_2 of eq. 36: the direction of v_2 "
                               "(default: along world x, the stick perpendicular to the palm)")
    lambda_2_auto_sign: bool = param(True, unit="1", choices=(True, False),
                                     doc="use -lambda_2 when that sends the stick toward the "
                                         "centre of the base range (tried first; the other "
                                         "sign only if it cannot be reached)")


# ------------------------------------------------------------------------------------------
# Hand configurations and the open-loop hand model
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Config:
    base: tuple           # (x, y) m
    joints: tuple         # ((q1, q2), (q1, q2)) rad

    def with_finger(self, k: int, q) -> "Config":
        j = [tuple(self.joints[0]), tuple(self.joints[1])]
        j[k] = (float(q[0]), float(q[1]))
        return Config(self.base, tuple(j))

    def tip(self, hand: HandSpec, k: int) -> np.ndarray:
        return hand2d.finger_tip(hand, self.base, k, self.joints[k])

    def command(self) -> HandCommand:
        return HandCommand(base=(float(self.base[0]), float(self.base[1])),
                           joints=tuple((float(q[0]), float(q[1])) for q in self.joints))


def travel(hand: HandSpec, a: Config, b: Config) -> float:
    return hand2d.travel_time(hand, a.base, b.base, a.joints, b.joints)


class HandModel:
    """Where the hand is, assuming each axis moves to its target at its speed limit."""

    def __init__(self, hand: HandSpec, start: Config) -> None:
        self.hand = hand
        self.config = start
        self.target = start
        self._t: float | None = None

    def advance(self, t: float) -> None:
        if self._t is not None and t > self._t:
            dt = t - self._t
            step_b = self.hand.base_speed * dt
            step_q = self.hand.joint_speed * dt
            base = tuple(a + min(step_b, max(-step_b, b - a))
                         for a, b in zip(self.config.base, self.target.base))
            joints = tuple(tuple(a + min(step_q, max(-step_q, b - a)) for a, b in zip(qa, qb))
                           for qa, qb in zip(self.config.joints, self.target.joints))
            self.config = Config(base, joints)
        self._t = t


# ------------------------------------------------------------------------------------------
# Predicted stick motion and its sweep
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Motion:
    """Constant velocities from ``est``; from ``t_switch`` on, ``u_after`` (a planned contact)."""
    est: StickEstimate
    t_switch: float = math.inf
    u_after: tuple = (0.0, 0.0, 0.0)

    def poses(self, times) -> tuple[np.ndarray, np.ndarray]:
        t = np.asarray(times, dtype=float)
        e = self.est
        t1 = np.minimum(t, self.t_switch) - e.t_ref
        c = np.column_stack([e.x + e.vx * t1, e.y + e.vy * t1])
        th = e.theta + e.omega * t1
        if math.isfinite(self.t_switch):
            t2 = np.maximum(t - self.t_switch, 0.0)
            c = c + np.column_stack([self.u_after[0] * t2, self.u_after[1] * t2])
            th = th + self.u_after[2] * t2
        return c, th

    def pose(self, t: float) -> tuple[np.ndarray, float]:
        c, th = self.poses([t])
        return c[0], float(th[0])


def _body(motion: Motion, times, points) -> tuple[np.ndarray, np.ndarray]:
    """Stick-frame coordinates (xb, yb), each (T, K), of fixed points (K, 2)."""
    c, th = motion.poses(times)
    cs, sn = np.cos(th), np.sin(th)
    d = np.asarray(points, dtype=float)[None, :, :] - c[:, None, :]
    return d[..., 0] * cs[:, None] + d[..., 1] * sn[:, None], \
        -d[..., 0] * sn[:, None] + d[..., 1] * cs[:, None]


def covered(motion: Motion, times, points, half_length: float, half_width: float,
            grow) -> np.ndarray:
    """(len(times), len(points)) booleans: point within ``grow`` of the stick rectangle."""
    xb, yb = _body(motion, times, np.asarray(points, dtype=float).reshape(-1, 2))
    return (np.abs(xb) <= half_length + grow) & (np.abs(yb) <= half_width + grow)


def covered_along(motion: Motion, times, points, half_length: float, half_width: float,
                  grow) -> np.ndarray:
    """(T,) booleans: points[i] (a moving point, (T, 2)) within ``grow`` of the stick at
    times[i]; ``grow`` a scalar or (T,)."""
    c, th = motion.poses(times)
    d = np.asarray(points, dtype=float) - c
    cs, sn = np.cos(th), np.sin(th)
    xb = d[:, 0] * cs + d[:, 1] * sn
    yb = -d[:, 0] * sn + d[:, 1] * cs
    return (np.abs(xb) <= half_length + grow) & (np.abs(yb) <= half_width + grow)


def _times(t0: float, t1: float) -> np.ndarray:
    if t1 <= t0:
        return np.array([t0])
    return np.linspace(t0, t1, max(2, int(math.ceil((t1 - t0) / SAMPLE_DT)) + 1))


def _route_configs(hand: HandSpec, starts, frm, to, times):
    """Base (T, 2) and joints (T, 2, 2) along waypoint segments, each axis moving toward its
    target at its speed limit (the plant's motion model)."""
    times = np.asarray(times, dtype=float)
    base = np.empty((len(times), 2))
    joints = np.empty((len(times), 2, 2))
    for i, (s0, a, b) in enumerate(zip(starts, frm, to)):
        t_end = starts[i + 1] if i + 1 < len(starts) else math.inf
        sel = (times >= s0) | (i == 0)
        sel &= times < t_end
        if not sel.any():
            continue
        tau = np.maximum(times[sel] - s0, 0.0)[:, None]
        a_b, b_b = np.array(a.base), np.array(b.base)
        base[sel] = a_b + np.clip(b_b - a_b, -hand.base_speed * tau, hand.base_speed * tau)
        a_q, b_q = np.array(a.joints).reshape(4), np.array(b.joints).reshape(4)
        q = a_q + np.clip(b_q - a_q, -hand.joint_speed * tau, hand.joint_speed * tau)
        joints[sel] = q.reshape(-1, 2, 2)
    return base, joints


def _tips(hand: HandSpec, base, joints) -> np.ndarray:
    """Fingertip centres (T, 2 fingers, 2) for bases (T, 2) and joints (T, 2, 2)."""
    l1, l2 = hand.link_lengths
    roots = np.array(hand.root_offsets)[None, :, :] + np.asarray(base)[:, None, :]
    q1, q12 = joints[..., 0], joints[..., 0] + joints[..., 1]
    return roots + np.stack([l1 * np.cos(q1) + l2 * np.cos(q12),
                             l1 * np.sin(q1) + l2 * np.sin(q12)], axis=-1)


def _route_target(route: list, t: float, default: Config) -> Config:
    """The waypoint of [(t_start, Config)] to command at time ``t``."""
    out = route[0][1] if route else default
    for t_start, cfg in route:
        if t >= t_start:
            out = cfg
    return out


def _finite_or_none(v) -> float | None:
    """Event data must be JSON without NaN/inf (the log contract): non-finite -> None."""
    v = float(v)
    return v if math.isfinite(v) else None


def wrap_half_pi(a: float) -> float:
    """a modulo pi, in (-pi/2, pi/2] (the camera's convention for theta)."""
    r = (a + math.pi / 2.0) % math.pi - math.pi / 2.0
    return math.pi / 2.0 if r <= -math.pi / 2.0 + 1e-15 else r


# ------------------------------------------------------------------------------------------
# Plans
# ------------------------------------------------------------------------------------------


@dataclass
class ContactPlan:
    index: int               # collision number i
    finger: int
    t: float                 # planned contact time (s)
    theta: float             # continuous orientation at the contact (estimator's frame)
    sol: sc.ContactSolution  # in the frame theta* = sol.theta (mod pi)
    raw_r_x: float | None    # the solved r_x when it was beyond the stick (sol is clamped)
    contact: np.ndarray      # world contact point (m)
    tip: np.ndarray          # world fingertip centre (m)
    config: Config           # the hand at the contact
    route: list = field(default_factory=list)   # [(t_start, Config)], the last one = config

    @property
    def clamped(self) -> bool:
        return self.raw_r_x is not None

    def target(self, t: float) -> Config:
        """The waypoint to command at time ``t``."""
        return _route_target(self.route, t, self.config)

    def frame_flip(self) -> int:
        """+1 if the estimator's frame at the contact equals theta*'s, -1 if it differs by pi."""
        k = round((self.theta - self.sol.theta) / math.pi)
        return 1 if k % 2 == 0 else -1

    def intent(self, width: float) -> dict:
        f = self.frame_flip()
        return {"index": self.index, "finger": self.finger, "t": float(self.t),
                "theta": float(self.theta), "r_x": f * self.sol.r_x,
                "r_y": f * self.sol.side * width / 2.0, "side": f * self.sol.side,
                "v_after": [float(self.sol.u_after[0]), float(self.sol.u_after[1])],
                "omega_after": float(self.sol.u_after[2]),
                "contact": [float(x) for x in self.contact], "tip": [float(x) for x in self.tip],
                "clamped": self.clamped, "r_x_solved": f * (self.raw_r_x if self.clamped
                                                             else self.sol.r_x)}


@dataclass
class ClosePlan:
    index: int
    front: int
    rear: int
    t_meet: float
    d: np.ndarray            # unit direction of motion along the closing line
    meet: np.ndarray         # stick centre at the meeting (m)
    half_gap: float          # fingertip centre to the stick centre at the end (m)
    config: Config           # base and front finger; rear finger updated while following
    sol: sc.ContactSolution | None
    theta: float
    n_breaks: int = 0        # the estimator's break count when planned
    route: list = field(default_factory=list)   # [(t_start, Config)] for base and front finger

    def target(self, t: float) -> Config:
        return _route_target(self.route, t, self.config)

    def intent(self, width: float) -> dict:
        out = {"index": self.index, "finger": self.front, "t": float(self.t_meet),
               "theta": float(self.theta), "r_x": 0.0, "clamped": False,
               "contact": [float(x) for x in self.meet + self.d * width / 2.0],
               "tip": [float(x) for x in self.meet + self.d * self.half_gap]}
        if self.sol is not None:
            k = round((self.theta - self.sol.theta) / math.pi)
            f = 1 if k % 2 == 0 else -1
            out.update({"r_y": f * self.sol.side * width / 2.0, "side": f * self.sol.side,
                        "v_after": [float(self.sol.u_after[0]), float(self.sol.u_after[1])],
                        "omega_after": float(self.sol.u_after[2])})
        return out


@dataclass
class _Shortfall:
    t_needed: float = math.inf
    t_available: float = 0.0

    def note(self, needed: float, available: float) -> None:
        if needed - available < self.t_needed - self.t_available:
            self.t_needed, self.t_available = needed, available


# ------------------------------------------------------------------------------------------
# The controller
# ------------------------------------------------------------------------------------------


class StickCaptureController(Controller):
    """Shared machinery; subclasses give the contact of each step (``_options``)."""

    Params: ClassVar[type] = StickCaptureParams
    n_steps: ClassVar[int] = 1

    def __init__(self, params, *, spec: AirTableSpec) -> None:
        super().__init__(params, spec=spec)
        p = params
        self.hand: HandSpec = spec.hand
        self.stick = spec.stick
        self.est = StickEstimator(window=p.window, min_samples=p.min_samples, pos_tol=p.pos_tol,
                                  theta_tol=p.theta_tol, confirm=p.confirm)
        self.model = HandModel(self.hand, self._home())
        self.phase = "observe"
        self.step = 1                       # index of the next collision
        self.plan: ContactPlan | None = None
        self.close: ClosePlan | None = None
        self.last_finger: int | None = None
        self.captured = False
        self._capture_since: float | None = None
        self._events: list[Occurrence] = []
        self._reported: set = set()
        self._passive_grid = self._posture_grid()
        self._next_try = -math.inf          # no new plan attempt before this time
        self.extra = 0                      # spin-stop collisions added so far
        self._lost: tuple | None = None     # (time of a contact chance not yet planned, numbers)

    # -- Controller interface -----------------------------------------------------------------
    def update(self, t: float, measurements) -> HandCommand:
        self.model.advance(t)
        broke = fresh = False
        for topic, m in measurements:
            if topic != TOPIC_VISION or m is None:
                continue
            broke |= self.est.add(m.t, m.x, m.y, m.theta)
            fresh = True
        if broke:
            self._on_break(t)
        if fresh and self.est.ready():
            self._on_estimate(t)
        self._command(t)
        self._check_capture(t)
        return self.model.target.command()

    def intent(self) -> dict:
        if self.plan is not None:
            return self.plan.intent(self.stick.width)
        if self.close is not None:
            return self.close.intent(self.stick.width)
        return {}

    def pop_events(self) -> list[Occurrence]:
        out, self._events = self._events, []
        return out

    def telemetry(self, t: float) -> dict:
        e = self.est.estimate()
        msg = {"t": float(t), "phase": self.phase, "step": self.step,
               "ready": bool(self.est.ready())}
        if e is not None:
            x, y, th = e.at(t)
            msg.update({"t_ref": e.t_ref, "x": x, "y": y, "theta": th, "vx": e.vx, "vy": e.vy,
                        "omega": e.omega, "n": e.n, "rms_xy": e.rms_xy,
                        "rms_theta": e.rms_theta})
        return {TOPIC_ESTIMATE: msg}

    # -- strategy hooks -------------------------------------------------------------------------
    def _options(self, est: StickEstimate, step: int) -> list[sc.ContactSolution]:
        """Contacts for collision ``step``, in order of preference (empty: none)."""
        raise NotImplementedError

    def _spin_stop(self, step: int) -> bool:
        """True when collision ``step`` is meant to remove the spin (omega_i = 0)."""
        raise NotImplementedError

    def _contacts(self, est: StickEstimate, step: int) -> list[sc.ContactSolution]:
        """The strategy's contacts, or an added spin-stop collision (eq. 30) after them."""
        if step <= self.n_steps:
            return self._options(est, step)
        st = self.stick
        sol = sc.two_step_first(st.mass, st.inertia, st.restitution, est.u, st.length)
        return [] if sol is None else [sol]

    def _stops_spin(self, step: int) -> bool:
        return step > self.n_steps or self._spin_stop(step)

    def _finger_order(self, sol: sc.ContactSolution, step: int) -> tuple[tuple[int, ...], bool]:
        """Fingers to try and whether the order is strict (else: the quickest)."""
        return (0, 1), False

    # -- events ---------------------------------------------------------------------------------
    def _report(self, kind: str, key, **data) -> None:
        if key in self._reported:
            return
        self._reported.add(key)
        clean = {k: (_finite_or_none(v) if isinstance(v, (float, np.floating)) else v)
                 for k, v in data.items()}
        self._events.append(Occurrence(kind=kind, data=clean))

    def _on_break(self, t: float) -> None:
        t_break = self.est.breaks[-1]
        if self.phase != "approach" or self.plan is None:
            return
        plan = self.plan
        self._report_clamp(plan)
        self._next_try = -math.inf
        self._lost = None
        if abs(t_break - plan.t) <= self.params.detect_window:
            self.last_finger = plan.finger
            self.plan = None
            self.step += 1
            self.phase = "observe"
            if self.step > self.n_steps:
                spinning = abs(plan.sol.u_after[2]) >= self.params.min_spin
                if spinning and self.extra < self.params.max_extra:
                    self.extra += 1          # one more spin-stop collision (eq. 30)
                else:
                    self.phase = "close"
        else:
            self._events.append(Occurrence("missed", {
                "index": plan.index, "reason": "early_contact", "t_planned": float(plan.t),
                "t_break": float(t_break)}))
            self.plan = None
            self.phase = "observe"

    def _on_estimate(self, t: float) -> None:
        est = self.est.estimate()
        p = self.params
        if self.phase in ("observe", "approach"):
            if self.plan is not None and est.t_ref > self.plan.t + p.detect_window:
                self._events.append(Occurrence("missed", {
                    "index": self.plan.index, "reason": "no_collision",
                    "t_planned": float(self.plan.t), "t_now": float(t)}))
                self.plan = None
                self.phase = "observe"
            if self.plan is None:
                if t >= self._next_try:
                    self._plan_step(t, est)
                    if self.plan is None and self.phase != "close":
                        self._next_try = t + p.retry_interval
            elif t < self.plan.t - p.freeze and len(self.plan.route) <= 1:
                self._refine(t, est)
        elif self.phase == "close":
            if self.close is not None and t > self.close.t_meet + p.close_retry \
                    and self._capture_since is None:
                self.close = None
            if self.close is None:
                if t >= self._next_try:
                    self._plan_close(t, est)
                    if self.close is None:
                        self._next_try = t + p.retry_interval
            elif t < self.close.t_meet - p.freeze:
                self._refine_close(t, est)

    # -- planning a collision -------------------------------------------------------------------
    def _plan_step(self, t: float, est: StickEstimate) -> None:
        p = self.params
        step = self.step
        if self._stops_spin(step) and abs(est.omega) < p.min_spin:
            self._events.append(Occurrence("skip", {"index": step, "omega": float(est.omega),
                                                    "reason": "no_spin"}))
            self.step = self.n_steps + 1
            self.phase = "close"
            return
        options = self._contacts(est, step)
        if not options:
            self._report("infeasible", (step, "no_solution"), step=step, reason="no_solution",
                         vx=est.vx, vy=est.vy, omega=est.omega)
            self._to_close()
            return
        usable = [c for c in map(self._clamp, options) if c is not None]
        shortfall = _Shortfall()
        crossings_any = False
        first = math.inf
        for sol, raw in usable:
            crossings = self._crossings(t, est, sol.theta)
            crossings_any |= bool(crossings)
            first = min([first, *crossings])
            fingers, strict = self._finger_order(sol, step)
            for t_c in crossings:
                plan = self._reach(t, est, sol, raw, t_c, fingers, strict, shortfall)
                if plan is not None:
                    self.plan = plan
                    self._lost = None
                    self.phase = "approach"
                    self._events.append(Occurrence("plan", plan.intent(self.stick.width)))
                    return
        if not crossings_any:
            if abs(est.omega) < 1e-6:
                self._report("infeasible", (step, "no_crossing"), step=step,
                             reason="no_crossing", omega=est.omega, theta=est.theta)
                self._to_close()
            return                      # else the next crossing is beyond the horizon: wait
        self._lost_chance(t, first, shortfall)

    def _lost_chance(self, t: float, deadline: float, shortfall: _Shortfall) -> None:
        """Report ``unreachable`` once a contact opportunity has passed unplanned (an attempt
        that fails now may still succeed later, from nearer): the numbers of the last attempt
        made for it. ``deadline`` = the opportunity's time."""
        lost = self._lost
        if lost is not None and t > lost[0]:            # that chance passed unplanned
            self._report("infeasible", (self.step, "unreachable"), step=self.step,
                         reason="unreachable", t_contact=lost[0], t_needed=lost[1].t_needed,
                         t_available=lost[1].t_available)
            lost = None
        if lost is None or deadline <= lost[0] + 0.05:   # the same (drifting) chance, or earlier
            self._lost = (deadline, shortfall)

    def _clamp(self, sol: sc.ContactSolution):
        """(sol, None) when within the stick, else the fallback (clamped sol, raw r_x), or None
        when the clamped contact would not be approaching."""
        if sol.within:
            return sol, None
        r = math.copysign(0.5 * self.stick.length - self.params.tip_margin, sol.r_x)
        if sc.approach_speed(sol.theta, r, sol.side, sol.u_before) <= 0.0:
            return None
        st = self.stick
        return sc.contact_at(st.mass, st.inertia, st.restitution, sol.theta, sol.side,
                             sol.u_before, r, length=st.length, roots=sol.roots), sol.r_x

    def _report_clamp(self, plan: ContactPlan) -> None:
        """The ``infeasible`` event of a clamped contact, with the plan's final numbers."""
        if plan.clamped:
            self._report("infeasible", (plan.index, "r_x_beyond_stick"), step=plan.index,
                         reason="r_x_beyond_stick", theta=plan.sol.theta, r_x=plan.raw_r_x,
                         limit=0.5 * self.stick.length, fallback_r_x=plan.sol.r_x,
                         omega_after=plan.sol.u_after[2],
                         v_after=[float(v) for v in plan.sol.u_after[:2]])

    def _to_close(self) -> None:
        self.step = self.n_steps + 1
        self.phase = "close"

    def _refine(self, t: float, est: StickEstimate) -> None:
        """Re-solve the committed crossing and finger with the new estimate; keep the old plan
        when the refined one does not work."""
        old = self.plan
        options = self._contacts(est, old.index)
        n_old = sc.tangent_normal(old.sol.theta, old.sol.side)[1]
        for sol in options:
            if float(np.dot(sc.tangent_normal(sol.theta, sol.side)[1], n_old)) <= 0.0:
                continue                # the other face (alpha may jump by pi: compare n)
            clamped = self._clamp(sol)
            if clamped is None:
                return
            sol, raw = clamped
            crossings = self._crossings(t, est, sol.theta, keep_past=True)
            if not crossings:
                return
            t_c = min(crossings, key=lambda tc: abs(tc - old.t))
            if abs(est.omega) > 1e-6 and abs(t_c - old.t) > 0.5 * math.pi / abs(est.omega):
                return                                  # not the same crossing any more
            plan = self._reach(t, est, sol, raw, t_c, (old.finger,), True, _Shortfall(),
                               bases=[old.config.base])
            if plan is None:       # the spot moved out of reach from the old base
                plan = self._reach(t, est, sol, raw, t_c, (old.finger,), True, _Shortfall())
            if plan is not None:
                self.plan = plan
            return

    def _crossings(self, t: float, est: StickEstimate, theta_star: float,
                   keep_past: bool = False) -> list[float]:
        """Future times (<= t + horizon) at which theta(t) = theta* (mod pi)."""
        p = self.params
        t_min = t if keep_past else t + p.arrive_margin
        t_max = t + p.horizon
        if abs(est.omega) < 1e-6:
            if abs(wrap_half_pi(est.theta - theta_star)) < 0.02:
                return [float(x) for x in np.arange(t_min, t_max, 0.01)]   # aligned: any time
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

    def _reach(self, t: float, est: StickEstimate, sol: sc.ContactSolution, raw: float | None,
               t_c: float, fingers, strict: bool, shortfall: _Shortfall,
               bases=None) -> ContactPlan | None:
        """The quickest hand configuration that has finger k's tip at the contact spot for
        t_c with every check passed, or None."""
        p, st, hand = self.params, self.stick, self.hand
        pre = Motion(est)
        c_c, th_c = pre.pose(t_c)
        R = sc.rotation(sol.theta)
        contact = c_c + R @ sol.r_b(st.width)
        _, n = sc.tangent_normal(sol.theta, sol.side)
        tip = contact - hand.tip_radius * n
        motion = Motion(est, t_c, sol.u_after)
        now = self.model.config
        times_all = _times(t, t_c + p.post_horizon)
        best: tuple | None = None
        for k in fingers:
            j = 1 - k
            for base in (bases if bases is not None else self._base_candidates(k, tip)):
                q = hand2d.finger_ik(hand, base, k, tip, q_near=now.joints[k])
                if q is None:
                    continue
                cfg = Config(tuple(base), now.joints).with_finger(k, q)
                passive = self._passive(cfg, j, motion, times_all, tip)
                if passive is None:
                    continue
                cfg = cfg.with_finger(j, passive)
                need = travel(hand, now, cfg)
                t_arr = t + need
                if t_arr > t_c - p.arrive_margin:
                    shortfall.note(need + p.arrive_margin, t_c - t)
                    continue
                found = self._route(t, now, cfg, k, motion, t_c, tip, c_c)
                if found is None:
                    continue
                route, cost = found
                if best is None or cost < best[0]:
                    best = (cost, ContactPlan(self.step, k, t_c, th_c, sol, raw, contact,
                                              tip, cfg, route))
            if best is not None and strict:
                break
        return None if best is None else best[1]

    def _route(self, t: float, now: Config, cfg: Config, k: int, motion: Motion, t_c: float,
               tip, c_c) -> tuple[list, float] | None:
        """Waypoints [(t_start, Config)] that bring the hand from ``now`` to ``cfg`` (finger k's
        tip at the spot) before t_c with no fingertip hit by the predicted sweep on the way,
        and the arrival time. Tried in order: straight there; via a staging point outside a
        spinning stick's reach, moving in after its last pass over the spot; each of these after
        first pulling any fingertip out of the stick's reach."""
        p, st, hand = self.params, self.stick, self.hand
        half_l, half_w = 0.5 * st.length, 0.5 * st.width
        times = _times(t, t_c - CONTACT_GUARD)
        hit = covered(motion, times, [tip], half_l, half_w, hand.tip_radius - 5e-4)[:, 0]
        heads: list[list] = [[]]
        exit_cfg = self._exit_config(t, now, motion)
        if exit_cfg is not None:
            heads.append([(t, exit_cfg)])
        tails: list[list] = [[]]
        if hit.any():
            t_go = float(times[hit][-1]) + GO_DELAY
            u = np.asarray(tip) - c_c
            if np.linalg.norm(u) > 1e-9:
                stage = c_c + u / np.linalg.norm(u) * (half_l + hand.tip_radius + p.stage_margin)
                q_s = hand2d.finger_ik(hand, cfg.base, k, stage, q_near=cfg.joints[k])
                if q_s is not None:
                    tails.append([(None, cfg.with_finger(k, q_s)), (t_go, cfg)])
        for head in heads:
            for tail in tails:
                route = list(head)
                t_free = t if not head else t + travel(hand, now, head[-1][1])
                for t_start, c in (tail or [(None, cfg)]):
                    route.append((t_free if t_start is None else t_start, c))
                if not route or route[0][0] > t:
                    route.insert(0, (t, now))
                arrival = self._route_clear(t, now, route, k, motion, t_c)
                if arrival is not None:
                    return route, arrival
        return None

    def _route_clear(self, t: float, now: Config, route: list, k: int, motion: Motion,
                     t_c: float, check_idle: bool = True) -> float | None:
        """The arrival time of ``route`` if every segment finishes before the next starts, the
        last before t_c - arrive_margin, and no fingertip is hit by the predicted sweep: on the
        way (both tips) and, once arrived, finger k's tip until just before t_c and the idle
        tip (``sweep_margin`` clear) until t_c + post_horizon. Else None."""
        p, st, hand = self.params, self.stick, self.hand
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
        if arrival > t_c - p.arrive_margin:
            return None
        times = _times(t, t_c + (p.post_horizon if check_idle else 0.0))
        base, joints = _route_configs(hand, starts, frm, to, times)
        tips = _tips(hand, base, joints)                                  # (T, 2, 2)
        half_l, half_w = 0.5 * st.length, 0.5 * st.width
        moving = times < arrival
        act = times <= t_c - CONTACT_GUARD
        if covered_along(motion, times[act], tips[act, k], half_l, half_w,
                         hand.tip_radius - 5e-4).any():
            return None
        if check_idle:
            grow = np.where(moving, hand.tip_radius - 5e-4, hand.tip_radius + p.sweep_margin)
            if covered_along(motion, times, tips[:, 1 - k], half_l, half_w, grow).any():
                return None
        return arrival

    def _exit_config(self, t: float, now: Config, motion: Motion) -> Config | None:
        """``now`` with every fingertip within the stick's reach moved radially out of it
        (base kept), or None when no tip is inside or a tip cannot get out."""
        p, st, hand = self.params, self.stick, self.hand
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

    def _passive(self, cfg: Config, j: int, motion: Motion, times, active_tip):
        """The idle finger's joints nearest its current ones whose tip stays clear of the
        predicted sweep (and of the active tip); None when no posture is clear."""
        hand, st, p = self.hand, self.stick, self.params
        cands = [tuple(cfg.joints[j])] + self._passive_grid
        tips = np.array([hand2d.finger_tip(hand, cfg.base, j, q) for q in cands])
        hit = covered(motion, times, tips, 0.5 * st.length, 0.5 * st.width,
                      hand.tip_radius + p.sweep_margin).any(axis=0)
        far = np.linalg.norm(tips - active_tip[None, :], axis=1) > 2.0 * hand.tip_radius \
            + p.sweep_margin
        ok = np.flatnonzero(~hit & far)
        if ok.size == 0:
            return None
        cur = np.array(cfg.joints[j])
        dist = [float(np.max(np.abs(np.array(cands[i]) - cur))) for i in ok]
        return cands[int(ok[int(np.argmin(dist))])]

    def _base_candidates(self, k: int, tip) -> list[tuple]:
        """The current base (when the tip is comfortably within reach from it, so later
        refinements stay reachable), then bases putting finger k's root below the tip at a few
        comfortable reaches and angles (clamped to the slider range)."""
        hand = self.hand
        (xlo, xhi), (ylo, yhi) = hand.base_limits
        root = np.array(hand.root_offsets[k])
        reach = sum(hand.link_lengths)
        here = tuple(self.model.target.base)
        out = []
        if np.linalg.norm(np.asarray(tip) - root - np.array(here)) <= 0.85 * reach:
            out.append(here)
        for rho in (0.7 * reach, 0.5 * reach, 0.85 * reach):
            for deg in (90.0, 65.0, 115.0, 40.0, 140.0):
                a = math.radians(deg)
                b = np.asarray(tip) - root - rho * np.array([math.cos(a), math.sin(a)])
                out.append((float(np.clip(b[0], xlo, xhi)), float(np.clip(b[1], ylo, yhi))))
        return out

    # -- closing (eqs. 32, 33, 38) --------------------------------------------------------------
    def _plan_close(self, t: float, est: StickEstimate) -> None:
        p, st, hand = self.params, self.stick, self.hand
        x, y, th = est.at(t)
        c_now = np.array([x, y])
        speed = est.speed
        moving = speed >= p.capture_speed
        if moving:
            d = np.array([est.vx, est.vy]) / speed
        else:
            d = np.array([-math.sin(th), math.cos(th)])
        rear = self.last_finger
        if rear is None:
            proj = [float(np.dot(hand.root_offsets[k], d)) for k in (0, 1)]
            rear = int(np.argmin(proj))
        elif not moving:
            if np.dot(d, c_now - self.model.config.tip(hand, rear)) < 0.0:
                d = -d
        front = 1 - rear
        h = 0.5 * st.width + hand.tip_radius + 0.5 * p.grip_clearance
        now = self.model.config
        # a spin left by a clamped contact is ignored here: the sweep of a spinning stick covers
        # every spot near the line, so the closing could never be planned (not friction free)
        pre = Motion(dataclasses.replace(est, omega=0.0))
        shortfall = _Shortfall()
        taus = np.arange(0.02, p.horizon + 1e-9, 0.02) if moving else np.array([0.02])
        for tau in taus:
            t_m = t + float(tau)
            meet = pre.pose(t_m)[0] if moving else c_now
            F, Rr = meet + d * h, meet - d * h
            best = None
            for base in self._close_bases(F, Rr, front, rear):
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
                    best = (need, cfg.with_finger(rear, qr), [(t, cfg.with_finger(rear, qr))])
                    break
                # while the base moves the rear finger is parked behind the stick (its joints
                # cannot hold the tip still against a moving slider); it follows once the
                # base has arrived
                park = pre.pose(t + need)[0] - d * (h + p.follow_gap)
                qp = hand2d.finger_ik(hand, base, rear, park, q_near=now.joints[rear])
                if qp is None:
                    continue
                cfg = cfg.with_finger(rear, qp)
                for route in [[(t, cfg)]] + self._around(t, now, cfg, front, F, pre):
                    arrival = self._route_clear(t, now, route, front, pre, t_m)
                    if arrival is not None:
                        best = (arrival, cfg, route)
                        break
                if best is not None:
                    break
            if best is not None:
                u = est.u
                sol = sc.closing_contact(st.mass, st.inertia, st.restitution, u, st.length) \
                    if moving else None
                self.close = ClosePlan(self.step, front, rear, t_m, d, meet, h, best[1], sol,
                                       pre.pose(t_m)[1], len(self.est.breaks), best[2])
                self._lost = None
                self._events.append(Occurrence("plan", self.close.intent(st.width)))
                return
        # the closing has no discrete chances: report once it failed for close_retry
        self._lost_chance(t, t + p.close_retry if self._lost is None else self._lost[0],
                          shortfall)

    def _around(self, t: float, now: Config, cfg: Config, k: int, target,
                motion: Motion) -> list:
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
            a2 = np.asarray(target) + s_hat * (sgn * w - float(np.dot(np.asarray(target) - c,
                                                                       s_hat)))
            q2 = hand2d.finger_ik(hand, cfg.base, k, a2, q_near=cfg.joints[k])
            if q2 is None:
                continue
            c2 = cfg.with_finger(k, q2)
            for base1 in (cfg.base, now.base):       # sideways first, the base moving or not
                q1 = hand2d.finger_ik(hand, base1, k, a1, q_near=now.joints[k])
                if q1 is not None:
                    break
            if q1 is None:
                continue
            c1 = (cfg if tuple(base1) == tuple(cfg.base) else
                  Config(tuple(base1), now.joints)).with_finger(k, q1)
            t1 = t + travel(hand, now, c1)
            t2 = t1 + travel(hand, c1, c2)
            routes.append([(t, c1), (t1, c2), (t2, cfg)])
        return routes

    def _refine_close(self, t: float, est: StickEstimate) -> None:
        """Move the waiting front tip onto the refined line of motion (same base and meeting
        time) while the stick has not touched anything since the closing was planned."""
        c, p = self.close, self.params
        if len(self.est.breaks) != c.n_breaks or est.speed < p.capture_speed \
                or (c.route and t < c.route[-1][0]):      # still going around the stick
            return
        d = np.array([est.vx, est.vy]) / est.speed
        if float(np.dot(d, c.d)) < 0.9:
            return
        meet = Motion(est).pose(c.t_meet)[0]
        q = hand2d.finger_ik(self.hand, c.config.base, c.front, meet + d * c.half_gap,
                             q_near=c.config.joints[c.front])
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
            c.sol = sc.closing_contact(st.mass, st.inertia, st.restitution, est.u, st.length) \
                or c.sol

    def _close_bases(self, F, Rr, front: int, rear: int) -> list[tuple]:
        hand = self.hand
        (xlo, xhi), (ylo, yhi) = hand.base_limits
        mid = 0.5 * (np.asarray(F) + np.asarray(Rr))
        roots = 0.5 * (np.array(hand.root_offsets[front]) + np.array(hand.root_offsets[rear]))
        reach = sum(hand.link_lengths)
        out = [tuple(self.model.target.base)]
        for frac in (0.7, 0.55, 0.85, 0.4):
            for dx in (0.0, -0.03, 0.03):
                b = mid - roots - np.array([dx, frac * reach])
                out.append((float(np.clip(b[0], xlo, xhi)), float(np.clip(b[1], ylo, yhi))))
        return out

    def _close_command(self, t: float) -> Config:
        c = self.close
        cfg = c.target(t)
        if np.max(np.abs(np.subtract(self.model.config.base, c.config.base))) > 1e-9:
            return cfg                   # the base is still moving: the rear finger is parked
        pred = self.est.predict(t)
        s_now = float(np.dot(c.d, np.array(pred[:2]) - c.meet))
        s_rear = -c.half_gap if t >= c.t_meet else min(-c.half_gap,
                                                      s_now - c.half_gap - self.params.follow_gap)
        point = c.meet + c.d * s_rear
        q = hand2d.finger_ik(self.hand, cfg.base, c.rear, point,
                             q_near=self.model.target.joints[c.rear])
        if q is None:
            return cfg.with_finger(c.rear, self.model.target.joints[c.rear])
        return cfg.with_finger(c.rear, q)

    # -- commands and capture -------------------------------------------------------------------
    def _command(self, t: float) -> None:
        if self.phase == "approach" and self.plan is not None:
            self.model.target = self.plan.target(t)
            if t >= self.plan.t - self.params.freeze:
                self._report_clamp(self.plan)
        elif self.phase in ("close", "captured") and self.close is not None:
            if self.phase == "close":
                self.model.target = self._close_command(t)

    def _check_capture(self, t: float) -> None:
        if self.phase != "close" or self.close is None or not self.est.ready():
            return
        p, st, hand = self.params, self.stick, self.hand
        est = self.est.estimate()
        x, y, th = est.at(t)
        ok = est.speed < p.capture_speed and abs(est.omega) < p.capture_spin
        if ok:
            cs, sn = math.cos(th), math.sin(th)
            sides = []
            for k in (0, 1):
                d = self.model.config.tip(hand, k) - np.array([x, y])
                xb, yb = d[0] * cs + d[1] * sn, -d[0] * sn + d[1] * cs
                at = abs(xb) <= 0.5 * st.length and \
                    abs(yb) <= 0.5 * st.width + hand.tip_radius + p.grip_clearance + 0.003
                sides.append(yb if at else 0.0)
            ok = sides[0] * sides[1] < 0.0
        if not ok:
            self._capture_since = None
            return
        if self._capture_since is None:
            self._capture_since = t
        if t - self._capture_since >= p.capture_hold and not self.captured:
            self.captured = True
            self.phase = "captured"
            self._events.append(Occurrence("capture", {
                "t_since": float(self._capture_since), "speed": float(est.speed),
                "omega": float(est.omega), "x": float(x), "y": float(y), "theta": float(th),
                "tips": [[float(v) for v in self.model.config.tip(hand, k)] for k in (0, 1)]}))

    # -- set-up -----------------------------------------------------------------------------------
    def _home(self) -> Config:
        """Where the hand was homed at t = 0 (the spec says; the method has no hand feedback
        after that and tracks its own commands)."""
        hand = self.hand
        return Config(tuple(hand.start_base), tuple(tuple(q) for q in hand.start_joints))

    def _posture_grid(self) -> list[tuple]:
        (a0, a1), (b0, b1) = self.hand.joint_limits
        return [(float(q1), float(q2)) for q1 in np.linspace(a0, a1, 5)
                for q2 in np.linspace(b0, b1, 5)]


class TwoStepController(StickCaptureController):
    """Sec. III-B: omega_1 = 0 at theta_1 = alpha(v_0) with p = -1 (eqs. 30, 31), then closing
    along the line of v_0 (eqs. 32, 33)."""

    Params: ClassVar[type] = TwoStepParams
    description = "Higashimori et al. 2007: 2-step friction independent stick capture"
    n_steps: ClassVar[int] = 1

    def _options(self, est, step):
        st = self.stick
        sol = sc.two_step_first(st.mass, st.inertia, st.restitution, est.u, st.length)
        return [] if sol is None else [sol]

    def _spin_stop(self, step):
        return step == 1


class ThreeStepController(StickCaptureController):
    """Sec. III-C: v_1 = 0 at theta_1 = alpha(v_0) (eqs. 34, 35), omega_2 = 0 at
    theta_2 = alpha(lambda_2) with v_2 along lambda_2 (eqs. 36, 37), then closing (eq. 38)."""

    Params: ClassVar[type] = ThreeStepParams
    description = "Higashimori et al. 2007: 3-step friction independent stick capture"
    n_steps: ClassVar[int] = 2

    def lambdas(self, est: StickEstimate) -> list[np.ndarray]:
        """lambda_2 (unit), and -lambda_2 first when auto-sign prefers it."""
        lam = np.asarray(self.params.lambda_2, dtype=float)
        lam = lam / np.linalg.norm(lam)
        if not self.params.lambda_2_auto_sign:
            return [lam]
        centre = np.array([0.5 * (lo + hi) for lo, hi in self.hand.base_limits])
        x, y, _ = est.at(est.t_ref)
        if float(np.dot(lam, centre - np.array([x, y]))) < 0.0:
            return [-lam, lam]
        return [lam, -lam]

    def _options(self, est, step):
        st = self.stick
        m, inertia, e = st.mass, st.inertia, st.restitution
        if step == 1:
            sol = sc.three_step_first(m, inertia, e, est.u, st.length)
            return [] if sol is None else [sol]
        out = []
        for lam in self.lambdas(est):
            sol = sc.three_step_second(m, inertia, e, est.u, lam, st.length)
            if sol is not None:
                out.append(sol)
        return out

    def _spin_stop(self, step):
        return step == 2

    def _finger_order(self, sol, step):
        if step != 2:
            return (0, 1), False
        v2 = np.array(sol.u_after[:2])
        proj = [float(np.dot(self.hand.root_offsets[k], v2)) for k in (0, 1)]
        rear = int(np.argmin(proj))     # the finger that pushes stays behind the stick
        return (rear, 1 - rear), True
