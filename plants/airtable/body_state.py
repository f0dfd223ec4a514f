"""The stick's and the two fingertips' state, read and written once a physics step through
Pymunk's public API (``Body.position``, ``velocity``, ``angle``, ``angular_velocity``).

:class:`TableIO` does a step's whole input/output: the hand's servo step, each tip's velocity
set to (target - position) / dt (so the engine's position integration lands it on the target),
the engine step, and the state after it.

Most steps the hand stands still (4,417 of stick_3step's 5,652): a tip's velocity is set only
when it changes (a kinematic body keeps the one it was given), and a tip whose velocity is zero
is not read back (the engine's position step p + v dt leaves it where it was).
"""

from __future__ import annotations

from typing import Callable

import pymunk

from plants.airtable.hand import HandServo

# Body.velocity's own setter, called as a function: the same public property without the
# attribute-typing mixin's __setattr__ that ``body.velocity = v`` goes through (0.51 -> 0.30 us)
_set_velocity = vars(pymunk.Body)["velocity"].fset  # (the property object itself)


class TableIO:
    """``state`` holds (x, y, vx, vy, angle, omega) of the stick and the tips' (x, y) as last
    read."""

    def __init__(self, stick: pymunk.Body, tips: list[pymunk.Body]) -> None:
        # a list, not array("d"): its items are the engine's float objects as read, stored and
        # unpacked without boxing (0.35 us a step less over the ten values)
        self.state: list[float] = [0.0] * 10
        self._stick = stick
        self._tips = tuple(tips)
        self.read()

    def read(self) -> None:
        """Every body's state, read from the engine (also after a change made other than by
        :meth:`step`: the tips' velocities are then set again at the next step)."""
        b, s = self._stick, self.state
        (s[0], s[1]), (s[2], s[3]) = b.position, b.velocity
        s[4], s[5] = b.angle, b.angular_velocity
        (s[6], s[7]), (s[8], s[9]) = self._tips[0].position, self._tips[1].position
        self._tip_v: list[tuple | None] = [None, None]  # the tips' velocities as last set
        # the targets (the same object) and dt of a step that left both tips still on them
        self._still_at: tuple | None = None
        self._still_dt: float | None = None

    def step(self, tips, dt: float, space_step: Callable[[float], None]) -> None:
        """Each tip's velocity toward its target (``tips``: ((x, y), (x, y))), then
        ``space_step(dt)`` (the engine, called as given: what times or wraps ``space.step``
        sees every step), then the state after it."""
        s, set_v = self.state, self._tip_v
        if tips is self._still_at and dt == self._still_dt:
            space_step(dt)  # (the same targets, both tips on them and still: nothing to set)
        else:
            (t0x, t0y), (t1x, t1y) = tips
            tip0, tip1 = self._tips
            v0 = ((t0x - s[6]) / dt, (t0y - s[7]) / dt)
            v1 = ((t1x - s[8]) / dt, (t1y - s[9]) / dt)
            if v0 != set_v[0]:
                _set_velocity(tip0, v0)
                set_v[0] = v0
            if v1 != set_v[1]:
                _set_velocity(tip1, v1)
                set_v[1] = v1
            space_step(dt)
            if v0 != _STILL:
                s[6], s[7] = tip0.position
            if v1 != _STILL:
                s[8], s[9] = tip1.position
            still = v0 == _STILL and v1 == _STILL
            self._still_at, self._still_dt = (tips, dt) if still else (None, None)
        b = self._stick
        (s[0], s[1]), (s[2], s[3]) = b.position, b.velocity
        s[4], s[5] = b.angle, b.angular_velocity

    def step_hand(self, hand: HandServo, dt: float, space_step: Callable[[float], None]) -> None:
        """The hand servo's step (``hand.advance(dt)``), then :meth:`step` to its tips."""
        hand.advance(dt)
        self.step(hand.tip_list(), dt, space_step)


_STILL = (0.0, 0.0)  # a tip's velocity standing still
