"""The air table of Higashimori et al. 2007 (Sec. IV-A) in Pymunk: a free stick and two fingertips.

- The stick is a dynamic body with the paper's m and I set explicitly (not from shape density).
  It collides as a segment (``collision_width`` = 0, Assumption 5) or as a box. No gravity in
  the plane, no damping, no table friction (the table blows air).
- The fingertips are kinematic discs, position-commanded through the rate-limited servo of the
  slider base and the finger joints: each step the tip's velocity is set so that Pymunk's
  position integration lands it on the forward kinematics, so the contact solver sees the real
  fingertip velocity. Finger links do not collide (Assumption 9).
- Stick/fingertip contacts use Newton's restitution e and Coulomb friction mu (Chipmunk combines
  the two shapes' values by product; the fingertip's are 1, so the pair gets exactly e and mu).

Chipmunk2D facts this relies on (read in Munk2D's cpSpaceStep.c/cpArbiter.c, the engine of
Pymunk 7, and checked by tests/plants/airtable/test_airtable_plant.py):
positions are integrated at the start of a step, contacts are then detected at the new
positions and velocities solved; restitution is a per-contact "bounce" target computed from the
velocity before the solve; on later steps of a persisting contact the bounce target asks for an
approaching velocity, which the non-negative normal impulse cannot produce, so the collision
impulse is applied once (the previous step's impulse is re-applied as a warm start and the
solver's first iteration takes it back out, leaving ~1e-17 m/s). Penetration is removed by a separate bias velocity that moves positions
only.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pymunk

from replay.robot.hand2d import AirTableSpec, HandCommand
from replay.interfaces import Occurrence, Plant
from replay.messages import (
    TOPIC_FINGERS_STATE,
    TOPIC_HAND_STATE,
    TOPIC_STICK_STATE,
    FingersState,
    StickState,
)
from replay.scene import Box, Cylinder, Scene
from replay.spatial import yaw_quaternion

from plants.airtable import body_state, settings, throw
from plants.airtable.hand import HandServo
from plants.airtable.params import Params as AirTableParams

STICK_TYPE = 1
TIP_TYPE = 2
_TIP_GROUP = 1  # fingertips never collide with each other


def _vec(v) -> list[float]:
    return [float(v[0]), float(v[1])]


def _space(solver) -> pymunk.Space:
    """A Pymunk space without gravity, damping or sleep, with ``solver``'s settings."""
    space = pymunk.Space()
    space.gravity = (0.0, 0.0)
    space.damping = 1.0  # no velocity damping
    space.iterations = int(solver.iterations)
    space.collision_slop = float(solver.collision_slop)
    space.collision_bias = float(solver.collision_bias)
    space.sleep_time_threshold = math.inf  # bodies never sleep
    return space


class AirTablePlant(Plant):
    """Stick on an air table and a two-fingered hand on an XY slider (Pymunk)."""

    Params = AirTableParams
    spec_type = AirTableSpec
    command_types = (HandCommand,)
    description = (
        "Pymunk air table: a free stick (no table friction) and two position-"
        "commanded fingertip discs on an XY slider hand (Higashimori et al. 2007)"
    )

    def __init__(
        self,
        params: AirTableParams | None = None,
        *,
        dt: float,
        rng: np.random.Generator | None = None,
    ) -> None:
        params = params if params is not None else AirTableParams()
        super().__init__(params, dt=dt, rng=rng if rng is not None else np.random.default_rng(0))
        if not dt > 0:
            raise ValueError(f"dt must be > 0, got {dt}")
        p = params
        self._events: list[Occurrence] = []
        self._hand_spec = settings.hand_spec(p)
        self.hand = HandServo(self._hand_spec, p.hand.base, [p.hand.joints0, p.hand.joints1])

        self.space = _space(p.solver)
        self._add_stick(p.stick)
        self._add_tips(p.hand.tip_radius)
        self.space.on_collision(TIP_TYPE, STICK_TYPE, begin=self._on_begin)

        self._steps = 0
        self._pending: list[dict] = []
        self._last_command: tuple | None = None
        self._last_object: HandCommand | None = None
        self._rest_since: float | None = None
        self._rest_reported = False
        self._nan_reported = False
        self._collisions = 0
        self._held_since: float | None = None  # the stick held between the tips since
        self._io = body_state.TableIO(self.stick_body, self.tip_bodies)
        self._rest_speed, self._rest_omega = p.rest_speed, p.rest_omega
        self._hold_speed, self._hold_omega = p.hold_speed, p.hold_omega
        self._read_state()
        self._reached = self._in_reach()  # the stick ever within the hand's reach
        # scene(): the boxes' centre heights and sizes, and the fingertips' last primitives
        marker_h, st = 0.0005, p.stick
        self._box_shapes = (
            (st.thickness / 2.0, (st.length, st.visual_width, st.thickness)),
            (st.thickness + marker_h / 2.0, (st.marker_length, st.marker_width, marker_h)),
        )
        self._tip_prims: list[Cylinder | None] = [None, None]

    def _add_stick(self, st) -> None:
        """The stick (``st``: its params) at its initial state: m and I set on the body; its
        shape (a segment, or a box of the collision width) has no mass or density."""
        body = pymunk.Body(st.mass, st.inertia, body_type=pymunk.Body.DYNAMIC)
        init = self._initial_state()
        body.position = (init["x"], init["y"])
        body.angle = init["theta"]
        body.velocity = (init["vx"], init["vy"])
        body.angular_velocity = init["omega"]
        half = st.length / 2.0
        shape: pymunk.Shape
        if st.collision_width > 0.0:
            shape = pymunk.Poly.create_box(body, (st.length, st.collision_width), radius=0.0)
        else:
            shape = pymunk.Segment(body, (-half, 0.0), (half, 0.0), 0.0)
        shape.elasticity = st.restitution
        shape.friction = st.friction
        shape.collision_type = STICK_TYPE
        self.space.add(body, shape)
        self.stick_body, self.stick_shape = body, shape
        if body.mass != st.mass or body.moment != st.inertia:  # pragma: no cover - guard
            raise RuntimeError("Pymunk changed the stick's mass or inertia")

    def _add_tips(self, radius: float) -> None:
        """The fingertips: kinematic discs (infinite mass, Assumption 8) at the hand's tips."""
        self.tip_bodies: list[pymunk.Body] = []
        self.tip_shapes: list[pymunk.Shape] = []  # discs, found by the arbiter's shapes
        for tip in self.hand.tips():
            tb = pymunk.Body(body_type=pymunk.Body.KINEMATIC)
            tb.position = (float(tip[0]), float(tip[1]))
            ts = pymunk.Circle(tb, radius)
            ts.elasticity = 1.0  # pair restitution = e * 1
            ts.friction = 1.0  # pair friction = mu * 1
            ts.collision_type = TIP_TYPE
            ts.filter = pymunk.ShapeFilter(group=_TIP_GROUP)
            self.space.add(tb, ts)
            self.tip_bodies.append(tb)
            self.tip_shapes.append(ts)

    def _initial_state(self) -> dict[str, float]:
        """``initial``, or a seeded random throw (``throw.random``), said in a ``throw`` event."""
        p = self.params
        if not p.throw.random:
            return {
                k: float(getattr(p.initial, k)) for k in ("x", "y", "theta", "vx", "vy", "omega")
            }
        state = throw.draw(self.rng, p.throw)
        self._events.append(
            Occurrence("throw", {**state, "speed": math.hypot(state["vx"], state["vy"])})
        )
        return state

    # -- Plant interface ------------------------------------------------------------------

    @property
    def time(self) -> float:
        """Simulated time of this plant (steps * dt)."""
        return self._steps * self.dt

    def apply(self, command: HandCommand) -> None:
        if command is self._last_object:
            return  # the same (frozen) command object again
        self._last_object = command
        key = (tuple(map(float, command.base)), tuple(tuple(map(float, q)) for q in command.joints))
        if key == self._last_command:
            return  # the same target again: nothing new to clamp or report
        self._last_command = key
        clamped = self.hand.set_targets(command.base, command.joints)
        if clamped is not None:
            self._events.append(Occurrence("limit", clamped))

    def step(self) -> None:
        io = self._io
        # Hand: rate-limited servo, then tip velocities that integrate onto the kinematics, the
        # engine's step and the state after it (TableIO.step_hand) (a collision's velocity
        # before is read in _on_begin, during the engine's step)
        io.step_hand(self.hand, self.dt, self.space.step)
        self._steps += 1
        if self._pending:
            _, _, vx, vy, _, omega = io.state[:6]
            for c in self._pending:
                c["v_after"], c["omega_after"] = [vx, vy], omega
                self._events.append(Occurrence("collision", c))
            self._collisions += len(self._pending)
            self._pending = []
        # the checks' usual case in line (a finite stick moving too fast to rest or be held);
        # anything else is _check_state's and _check_held's
        x, y, vx, vy, angle, omega, t0x, t0y, t1x, t1y = io.state
        speed, spin = math.hypot(vx, vy), abs(omega)
        if math.isfinite(x + y + angle + vx + vy + omega + t0x + t0y + t1x + t1y) and not (
            speed < self._rest_speed and spin < self._rest_omega
        ):
            self._rest_since = None
            self._rest_reported = False  # moving: a later rest is a new event
        else:
            self._check_state()
        if not self._reached:
            self._reached = self._in_reach()
        if speed >= self._hold_speed or spin >= self._hold_omega:
            self._held_since = None  # (not _held)
        else:
            self._check_held()

    def invalidate_state(self) -> None:
        """Re-read the bodies after the space was changed other than by :meth:`step` (the state is
        read once a step; as the arm plant's ``invalidate_state``)."""
        self._read_state()

    def _read_state(self) -> None:
        """The stick's and the tips' state, read from Pymunk (once a step: by the step itself)."""
        self._io.read()

    @property
    def _state(self) -> tuple:
        """((x, y), (vx, vy), angle, omega) of the stick as last read."""
        x, y, vx, vy, angle, omega = self._io.state[:6]
        return (x, y), (vx, vy), angle, omega

    @property
    def _tip_pos(self) -> list[tuple[float, float]]:
        """The fingertips' [(x, y), (x, y)] as last read."""
        t0x, t0y, t1x, t1y = self._io.state[6:]
        return [(t0x, t0y), (t1x, t1y)]

    def _on_begin(self, arbiter: pymunk.Arbiter, space: pymunk.Space, data: Any) -> None:
        """A fingertip started touching the stick (called after position integration, before
        the velocity solve: the stick's pose is that of the contact, its velocity the one before)."""
        sa, sb = arbiter.shapes
        cps = arbiter.contact_point_set
        normal = np.array(cps.normal, dtype=float)  # from shape a to shape b
        if sa is self.stick_shape:
            tip_shape = sb
            normal = -normal
            pts = [np.array(pt.point_a, dtype=float) for pt in cps.points]
        else:
            tip_shape = sa
            pts = [np.array(pt.point_b, dtype=float) for pt in cps.points]
        if not pts:
            return
        finger = self.tip_shapes.index(tip_shape)
        contact = np.mean(pts, axis=0)
        b = self.stick_body
        theta = float(b.angle)
        c, s = math.cos(theta), math.sin(theta)
        d = contact - np.array(b.position, dtype=float)
        r_x, r_y = c * d[0] + s * d[1], -s * d[0] + c * d[1]  # R_B(theta)^T d
        # before the velocity solve (and Chipmunk's velocity integration, which with no gravity,
        # damping 1 and no forces changes nothing): the velocity the stick came in with
        vx, vy = b.velocity
        v_before, w_before = [vx, vy], b.angular_velocity
        self._pending.append(
            {
                "finger": finger,
                "r_x": float(r_x),
                "r_y": float(r_y),
                "theta": theta,
                "v_before": v_before,
                "omega_before": w_before,
                "contact": _vec(contact),
                "normal": _vec(normal),
                "penetration": float(-min(pt.distance for pt in cps.points)),
                "tip_velocity": _vec(self.tip_bodies[finger].velocity),
            }
        )

    def _check_state(self) -> None:
        (x, y), (vx, vy), angle, omega = self._state
        (t0x, t0y), (t1x, t1y) = self._tip_pos
        if not math.isfinite(x + y + angle + vx + vy + omega + t0x + t0y + t1x + t1y):
            values = {"x": x, "y": y, "theta": angle, "vx": vx, "vy": vy, "omega": omega}
            for k, (tx, ty) in enumerate(self._tip_pos):
                values[f"tip{k}_x"], values[f"tip{k}_y"] = tx, ty
            bad = sorted(k for k, v in values.items() if not math.isfinite(v))
            if bad:  # (else a finite sum overflowed)
                if not self._nan_reported:
                    self._nan_reported = True
                    self._events.append(Occurrence("nan", {"fields": bad, "step": self._steps}))
                return
        t = self.time
        slow = math.hypot(vx, vy) < self.params.rest_speed and abs(omega) < self.params.rest_omega
        if not slow:
            self._rest_since = None
            self._rest_reported = False  # moving again: a later rest is a new event
            return
        if self._rest_since is None:
            self._rest_since = t
        if not self._rest_reported and t - self._rest_since >= self.params.rest_time - 1e-12:
            self._rest_reported = True
            self._events.append(
                Occurrence(
                    "rest",
                    {
                        "since": self._rest_since,
                        "x": x,
                        "y": y,
                        "theta": angle,
                        "speed": math.hypot(vx, vy),
                        "omega": omega,
                    },
                )
            )

    def _in_reach(self) -> bool:
        """The stick's centre within finger reach (l1 + l2, joint limits ignored) plus L/2 of a
        finger root anywhere on the slider's range: a loose, purely geometric bound."""
        return settings.in_reach(self._hand_spec, self.params.stick.length, self._state[0])

    def _held(self) -> bool:
        """Slow (``hold_speed``, ``hold_omega``) with a fingertip at each face: between the
        stick's ends and within W/2 + tip_radius + ``hold_gap`` of its axis, on opposite sides."""
        p = self.params
        (x, y), (vx, vy), angle, omega = self._state
        if math.hypot(vx, vy) >= p.hold_speed or abs(omega) >= p.hold_omega:
            return False
        c, s = math.cos(angle), math.sin(angle)
        reach_y = 0.5 * p.stick.collision_width + p.hand.tip_radius + p.hold_gap
        sides = []
        for tx, ty in self._tip_pos:
            dx, dy = tx - x, ty - y
            xb, yb = c * dx + s * dy, -s * dx + c * dy
            if abs(xb) > 0.5 * p.stick.length or abs(yb) > reach_y:
                return False
            sides.append(yb)
        return sides[0] * sides[1] < 0.0

    def _check_held(self) -> None:
        self._reached = self._reached or self._in_reach()
        if self._held():
            if self._held_since is None:
                self._held_since = self.time
        else:
            self._held_since = None

    def outcome(self, t: float) -> dict:
        """Captured: the stick held between the fingertips (``_held``) for the last
        ``hold_time`` of the run; ``t_capture`` = since when: the run's capture time, the one
        the claims and sweeps read (the method's ``t_capture_method`` and ``capture`` event are
        its own, later, belief; docs/stick.md). Else why not, physically."""
        p, b = self.params, self.stick_body
        speed, omega = math.hypot(b.velocity.x, b.velocity.y), float(b.angular_velocity)
        held = self._held_since is not None and t - self._held_since >= p.hold_time - 1e-12
        out = {
            "success": held,
            "reason": "captured",
            "captured": held,
            "t_capture": self._held_since if held else None,
            "speed": speed,
            "omega": omega,
            "collisions": self._collisions,
            "x": float(b.position.x),
            "y": float(b.position.y),
            "theta": float(b.angle),
        }
        if held:
            return out
        if not math.isfinite(speed + omega):
            out["reason"] = "not captured: the simulation diverged"
            out["speed"] = out["omega"] = None
        elif not self._reached:
            out["reason"] = "not captured: the stick never came within the hand's reach"
        elif self._held_since is not None:
            out["reason"] = (
                f"not captured: held between the fingertips only for the last "
                f"{t - self._held_since:.3f} s (< {p.hold_time:g} s)"
            )
        elif speed >= p.hold_speed or abs(omega) >= p.hold_omega:
            where = "" if self._in_reach() else ", out of the hand's reach"
            out["reason"] = (
                f"not captured: the stick still moves ({speed:.3f} m/s, {omega:.2f} rad/s{where})"
            )
        else:
            out["reason"] = "not captured: the stick stopped but not between the fingertips"
        return out

    def pop_events(self) -> list[Occurrence]:
        out, self._events = self._events, []
        return out

    def truth(self, t: float) -> dict[str, Any]:
        x, y, vx, vy, angle, omega, t0x, t0y, t1x, t1y = self._io.state  # (= _state, _tip_pos)
        base, joints, base_target, joint_targets = self.hand.state_lists()
        return {
            TOPIC_STICK_STATE: StickState(t, x, y, angle, vx, vy, omega),
            TOPIC_FINGERS_STATE: FingersState(t, [[t0x, t0y], [t1x, t1y]]),
            TOPIC_HAND_STATE: {
                "t": t,
                "base": base,
                "joints": joints,
                "base_target": base_target,
                "joint_targets": joint_targets,
            },
        }

    def scene(self) -> Scene:
        x, y, _, _, th, _, t0x, t0y, t1x, t1y = self._io.state
        q = yaw_quaternion(th)
        (stick_z, stick_size), (marker_z, marker_size) = self._box_shapes
        prims: list = [
            Box("stick", (x, y, stick_z), q, stick_size, albedo=0.3),
            Box("marker", (x, y, marker_z), q, marker_size, albedo=1.0),
        ]
        tips = self._tip_prims
        for k, (tx, ty) in enumerate(((t0x, t0y), (t1x, t1y))):
            tip = tips[k]
            if tip is None or tip.position[0] != tx or tip.position[1] != ty:
                h = self.params.hand
                tip = tips[k] = Cylinder(
                    f"tip{k}",
                    (tx, ty, h.tip_height / 2.0),
                    (0.0, 0.0, 0.0, 1.0),
                    h.tip_radius,
                    h.tip_height,
                    albedo=0.1,
                )
            prims.append(tip)  # (the last one made while the tip has not moved: frozen)
        return Scene(prims)

    def spec(self) -> AirTableSpec:
        return settings.spec(self.params, self._hand_spec)  # nominal: no friction

    def close(self) -> None:
        self._pending = []
