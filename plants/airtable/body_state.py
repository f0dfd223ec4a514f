"""The stick's and the two fingertips' state, read and written once a physics step through
Pymunk's public API (``Body.position``, ``velocity``, ``angle``, ``angular_velocity``).

:class:`TableIO` does a step's whole input/output: the hand's servo step, each tip's velocity
set to (target - position) / dt (so the engine's position integration lands it on the target),
the engine step, and the state after it.
"""

from __future__ import annotations

from array import array
from typing import Callable

import pymunk

from plants.airtable.hand import HandServo


class TableIO:
    """``state`` holds (x, y, vx, vy, angle, omega) of the stick and the tips' (x, y) as last
    read."""

    def __init__(self, stick: pymunk.Body, tips: list[pymunk.Body]) -> None:
        self.state = array("d", [0.0] * 10)
        self._stick = stick
        self._tips = tuple(tips)
        self.read()

    def read(self) -> None:
        b, s = self._stick, self.state
        (s[0], s[1]), (s[2], s[3]) = b.position, b.velocity
        s[4], s[5] = b.angle, b.angular_velocity
        (s[6], s[7]), (s[8], s[9]) = self._tips[0].position, self._tips[1].position

    def step(self, tips, dt: float, space_step: Callable[[float], None]) -> None:
        """Each tip's velocity toward its target (``tips``: ((x, y), (x, y))), then
        ``space_step(dt)`` (the engine, called as given: what times or wraps ``space.step``
        sees every step), then :meth:`read`."""
        s = self.state
        for k, (body, (tx, ty)) in enumerate(zip(self._tips, tips)):
            body.velocity = ((tx - s[6 + 2 * k]) / dt, (ty - s[7 + 2 * k]) / dt)
        space_step(dt)
        self.read()

    def step_hand(self, hand: HandServo, dt: float, space_step: Callable[[float], None]) -> None:
        """The hand servo's step (``hand.advance(dt)``), then :meth:`step` to its tips."""
        hand.advance(dt)
        self.step(hand.tip_list(), dt, space_step)
