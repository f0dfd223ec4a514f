"""Reading and setting Pymunk body state without Pymunk's per-call ``Vec2d`` objects.

``Body.position`` / ``velocity`` build a ``Vec2d`` on every read (~6 of the ~7 us a read costs);
the air table reads the stick's and both tips' state every physics step, so it goes through the
Chipmunk calls Pymunk itself wraps (``pymunk._chipmunk_cffi.lib``, Pymunk 7). Where that module
is not there, the public properties are used: the same numbers, only slower.

:class:`TableIO` does a step's whole input/output (the tips' velocities, the engine step, the
state after it) in one compiled call (``_bodies.c``), calling those same Chipmunk functions
through the addresses the cffi binding gives; the readers and setter below are its reference
(tests/plants/airtable/test_bodies_kernel.py) and its fallback. :meth:`TableIO.step_hand` also
advances the hand's servo first (``HandServo.advance`` and ``tip_list`` are its reference).
"""

from __future__ import annotations

import functools
from array import array
from typing import Callable

import pymunk

from plants.airtable import _bodies
from plants.airtable.hand import HandServo

try:  # Pymunk 7's own cffi binding of Chipmunk
    from pymunk._chipmunk_cffi import ffi as _ffi, lib as _cp
except ImportError:  # pragma: no cover - another Pymunk layout
    _ffi = _cp = None


def pose_reader(body: pymunk.Body) -> Callable[[], tuple[float, float, float, float, float, float]]:
    """A callable returning ``(x, y, vx, vy, angle, angular_velocity)`` of ``body`` now."""
    if _cp is None or not hasattr(body, "_body"):  # pragma: no cover

        def public() -> tuple[float, float, float, float, float, float]:
            (x, y), (vx, vy) = body.position, body.velocity
            return x, y, vx, vy, body.angle, body.angular_velocity

        return public
    ptr, pos, vel = body._body, _cp.cpBodyGetPosition, _cp.cpBodyGetVelocity
    angle, omega = _cp.cpBodyGetAngle, _cp.cpBodyGetAngularVelocity

    def read() -> tuple[float, float, float, float, float, float]:
        p, v = pos(ptr), vel(ptr)
        return p.x, p.y, v.x, v.y, angle(ptr), omega(ptr)

    return read


def position_reader(body: pymunk.Body) -> Callable[[], tuple[float, float]]:
    """A callable returning ``(x, y)`` of ``body`` now."""
    if _cp is None or not hasattr(body, "_body"):  # pragma: no cover

        def public() -> tuple[float, float]:
            x, y = body.position
            return x, y

        return public
    ptr, pos = body._body, _cp.cpBodyGetPosition

    def read() -> tuple[float, float]:
        p = pos(ptr)
        return p.x, p.y

    return read


def velocity_setter(body: pymunk.Body) -> Callable[[float, float], None]:
    """A callable setting ``body.velocity = (vx, vy)``."""
    if _cp is None or not hasattr(body, "_body"):  # pragma: no cover

        def public(vx: float, vy: float) -> None:
            body.velocity = (vx, vy)

        return public
    ptr, setv = body._body, _cp.cpBodySetVelocity
    return lambda vx, vy: setv(ptr, (vx, vy))


class TableIO:
    """The stick's and two tips' state, read and written once a step.

    ``state`` holds (x, y, vx, vy, angle, omega) of the stick and the tips' (x, y) as last read.
    :meth:`step` sets each tip's velocity to (target - position) / dt (so the engine's position
    integration lands it on the target), runs ``space_step(dt)`` (the engine, called as given:
    what times or wraps ``space.step`` sees every step) and reads the state again."""

    def __init__(
        self, stick: pymunk.Body, tips: list[pymunk.Body], space: pymunk.Space | None = None
    ) -> None:
        self.state = array("d", [0.0] * 10)
        self._ptrs: array | None = None
        self.direct = False  # whether step(space_step=None) may call cpSpaceStep itself
        if _ffi is not None and all(hasattr(b, "_body") for b in (stick, *tips)):

            def address(obj) -> int:
                return int(_ffi.cast("uintptr_t", obj))

            fns = [
                _ffi.addressof(_cp, name)
                for name in (
                    "cpBodyGetPosition",
                    "cpBodyGetVelocity",
                    "cpBodyGetAngle",
                    "cpBodyGetAngularVelocity",
                    "cpBodySetVelocity",
                )
            ]
            bodies = [stick._body, tips[0]._body, tips[1]._body]
            engine = [0, 0]
            if space is not None and not space.threaded and hasattr(space, "_space"):
                engine = [address(_ffi.addressof(_cp, "cpSpaceStep")), address(space._space)]
                self.direct = True
            self._ptrs = array("Q", [address(x) for x in fns + bodies] + engine)
            self._keep = (stick, tips, space)  # the bodies and the space outlive the addresses
        else:  # pragma: no cover - another Pymunk layout
            self._read_stick = pose_reader(stick)
            self._read_tips = [position_reader(tb) for tb in tips]
            self._set_tip_v = [velocity_setter(tb) for tb in tips]
        self.read()

    def __getstate__(self):
        raise TypeError("TableIO holds the bodies' Chipmunk addresses: it cannot be copied")

    def read(self) -> None:
        if self._ptrs is not None:
            _bodies.read(self._ptrs, self.state)
            return
        s = self.state  # pragma: no cover - the fallback
        s[0:6] = array("d", self._read_stick())
        for k, read in enumerate(self._read_tips):
            s[6 + 2 * k : 8 + 2 * k] = array("d", read())

    def step(
        self, tips, dt: float, space_step: Callable[[float], None] | None, limits: tuple
    ) -> bool:
        """One step; True when the state after it is certainly the usual case for ``limits``
        (rest_speed, rest_omega, hold_speed, hold_omega): all finite, too fast to rest or to be
        held (``_bodies.c`` says how; False: the caller's own checks decide). ``space_step``
        None (only when :attr:`direct`): Chipmunk's ``cpSpaceStep`` of the space given, called
        from C, which is :class:`~plants.airtable.lean_space.LeanSpace`'s step when it has no
        bookkeeping to do (the caller knows)."""
        (tx0, ty0), (tx1, ty1) = tips
        if self._ptrs is not None:
            return _bodies.step(self._ptrs, self.state, tx0, ty0, tx1, ty1, dt, space_step, *limits)
        s = self.state  # pragma: no cover - the fallback
        assert space_step is not None  # (direct is False without the addresses)
        for k, (put, tx, ty) in enumerate(zip(self._set_tip_v, (tx0, tx1), (ty0, ty1))):
            put((tx - s[6 + 2 * k]) / dt, (ty - s[7 + 2 * k]) / dt)
        space_step(dt)
        self.read()
        return False

    def step_hand(
        self, hand: HandServo, dt: float, space_step: Callable[[float], None] | None, limits: tuple
    ) -> bool:
        """The hand servo's step (``hand.advance(dt)``, its reference) and then :meth:`step`
        with its tips (``hand.tip_list()``) as the targets, in one compiled call."""
        if self._ptrs is not None:
            return _bodies.step_hand(self._ptrs, self.state, hand.state, dt, space_step, *limits)
        hand.advance(dt)  # pragma: no cover - the fallback
        return self.step(hand.tip_list(), dt, space_step, limits)  # pragma: no cover

    def lean_stepper(self, hand: HandServo, dt: float, limits: tuple) -> Callable[[], bool] | None:
        """``step_hand(hand, dt, None, limits)`` as one callable of no arguments (the compiled
        call with its arguments bound: no Python frame a step), or None when the engine cannot
        be called from C (:attr:`direct` False)."""
        if not self.direct or self._ptrs is None:
            return None
        return functools.partial(
            _bodies.step_hand, self._ptrs, self.state, hand.state, dt, None, *limits
        )
