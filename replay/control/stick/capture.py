"""The controller machinery the 2-step and 3-step capturing strategies (Higashimori et al. 2007,
Sec. III) share: phases, planned collisions, events and the capture check.

:class:`StickCaptureController` runs the cycle below; the strategies
(``strategy``) give the contact of each collision. The hand plans are made by
``plan`` (collisions) and ``close`` (the closing), with the hand model of
``hand_model`` and the predicted sweep of ``coverage``.

Pure NumPy. The controller sees only ``/vision/stick`` measurements (x, y, theta mod pi; already
delayed by the camera latency) and the :class:`~replay.robot.hand2d.AirTableSpec` (hand kinematics and
the stick's m, I, L, W, e; never the friction mu). It has no hand feedback: it tracks its own
commands with a model that moves every axis toward its target at the spec's speed limit, starting
from where the spec says the hand was homed (``HandSpec.start_base`` / ``start_joints``).

Cycle of one planned collision i:

1. Observe until the :class:`~replay.control.stick.estimator.StickEstimator` is ready.
2. Solve the contact (r_x, side) from the estimated u_{i-1} (collision: eqs. 25, 28, 26 and
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
   the plant moves). The first crossing that works, among those after which the stick (moving
   with J_i u, eq. 22) is still within ``reach_fraction`` of the fingers' reach
   ``keep_in_reach`` later (else among all), is the plan; it is refined with new estimates
   until ``freeze`` before the contact (staged routes too: a plan made from the few samples just
   after a collision extrapolates a noisy velocity), re-planned only when an estimate moves the
   contact beyond ``replan_tol`` / ``replan_theta`` / ``replan_dt`` (a control tick without a new
   frame plans nothing, at any controller rate, nor does a frame that changes nothing; every
   span here is in seconds of the frames' and ticks' own times, none counted in calls).
4. A model break of the estimator within ``detect_window`` of the planned time, or whose unseen
   gap (last fitted sample .. first deviating one, e.g. the stick out of the camera's view)
   contains it, is the planned collision; the plan for the next step is then made from fresh
   estimates. A break much earlier, or none by ``detect_window`` after the plan, is reported
   (``missed``) and the step re-planned.

Closing (eqs. 32, 33, 38): once the stick translates, the finger that made the last collision is
behind it; the other waits on the line through the centre of mass along v, ahead of the stick, at
the point the stick reaches first that the hand can get to in time (going around an end of the
stick when it starts behind it); the rear fingertip waits behind the stick while the slider
moves (finger joints cannot hold a tip still against a moving slider), then follows the stick
along that line (``follow_gap`` behind) to the final gap W + 2 tip_radius + grip_clearance; the
front tip's route keeps a full tip radius clear of the predicted stick before the meeting.
Whatever spin is left is ignored by the closing plan (the fingers then squeeze a turning stick:
not friction independent); but a closing to be (re)planned on a stick spinning faster than
``respin`` first gets a spin-stop collision (eq. 30), up to ``max_extra`` in all.
A ``capture`` event is emitted once the estimated speed stays below ``capture_speed`` and spin
below ``capture_spin`` for ``capture_hold`` with both modelled fingertips at the stick's two faces.
That is the method's own belief (from vision, a frame late and a fit window behind), not the
run's capture time: the event comes at ``t_since`` + ``capture_hold`` (``t_since``, also the
outcome's ``t_capture_method``, is when the method first saw the conditions); the run's capture
time is the plant's ``t_capture`` (docs/stick.md, "Capture time").

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
``skip``, ``capture``. ``outcome()``: the method's metrics, and when it has not captured the stick
``success: False`` with why (out of reach, r_x beyond the stick, no feasible plan, timed out).
``intent()``: index, finger, t, theta, r_x, r_y, side, v_after,
omega_after, contact and tip (world, m), clamped, r_x_solved. theta is the estimator's continuous
orientation (it starts from the camera's first reading in (-pi/2, pi/2]); r_x, r_y and side are
in that body frame (the solution's frame theta* = alpha(.) may differ from it by pi).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from replay.robot import hand2d
from replay.robot.hand2d import AirTableSpec, HandCommand, HandSpec
from replay.interfaces import Controller, Occurrence
from replay.params import param
from replay.control.stick import collision as sc
from replay.control.stick.close import ClosePlan, ClosePlanner
from replay.control.stick.estimator import StickEstimate, StickEstimator
from replay.control.stick.hand_model import Config, HandModel
from replay.control.stick.plan import ContactPlan, ContactPlanner, Shortfall
from replay.control.stick.coverage import Motion
from replay.messages import TOPIC_STICK_ESTIMATE, TOPIC_VISION_STICK


# ------------------------------------------------------------------------------------------
# Parameters
# ------------------------------------------------------------------------------------------


@dataclass
class StickCaptureParams:
    window: int = param(
        30,
        unit="1",
        ge=2,
        le=1000,
        doc="samples in the sliding least-squares window (0.1 s at 300 fps)",
    )
    min_samples: int = param(
        6,
        unit="1",
        ge=2,
        le=1000,
        doc="samples since the last collision before the estimate is used",
    )
    pos_tol: float = param(
        0.002,
        unit="m",
        gt=0.0,
        le=0.1,
        doc="position deviation from the prediction that breaks the model",
    )
    theta_tol: float = param(
        0.03,
        unit="rad",
        gt=0.0,
        le=1.0,
        doc="orientation deviation from the prediction that breaks the model",
    )
    confirm: int = param(
        2, unit="1", ge=1, le=5, doc="consecutive deviating samples that confirm a collision"
    )
    horizon: float = param(
        1.0, unit="s", gt=0.0, le=10.0, doc="how far ahead a contact is searched"
    )
    arrive_margin: float = param(
        0.01,
        unit="s",
        ge=0.0,
        le=0.5,
        doc="the fingertip must be at the spot this long before contact",
    )
    freeze: float = param(
        0.01,
        unit="s",
        ge=0.0,
        le=0.5,
        doc="the target is no longer refined this long before the contact",
    )
    replan_tol: float = param(
        5e-5,
        unit="m",
        ge=0.0,
        le=0.01,
        doc="a new estimate re-plans a committed contact only when it moves the fingertip "
        "spot by more than this (our choice, ~0.03 px of the 512 px camera; on the seeded "
        "20-throw audit, analysis.stick.throws, 3e-5 and 5e-5 m keep the 3-step's 19/20 of "
        "re-planning on every estimate, 1e-4 gives 18/20: one throw's closing meets the "
        "stick 20 ms later and its front tip is hit) ...",
    )
    replan_theta: float = param(
        2e-3,
        unit="rad",
        ge=0.0,
        le=0.5,
        doc="... or when, at the committed time, the stick would be this far from the "
        "contact orientation (|omega| |t_c' - t_c|; our choice, 1/15 of theta_tol) ...",
    )
    replan_dt: float = param(
        1e-3,
        unit="s",
        ge=0.0,
        le=0.1,
        doc="... or the contact time moves by more than this (a tenth of arrive_margin)",
    )
    detect_window: float = param(
        0.04,
        unit="s",
        gt=0.0,
        le=1.0,
        doc="a model break this close to the planned time is the plan's",
    )
    min_spin: float = param(
        0.2,
        unit="rad/s",
        ge=0.0,
        le=100.0,
        doc="below this |omega| a spin-stopping step is skipped",
    )
    max_extra: int = param(
        2,
        unit="1",
        ge=0,
        le=10,
        doc="spin-stop collisions (eq. 30) added when a clamped contact left "
        "|omega| >= min_spin, before closing",
    )
    tip_margin: float = param(
        0.005, unit="m", ge=0.0, le=0.05, doc="fallback: |r_x| is clamped to L/2 - tip_margin"
    )
    sweep_margin: float = param(
        0.003,
        unit="m",
        ge=0.0,
        le=0.05,
        doc="clearance between an idle fingertip and the predicted sweep",
    )
    stage_margin: float = param(
        0.01,
        unit="m",
        ge=0.0,
        le=0.2,
        doc="a staged tip waits this far outside a spinning stick's reach",
    )
    post_horizon: float = param(
        0.1, unit="s", ge=0.0, le=2.0, doc="after a contact the idle finger stays clear this long"
    )
    grip_clearance: float = param(
        0.002,
        unit="m",
        ge=0.0,
        le=0.05,
        doc="final fingertip gap = W + 2 tip_radius + grip_clearance",
    )
    follow_gap: float = param(
        0.01, unit="m", ge=0.0, le=0.1, doc="the rear fingertip follows this far behind the stick"
    )
    retry_interval: float = param(
        0.02,
        unit="s",
        ge=0.0,
        le=1.0,
        doc="after a failed plan, wait this long before trying again",
    )
    close_retry: float = param(
        0.3,
        unit="s",
        gt=0.0,
        le=5.0,
        doc="the closing is re-planned when no capture this long after the planned meeting",
    )
    capture_speed: float = param(
        0.02, unit="m/s", gt=0.0, le=1.0, doc="capture: estimated speed below this"
    )
    capture_spin: float = param(
        0.5, unit="rad/s", gt=0.0, le=50.0, doc="capture: estimated |omega| below this"
    )
    capture_hold: float = param(
        0.05, unit="s", ge=0.0, le=5.0, doc="capture: conditions held this long"
    )
    respin: float = param(
        2.0,
        unit="rad/s",
        ge=0.0,
        le=100.0,
        doc="a closing to be (re)planned on a stick spinning faster than this "
        "gets a spin-stop collision (eq. 30) first, up to max_extra",
    )
    view: list = param(
        [-0.40, 0.40, -0.20, 0.60],
        unit="m",
        length=4,
        ge=-10.0,
        le=10.0,
        doc="[x_min, x_max, y_min, y_max] of the stick's centre where the camera "
        "sees the whole stick (the scenarios' camera: a 0.9 m square about "
        "(0, 0.2), less L/2); contacts there are preferred (the method sees "
        "their result)",
    )
    keep_in_reach: float = param(
        0.3,
        unit="s",
        ge=0.0,
        le=5.0,
        doc="a contact after which the stick's predicted centre is still "
        "within reach_fraction of the fingers' reach this long is "
        "preferred (the next steps need it there; our choice)",
    )
    reach_fraction: float = param(
        0.85,
        unit="1",
        gt=0.0,
        le=2.0,
        doc="'within reach' for keep_in_reach: this fraction of l1 + l2 "
        "from a finger root the slider can reach",
    )


def _finite_or_none(v) -> float | None:
    """Event data must be JSON without NaN/inf (the log contract): non-finite -> None."""
    v = float(v)
    return v if math.isfinite(v) else None


# ------------------------------------------------------------------------------------------
# The controller
# ------------------------------------------------------------------------------------------


class StickCaptureController(Controller):
    """Shared machinery; subclasses give the contact of each step (``_options``)."""

    Params: ClassVar[type] = StickCaptureParams
    spec_type: ClassVar[type] = AirTableSpec
    command_type: ClassVar[type] = HandCommand
    reads: ClassVar[tuple[str, ...]] = (TOPIC_VISION_STICK,)
    n_steps: ClassVar[int] = 1

    def __init__(self, params, *, spec: AirTableSpec) -> None:
        super().__init__(params, spec=spec)
        p = params
        self.hand: HandSpec = spec.hand
        self.stick = spec.stick
        self.est = StickEstimator(
            window=p.window,
            min_samples=p.min_samples,
            pos_tol=p.pos_tol,
            theta_tol=p.theta_tol,
            confirm=p.confirm,
        )
        self.model = HandModel(self.hand, self._home())
        self.planner = ContactPlanner(p, self.hand, self.stick, self.model)
        self.closing = ClosePlanner(self.planner)
        self.phase = "observe"
        self.step = 1  # index of the next collision
        self.plan: ContactPlan | None = None
        self.close: ClosePlan | None = None
        self.last_finger: int | None = None
        self.captured = False
        self._capture_since: float | None = None
        self._events: list[Occurrence] = []
        self._reported: set = set()
        self._next_try = -math.inf  # no new plan attempt before this time
        self.extra = 0  # spin-stop collisions added so far
        self._lost: tuple | None = None  # (time of a contact chance not yet planned, numbers)
        self._infeasible: list[dict] = []  # the ``infeasible`` reports, in order
        self._missed = 0  # ``missed`` reports
        self._t_capture: float | None = None

    # -- Controller interface -----------------------------------------------------------------
    def update(self, t: float, measurements) -> HandCommand:
        self.model.advance(t)
        broke = fresh = False
        for topic, m in measurements:
            if topic != TOPIC_VISION_STICK or m is None:
                continue
            broke |= self.est.add(m.t, m.x, m.y, m.theta)
            fresh = True
        if broke:
            self._on_break(t)
        if fresh and self.est.ready():
            self._on_estimate(t, self.est.current())
        self._command(t)
        self._check_capture(t)
        return self.model.target.command

    def intent(self) -> dict:
        if self.plan is not None:
            return self.plan.intent(self.stick.width)
        if self.close is not None:
            return self.close.intent(self.stick.width)
        return {}

    def pop_events(self) -> list[Occurrence]:
        out, self._events = self._events, []
        return out

    def outcome(self, t: float) -> dict:
        """The method's metrics (``t_capture_method``: when its estimate first saw the stick held,
        the ``capture`` event's ``t_since``; not the run's capture time, the plant's
        ``t_capture``) and, when it has not captured the stick, why (the last thing that
        stopped it: out of reach, r_x beyond the stick, no feasible plan, or the run ended first)."""
        out = {
            "method_captured": self.captured,
            "t_capture_method": self._t_capture,
            "phase": self.phase,
            "collisions_done": self.step - 1,
            "extra_spin_stops": self.extra,
            "missed": self._missed,
            "infeasible": [d["reason"] + f"@{d['step']}" for d in self._infeasible],
            "as_planned": not self._infeasible and not self._missed,
        }
        if self.captured:
            return out
        # the runner keeps the plant's reason when both fail: method_reason keeps this one too
        out["success"] = False
        out["reason"] = out["method_reason"] = self._why_not(t)
        return out

    def _why_not(self, t: float) -> str:
        last = self._infeasible[-1] if self._infeasible else None
        where = f"phase {self.phase}, collision {self.step}"
        if self._lost is not None and t > self._lost[0]:  # a chance passed, not reported
            last = {
                "reason": "unreachable",
                "step": self.step,
                "t_contact": self._lost[0],
                "t_needed": _finite_or_none(self._lost[1].t_needed),
                "t_available": self._lost[1].t_available,
            }
        if last is None:
            e = self.est.estimate()
            if e is None:
                return f"timed out before capture: the stick was never seen ({where})"
            if t - e.t_ref > 0.1:
                return (
                    f"timed out before capture: the stick out of sight since t = "
                    f"{e.t_ref:.3f} s ({where})"
                )
            return f"timed out before capture ({where})"
        step = last["step"]
        if last["reason"] == "unreachable":
            need = last.get("t_needed")
            if need is None:
                return f"out of reach: no hand posture reaches contact {step} clear of the stick"
            return (
                f"out of reach: the hand cannot get to contact {step} in time (needs "
                f"{need:.3f} s, had {last.get('t_available', 0.0):.3f} s)"
            )
        if last["reason"] == "r_x_beyond_stick":
            return (
                f"infeasible: r_x beyond the stick at collision {step} (|r_x| = "
                f"{abs(last['r_x']) * 1e3:.1f} mm > L/2 = {last['limit'] * 1e3:.1f} mm); "
                f"the clamped fallback did not capture ({where})"
            )
        if last["reason"] in ("no_solution", "no_crossing"):
            what = (
                "no root of eq. 25/28 passes eq. 26"
                if last["reason"] == "no_solution"
                else "the stick never turns to alpha(v)"
            )
            return f"infeasible: no feasible plan for collision {step} ({what}; {where})"
        return f"infeasible: {last['reason']} at collision {step} ({where})"

    def telemetry(self, t: float) -> dict:
        e = self.est.estimate()
        if e is None:
            return {
                TOPIC_STICK_ESTIMATE: {
                    "t": float(t),
                    "phase": self.phase,
                    "step": self.step,
                    "ready": False,
                }
            }
        dt = t - e.t_ref  # e.at(t)
        return {
            TOPIC_STICK_ESTIMATE: {
                "t": float(t),
                "phase": self.phase,
                "step": self.step,
                "ready": e.n >= self.est.min_samples,  # est.ready()
                "t_ref": e.t_ref,
                "x": e.x + e.vx * dt,
                "y": e.y + e.vy * dt,
                "theta": e.theta + e.omega * dt,
                "vx": e.vx,
                "vy": e.vy,
                "omega": e.omega,
                "n": e.n,
                "rms_xy": e.rms_xy,
                "rms_theta": e.rms_theta,
            }
        }

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
        clean = {
            k: (_finite_or_none(v) if isinstance(v, (float, np.floating)) else v)
            for k, v in data.items()
        }
        self._events.append(Occurrence(kind=kind, data=clean))
        if kind == "infeasible":
            self._infeasible.append(clean)

    def _on_break(self, t: float) -> None:
        t_break = self.est.breaks[-1]
        if self.phase != "approach" or self.plan is None:
            return
        plan = self.plan
        self._report_clamp(plan)
        self._next_try = -math.inf
        self._lost = None
        # the planned time within the break's unseen gap (the last fitted sample .. the first
        # deviating one; the stick may have been out of the camera's view) is the plan's
        dw = self.params.detect_window
        prev = self.est.before_break
        t_seen = prev.t_ref if prev is not None else t_break
        if t_seen - dw <= plan.t <= t_break + dw:
            self.last_finger = plan.finger
            self.plan = None
            self.step += 1
            self.phase = "observe"
            if self.step > self.n_steps:
                spinning = abs(plan.sol.u_after[2]) >= self.params.min_spin
                if spinning and self.extra < self.params.max_extra:
                    self.extra += 1  # one more spin-stop collision (eq. 30)
                else:
                    self.phase = "close"
        else:
            self._missed += 1
            self._events.append(
                Occurrence(
                    "missed",
                    {
                        "index": plan.index,
                        "reason": "early_contact",
                        "t_planned": float(plan.t),
                        "t_break": float(t_break),
                    },
                )
            )
            self.plan = None
            self.phase = "observe"

    def _on_estimate(self, t: float, est: StickEstimate) -> None:
        p = self.params
        if self.phase in ("observe", "approach"):
            if self.plan is not None and est.t_ref > self.plan.t + p.detect_window:
                self._missed += 1
                self._events.append(
                    Occurrence(
                        "missed",
                        {
                            "index": self.plan.index,
                            "reason": "no_collision",
                            "t_planned": float(self.plan.t),
                            "t_now": float(t),
                        },
                    )
                )
                self.plan = None
                self.phase = "observe"
            if self.plan is None:
                if t >= self._next_try:
                    self._plan_step(t, est)
                    if self.plan is None and self.phase != "close":
                        self._next_try = t + p.retry_interval
            elif t < self.plan.t - p.freeze:
                # staged routes too: a plan made from the few samples after a collision
                # extrapolates a noisy velocity (e.g. 0.05 m/s from 6 samples: 2 cm in 0.4 s)
                self._refine(t, est, self.plan)
        elif self.phase == "close":
            if (
                self.close is not None
                and t > self.close.t_meet + p.close_retry
                and self._capture_since is None
                and not self._between_tips(t, est)
            ):
                self.close = None  # (a stick already between the tips is left to settle)
            if (
                self.close is None
                and abs(est.omega) >= p.respin
                and self.extra < p.max_extra
                and self._capture_since is None
            ):
                self.extra += 1  # still spinning: one more spin-stop collision (eq. 30)
                self.step = max(self.step, self.n_steps + 1)
                self.phase = "observe"
                self._next_try = -math.inf
                return
            if self.close is None:
                if t >= self._next_try:
                    self._plan_close(t, est)
                    if self.close is None:
                        self._next_try = t + p.retry_interval
            elif t < self.close.t_meet - p.freeze:
                self.closing.refine(t, est, self.close, len(self.est.breaks))

    # -- planning a collision -------------------------------------------------------------------
    def _plan_step(self, t: float, est: StickEstimate) -> None:
        p = self.params
        step = self.step
        if self._stops_spin(step) and abs(est.omega) < p.min_spin:
            self._events.append(
                Occurrence("skip", {"index": step, "omega": float(est.omega), "reason": "no_spin"})
            )
            self.step = self.n_steps + 1
            self.phase = "close"
            return
        options = self._contacts(est, step)
        if not options:
            self._report(
                "infeasible",
                (step, "no_solution"),
                step=step,
                reason="no_solution",
                vx=est.vx,
                vy=est.vy,
                omega=est.omega,
            )
            self._to_close()
            return
        usable = [c for c in map(self._clamp, options) if c is not None]
        shortfall = Shortfall()
        crossings_any = False
        first = math.inf
        tried = set()  # (option, crossing) already without a plan: the same inputs again fail
        # first the contacts in view that leave the stick within reach, then those in view, then any
        for keep in (2, 1, 0):
            for i, (sol, raw) in enumerate(usable):
                crossings = self.planner.crossings(t, est, sol.theta)
                crossings_any |= bool(crossings)
                first = min([first, *crossings])
                fingers, strict = self._finger_order(sol, step)
                for t_c in crossings:
                    if (i, t_c) in tried:
                        continue
                    if keep and not self._in_view(est, sol, t_c):
                        continue
                    if keep == 2 and not self._stays_in_reach(est, sol, t_c):
                        continue
                    tried.add((i, t_c))
                    plan = self.planner.reach(
                        self.step, t, est, sol, raw, t_c, fingers, strict, shortfall
                    )
                    if plan is not None:
                        self.plan = plan
                        self._lost = None
                        self.phase = "approach"
                        self._events.append(Occurrence("plan", plan.intent(self.stick.width)))
                        return
        if not crossings_any:
            if abs(est.omega) < 1e-6:
                self._report(
                    "infeasible",
                    (step, "no_crossing"),
                    step=step,
                    reason="no_crossing",
                    omega=est.omega,
                    theta=est.theta,
                )
                self._to_close()
            return  # else the next crossing is beyond the horizon: wait
        self._lost_chance(t, first, shortfall)

    def _in_view(self, est: StickEstimate, sol: sc.ContactSolution, t_c: float) -> bool:
        """The stick's centre within ``view`` at the contact and ``keep_in_reach`` after it."""
        x0, x1, y0, y1 = self.params.view
        motion = Motion(est, t_c, sol.u_after)
        for tt in (t_c, t_c + self.params.keep_in_reach):
            c = motion.pose(tt)[0]
            if not (x0 <= c[0] <= x1 and y0 <= c[1] <= y1):
                return False
        return True

    def _stays_in_reach(self, est: StickEstimate, sol: sc.ContactSolution, t_c: float) -> bool:
        """The stick's centre, moving with J_i u (eq. 22) after the contact at t_c, is within
        ``reach_fraction`` of the fingers' reach ``keep_in_reach`` later."""
        p = self.params
        c = Motion(est, t_c, sol.u_after).pose(t_c + p.keep_in_reach)[0]
        return hand2d.root_distance(self.hand, c) <= p.reach_fraction * sum(self.hand.link_lengths)

    def _lost_chance(self, t: float, deadline: float, shortfall: Shortfall) -> None:
        """Report ``unreachable`` once a contact opportunity has passed unplanned (an attempt
        that fails now may still succeed later, from nearer): the numbers of the last attempt
        made for it. ``deadline`` = the opportunity's time."""
        lost = self._lost
        if lost is not None and t > lost[0]:  # that chance passed unplanned
            self._report(
                "infeasible",
                (self.step, "unreachable"),
                step=self.step,
                reason="unreachable",
                t_contact=lost[0],
                t_needed=lost[1].t_needed,
                t_available=lost[1].t_available,
            )
            lost = None
        if lost is None or deadline <= lost[0] + 0.05:  # the same (drifting) chance, or earlier
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
        return sc.contact_at(
            st.mass,
            st.inertia,
            st.restitution,
            sol.theta,
            sol.side,
            sol.u_before,
            r,
            length=st.length,
            roots=sol.roots,
        ), sol.r_x

    def _report_clamp(self, plan: ContactPlan) -> None:
        """The ``infeasible`` event of a clamped contact, with the plan's final numbers."""
        if plan.clamped:
            self._report(
                "infeasible",
                (plan.index, "r_x_beyond_stick"),
                step=plan.index,
                reason="r_x_beyond_stick",
                theta=plan.sol.theta,
                r_x=plan.raw_r_x,
                limit=0.5 * self.stick.length,
                fallback_r_x=plan.sol.r_x,
                omega_after=plan.sol.u_after[2],
                v_after=[float(v) for v in plan.sol.u_after[:2]],
            )

    def _to_close(self) -> None:
        self.step = self.n_steps + 1
        self.phase = "close"

    def _refine(self, t: float, est: StickEstimate, old: ContactPlan) -> None:
        """Re-solve the committed crossing and finger (``old``, the plan in force) with the new
        estimate; keep the old plan when the refined one does not work."""
        options = self._contacts(est, old.index)
        ox, oy = sc.normal(old.sol.theta, old.sol.side)
        for sol in options:
            nx, ny = sc.normal(sol.theta, sol.side)
            if nx * ox + ny * oy <= 0.0:
                continue  # the other face (alpha may jump by pi: compare n)
            clamped = self._clamp(sol)
            if clamped is None:
                return
            sol, raw = clamped
            crossings = self.planner.crossings(t, est, sol.theta, keep_past=True)
            if not crossings:
                return
            t_c = min(crossings, key=lambda tc: abs(tc - old.t))
            if abs(est.omega) > 1e-6 and abs(t_c - old.t) > 0.5 * math.pi / abs(est.omega):
                return  # not the same crossing any more
            if self._plan_holds(old, est, sol, t_c):
                return  # the new measurement does not change the plan
            plan = self.planner.reach(
                self.step,
                t,
                est,
                sol,
                raw,
                t_c,
                (old.finger,),
                True,
                Shortfall(),
                bases=[old.config.base],
            )
            if plan is None:  # the spot moved out of reach from the old base
                plan = self.planner.reach(
                    self.step, t, est, sol, raw, t_c, (old.finger,), True, Shortfall()
                )
            if plan is not None:
                self.plan = plan
            return

    def _plan_holds(
        self, old: ContactPlan, est: StickEstimate, sol: sc.ContactSolution, t_c: float
    ) -> bool:
        """The refined contact (``sol`` at ``t_c``) is the committed one within the tolerances:
        fingertip spot within ``replan_tol``, the stick's orientation at the committed time within
        ``replan_theta`` of the contact's, the time within ``replan_dt``."""
        p = self.params
        dt = abs(t_c - old.t)
        if dt > p.replan_dt or abs(est.omega) * dt > p.replan_theta:
            return False
        tx, ty = self.planner.tip_at(est, sol, t_c)
        return math.hypot(tx - old.tip[0], ty - old.tip[1]) <= p.replan_tol

    # -- closing (eqs. 32, 33, 38) --------------------------------------------------------------
    def _plan_close(self, t: float, est: StickEstimate) -> None:
        shortfall = Shortfall()
        close = self.closing.plan(
            t, est, self.last_finger, self.step, len(self.est.breaks), shortfall
        )
        if close is not None:
            self.close = close
            self._lost = None
            self._events.append(Occurrence("plan", close.intent(self.stick.width)))
            return
        # the closing has no discrete chances: report once it failed for close_retry
        p = self.params
        self._lost_chance(t, t + p.close_retry if self._lost is None else self._lost[0], shortfall)

    # -- commands and capture -------------------------------------------------------------------
    def _command(self, t: float) -> None:
        if self.phase == "approach" and self.plan is not None:
            self.model.target = self.plan.target(t)
            if t >= self.plan.t - self.params.freeze:
                self._report_clamp(self.plan)
        elif self.phase in ("close", "captured") and self.close is not None:
            if self.phase == "close":
                self.model.target = self.closing.command(t, self.close, self.est)

    def _between_tips(self, t: float, est: StickEstimate) -> bool:
        """Both modelled fingertips at the estimated stick's two faces (between its ends)."""
        p, st, hand = self.params, self.stick, self.hand
        x, y, th = est.at(t)
        cs, sn = math.cos(th), math.sin(th)
        sides = []
        for k in (0, 1):
            d = self.model.config.tip(hand, k) - np.array([x, y])
            xb, yb = d[0] * cs + d[1] * sn, -d[0] * sn + d[1] * cs
            at = (
                abs(xb) <= 0.5 * st.length
                and abs(yb) <= 0.5 * st.width + hand.tip_radius + p.grip_clearance + 0.003
            )
            sides.append(yb if at else 0.0)
        return sides[0] * sides[1] < 0.0

    def _check_capture(self, t: float) -> None:
        if self.phase != "close" or self.close is None or not self.est.ready():
            return
        p, hand = self.params, self.hand
        est = self.est.current()
        x, y, th = est.at(t)
        ok = (
            est.speed < p.capture_speed
            and abs(est.omega) < p.capture_spin
            and self._between_tips(t, est)
        )
        if not ok:
            self._capture_since = None
            return
        if self._capture_since is None:
            self._capture_since = t
        if t - self._capture_since >= p.capture_hold and not self.captured:
            self.captured = True
            self._t_capture = float(self._capture_since)
            self.phase = "captured"
            self._events.append(
                Occurrence(
                    "capture",
                    {
                        "t_since": float(self._capture_since),
                        "speed": float(est.speed),
                        "omega": float(est.omega),
                        "x": float(x),
                        "y": float(y),
                        "theta": float(th),
                        "tips": [
                            [float(v) for v in self.model.config.tip(hand, k)] for k in (0, 1)
                        ],
                    },
                )
            )

    # -- set-up -----------------------------------------------------------------------------------
    def _home(self) -> Config:
        """Where the hand was homed at t = 0 (the spec says; the method has no hand feedback
        after that and tracks its own commands)."""
        hand = self.hand
        return Config(tuple(hand.start_base), tuple(tuple(q) for q in hand.start_joints))
