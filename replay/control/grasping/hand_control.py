"""Grasping control of the hand (Namiki et al. 1999, Sec. 4.3, eq. 4) and preshaping:

    theta_dot_d^h = K^hg (theta_d^h - theta^h) - K^hv theta_dot^h + K^hf F^h          (4)

- F^h (N m): the load on each joint (tared by the first reading: the fingers' own weight), minus
  the strain gauge's actuator torque (the gauge reads
  the torque the drive puts on the joint; the object pushes back with its opposite). At rest
  against an object eq. 4 balances at F^h = -(K^hg / K^hf) (theta_d - theta): the grip torque
  grows with how far theta_d^h closes past the contact, a compliance.
- theta_d^h = preshape + c (grip - preshape): ``c`` (0..1) follows the reaching motion x_d^a
  (the schedule's reach progress: from ``close_from`` to the grasp position it closes to the
  touch posture, where the fingers clear the measured width by ``touch_clearance``, arriving
  as x_d^a comes to rest; in the hold it is the grip posture, closed at most ``touch_speed``
  per joint, so the fingers meet the object gently; opened on release). Preshape and grip postures are chosen by the recognised shape
  (Fig. 5(b)): a rectangle gets straight fingers side by side (a flat hand, closing like a
  parallel gripper on the box's faces), a circle a cupped hand: the fingers opened wide at the
  knuckle and curled at their distal joints, the index and ring turned in towards the middle
  finger, wrapping the ball. Before the shape is known the hand stays open.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from replay.control.grasping.gain_rule import check_period, direct_gain, scale
from replay.control.grasping.payloads import HandLoop
from replay.interfaces import Controller, Occurrence
from replay.messages import (
    TOPIC_GRASP_HAND,
    TOPIC_GRASP_OBJECT,
    TOPIC_GRASP_STATE,
    TOPIC_HAND_ENCODERS,
    TOPIC_HAND_TORQUE,
)
from replay.params import param
from replay.robot.arm_types import GraspSpec, ServoCommand

# GRASP4 joint order: index (abduct, flex x3), middle (flex x3), ring (abduct, flex x3),
# thumb (flex x3). Assumed postures (rad), none from the paper.
_RECT_PRE = [0.0, 0.0, 0.05, 0.05, 0.0, 0.05, 0.05, 0.0, 0.0, 0.05, 0.05, 0.0, 0.05, 0.05]
_RECT_GRIP = [0.0, 1.10, 0.80, 0.60, 1.10, 0.80, 0.60, 0.0, 1.10, 0.80, 0.60, 1.10, 0.80, 0.60]
_CIRC_PRE = [
    -0.10,
    -0.15,
    0.20,
    0.20,
    -0.15,
    0.20,
    0.20,
    0.10,
    -0.15,
    0.20,
    0.20,
    -0.15,
    0.20,
    0.20,
]
_CIRC_GRIP = [-0.20, 1.20, 0.90, 0.80, 1.20, 0.90, 0.80, 0.20, 1.20, 0.90, 0.80, 1.20, 0.90, 0.80]


def eq4_step(pre, grip, c, q, qd, load, K_hg, K_hv, K_hf, vmax):
    """(theta_d^h, eq. 4's command clipped to +-vmax, max |theta_d^h - theta^h|) in floats, the
    task's per-step path (``grip`` None: theta_d^h = ``pre``)."""
    theta_d = list(pre) if grip is None else [p + c * (g - p) for p, g in zip(pre, grip)]
    cmd = [K_hg * (td - x) - K_hv * v + K_hf * f for td, x, v, f in zip(theta_d, q, qd, load)]
    cmd = [vmax if x > vmax else (-vmax if x < -vmax else x) for x in cmd]  # np.clip's
    return theta_d, cmd, max(abs(td - x) for td, x in zip(theta_d, q))


def lowpass_step(load, torque, a) -> list[float]:
    """F^h (minus the drive's torque) first-order low-passed with gain ``a``: x + a (-tau - x)
    per joint."""
    return [x + a * (-t - x) for x, t in zip(load, torque)]


@dataclass
class HandParams:
    K_hg: float = param(25.0, unit="1/s", ge=0.0, doc="eq. 4's K^hg (scalar times I, assumed)")
    K_hv: float = param(0.02, unit="1", ge=0.0, doc="eq. 4's K^hv (scalar times I)")
    K_hf: float = param(
        10.0,
        unit="rad/(s*N*m)",
        ge=0.0,
        doc="eq. 4's K^hf (scalar times I): grip torque = K^hg/K^hf x overclosure",
    )
    rectangle_preshape: list = param(
        _RECT_PRE, unit="rad", length=14, doc="theta_d^h before closing on a rectangle (assumed)"
    )
    rectangle_grip: list = param(
        _RECT_GRIP,
        unit="rad",
        length=14,
        doc="theta_d^h fully closed on a rectangle (past the contact)",
    )
    circle_preshape: list = param(
        _CIRC_PRE, unit="rad", length=14, doc="theta_d^h before closing on a circle: a cupped hand"
    )
    circle_grip: list = param(
        _CIRC_GRIP, unit="rad", length=14, doc="theta_d^h fully closed on a circle"
    )
    close_from: float = param(
        0.7,
        unit="1",
        ge=0.0,
        lt=1.0,
        doc="reach progress (x_d^a) from which theta_d^h closes towards the touch posture "
        "(closing to the full grip from 0.8 shoved the ball off its plane before the palm was "
        "there; to the touch it stays clear of the measured width)",
    )
    load_filter: float = param(
        0.005,
        unit="s",
        ge=0.0,
        doc="time constant of the first-order low-pass on F^h: the gauge "
        "reads the drive's own torque, so unfiltered feedback through "
        "a stiff servo chatters",
    )
    aperture_margin: float = param(
        0.02,
        unit="m",
        ge=0.0,
        doc="preshape aperture: the thumb's and fingers' tips this far clear of the object's "
        "measured width on each side (the vision chip's pixel is ~1 cm at the object; assumed)",
    )
    touch_clearance: float = param(
        0.005,
        unit="m",
        ge=0.0,
        doc="the reach closes theta_d^h only to where the fingers clear the measured width by "
        "this much on each side (the touch posture), arriving as x_d^a comes to rest; the hold "
        "then closes on to the grip posture (assumed)",
    )
    touch_speed: float = param(
        4.0,
        unit="rad/s",
        gt=0.0,
        doc="in the hold each hand joint closes at most this fast (eq. 4's command clipped): "
        "the last clearance is crossed slowly, so the fingers meet the object gently (assumed)",
    )
    free_closure: float = param(
        0.1,
        unit="rad",
        gt=0.0,
        doc="a hold phase in which every finger reaches its grip posture "
        "within this closed on nothing (a missed grasp): an object "
        "stops them ~0.4 rad short",
    )
    gain_period: float = param(
        0.0,
        unit="s",
        ge=0.0,
        omit_empty=True,
        doc="the gain rule: 0 keeps K^hg, K^hf as given (tuned for 1 ms loops); a period T (s, "
        "the task's 1 / rate) re-designs K^hg for it, the 1 ms loop's pole kept "
        "(gain_rule.direct_gain), and scales K^hf alike (the grip's K^hg / K^hf kept)",
    )


class HandControlTask(Controller):
    """Eq. 4: hand compliance control with joint-torque feedback, preshaped by the shape."""

    Params = HandParams
    spec_type = GraspSpec
    command_type = ServoCommand
    reads = (TOPIC_HAND_ENCODERS, TOPIC_HAND_TORQUE, TOPIC_GRASP_OBJECT, TOPIC_GRASP_STATE)
    description = "eq. 4: hand compliance control with joint torque feedback; preshaping"

    def __init__(self, params: HandParams, *, spec: GraspSpec) -> None:
        super().__init__(params, spec=spec)
        hand = spec.hand
        if hand is None:
            raise ValueError("hand control needs a plant with a hand")
        n = hand.n
        if n != 14:
            raise ValueError(f"the grasping hand has 14 joints, this plant's has {n}")
        self.postures = {
            "rectangle": (
                np.asarray(params.rectangle_preshape, float),
                np.asarray(params.rectangle_grip, float),
            ),
            "circle": (
                np.asarray(params.circle_preshape, float),
                np.asarray(params.circle_grip, float),
            ),
        }
        self.open = np.asarray(hand.open_posture, float)
        self.lo, self.hi = np.asarray(hand.lower, float), np.asarray(hand.upper, float)
        self.vmax = float(hand.closing_speed)
        # the same in floats, for the per-step loop
        self._postures: dict[str, tuple[list[float], list[float] | None]] = {
            k: (a.tolist(), b.tolist()) for k, (a, b) in self.postures.items()
        }
        self._open = self.open.tolist()
        self.q: list[float] = list(self._open)
        self.qd = [0.0] * n
        self.load = [0.0] * n  # F^h, low-passed (a new list each step: logged as is)
        self._tare: list[float] | None = None
        self.shape = "unknown"
        self.preshape = "none"
        # the aperture: per finger its first flex joint (index in the 14), the half-span of
        # its root's inner face from the palm centre (across the thumb-finger axis) and its
        # length; the measured width (smaller in-plane size) averaged while tracking
        self._flex: list[tuple[int, list[int], float, float]] = []
        self._chains: list[tuple[int, list[int], float, float, float, list]] = []
        self._touch: float | None = None
        k = 0
        for finger in hand.table.fingers:
            idx = list(range(k, k + len(finger.joints)))
            k += len(finger.joints)
            flex = [i for i, j in zip(idx, finger.joints) if j.kind == "flex"]
            half = abs(finger.root[0]) - finger.joints[-1].width / 2.0
            length = sum(j.length for j in finger.joints)
            self._flex.append((flex[0], flex[1:], half, length))
            # the flex chain in the closing plane: the root's distance from the palm centre
            # and each flex link's (length, width), for touch_closure
            links = [(j.length, j.width) for j in finger.joints if j.kind == "flex"]
            self._chains.append((flex[0], flex, half, length, abs(finger.root[0]), links))
        self._width_sum, self._width_n = 0.0, 0
        self.width: float | None = None
        self.dt = spec.dt
        T = params.gain_period  # the gain rule (gain_rule.py): 0 keeps the gains
        self.K_hg = direct_gain(params.K_hg, T) if T > 0.0 else params.K_hg
        self.K_hf = params.K_hf * scale(params.K_hg, T)
        self._t_last: float | None = None
        self.state: Any = None
        self._events: list[Occurrence] = []
        self._out: HandLoop | None = None
        self._holds: dict[int, float] = {}  # cycle -> least closure deficit in its hold
        self._shape_at_grasp: dict[int, str] = {}

    def update(self, t: float, measurements) -> ServoCommand | None:
        for topic, m in measurements:
            if topic == TOPIC_HAND_ENCODERS:
                self.q, self.qd = m.position, m.velocity
            elif topic == TOPIC_HAND_TORQUE:
                # F^h: the load on the joints (minus the drive's torque), low-passed
                a = (
                    1.0
                    if self.params.load_filter <= 0.0
                    else min(1.0, self.dt / (self.params.load_filter + self.dt))
                )
                # the first reading is the tare: the fingers' own weight on the open hand (else
                # eq. 4 balances it by sagging ~0.15 rad off theta_d, closing the aperture)
                if self._tare is None:
                    self._tare = list(m.torque)
                tau = [x - x0 for x, x0 in zip(m.torque, self._tare)]
                self.load = lowpass_step(self.load, tau, a)
            elif topic == TOPIC_GRASP_OBJECT:
                self.shape = m.shape
                if m.found and m.size and self.state is not None and self.state.phase == "track":
                    self._width_sum += min(m.size)
                    self._width_n += 1
                    self.width = self._width_sum / self._width_n
            elif topic == TOPIC_GRASP_STATE:
                self.state = m
        if self._t_last is not None and t > self._t_last:
            self.dt = t - self._t_last
            check_period(self.params.gain_period, self.dt, "hand")
        self._t_last = t
        if self.state is None:
            return None
        st = self.state
        if self.shape in self.postures and (
            st.phase in ("track", "release") or self.preshape == "none"
        ):
            if self.preshape != self.shape:
                self.preshape = self.shape
                self._events.append(Occurrence("preshape", {"shape": self.shape}))
        pre, grip = self._postures.get(self.preshape, (self._open, None))
        P = self.params
        touch = 1.0
        if grip is not None and self.width is not None:
            pre = self.aperture(pre, self.width)
            if st.phase in ("track", "release") or self._touch is None:
                self._touch = self.touch_closure(
                    pre, grip, self.width + 2.0 * P.touch_clearance, self.preshape
                )
            touch = self._touch
        # theta_d^h by the reach (Sec. 4.3): from close_from of x_d^a's progress to the touch,
        # reached as x_d^a comes to rest (its min-jerk progress has zero rate at 1); in the hold
        # the grip posture, closed at most touch_speed
        c = 0.0
        vmax = self.vmax
        if st.phase == "reach":
            f = P.close_from
            c = touch * min(max((st.reach_progress - f) / (1.0 - f), 0.0), 1.0)
        elif st.phase == "hold":
            c = 1.0
            vmax = min(vmax, P.touch_speed)
        theta_d, cmd, deficit = eq4_step(
            pre, grip, c, self.q, self.qd, self.load, self.K_hg, P.K_hv, self.K_hf, vmax
        )
        if st.phase == "hold":
            self._shape_at_grasp.setdefault(st.cycle, self.preshape)
            self._holds[st.cycle] = min(self._holds.get(st.cycle, math.inf), deficit)
        self._out = HandLoop(t, self.preshape, c, theta_d, self.load, cmd)
        return ServoCommand(hand=cmd)

    def aperture(self, pre: list[float], width: float) -> list[float]:
        """The preshape opened for an object ``width`` wide (m): each finger straight, turned
        out at its first flex joint so that its tip clears the object by ``aperture_margin``
        on its side (never closed further than ``pre``), within the joint's limits."""
        out = list(pre)
        need = width / 2.0 + self.params.aperture_margin
        for j1, rest, half, length in self._flex:
            s = min(max((need - half) / length, 0.0), 1.0)
            out[j1] = max(min(-math.asin(s), pre[j1]), float(self.lo[j1]))
            for i in rest:
                out[i] = 0.0
        return out

    def touch_closure(self, pre: list[float], grip: list[float], width: float, shape: str) -> float:
        """The closure c (theta_d^h = pre + c (grip - pre)) at which the first finger's joints
        or tip (on their inner face) meet an object ``width`` wide (the measured size), by bisection over c on each
        finger's flex chain in its closing plane: a rectangle as a slab |d| <= width/2 in front
        of the palm (its depth is not measured), a circle as a disc of diameter ``width`` resting
        on the palm face. 1 if the grip posture never meets it."""
        r = width / 2.0

        def inside(c: float) -> bool:
            for _j1, flex, half, _length, a, links in self._chains:
                phi, u, h = 0.0, 0.0, 0.0  # toward the centre, along the palm normal
                for i, (length, w) in zip(flex, links):
                    phi += pre[i] + c * (grip[i] - pre[i])
                    s, co = math.sin(phi), math.cos(phi)
                    u += length * s
                    h += length * co
                    # the link's end (the next joint, or the tip), on its inner face
                    d = a - (u + 0.5 * w * co)
                    z = h - 0.5 * w * s
                    if shape == "circle":
                        if d * d + (z - r) * (z - r) <= r * r:
                            return True
                    elif abs(d) <= r and z >= 0.0:
                        return True
            return False

        if not inside(1.0):
            return 1.0
        lo, hi = 0.0, 1.0
        for _ in range(20):
            mid = 0.5 * (lo + hi)
            lo, hi = (lo, mid) if inside(mid) else (mid, hi)
        return lo

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_HAND: self._out} if self._out is not None else {}

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict:
        missed = [
            {
                "cycle": c,
                "why": f"the fingers closed on nothing (all within {v:.3f} rad "
                "of their grip posture)",
            }
            for c, v in sorted(self._holds.items())
            if v < self.params.free_closure
        ]
        out: dict[str, Any] = {
            "preshape": self.preshape,
            "preshape_at_grasp": [self._shape_at_grasp[c] for c in sorted(self._shape_at_grasp)],
            "hold_closure_deficit": [self._holds[c] for c in sorted(self._holds)],
            "missed": missed,
        }
        if missed:
            out.update(
                success=False,
                reason=f"missed grasp in cycle {missed[0]['cycle']}: {missed[0]['why']}",
            )
        return out
