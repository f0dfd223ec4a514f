"""A Pymunk space whose step costs only the engine's step when there is no bookkeeping to do.

``pymunk.Space.step`` (Pymunk 7) wraps Chipmunk's ``cpSpaceStep`` with bookkeeping for bodies
added since the last step, objects added or removed from inside collision callbacks and
post-step callbacks: ~1 us a step of Python even when all of it is empty, as it always is on
the air table (its bodies are made once; its collision callback only records). :class:`LeanSpace`
calls the engine directly when nothing is pending (Pymunk's own step otherwise: the same engine
call); its collision callbacks must not add or remove objects or schedule post-step callbacks
(an error, raised after the step).
"""

from __future__ import annotations

import pymunk

try:  # Pymunk 7's own cffi binding of Chipmunk
    from pymunk._chipmunk_cffi import lib as _cp
except ImportError:  # pragma: no cover - another Pymunk layout
    _cp = None


class LeanSpace(pymunk.Space):
    def step(self, dt: float) -> None:
        if (
            _cp is None
            or self.threaded
            or self._bodies_to_check
            or self._add_later
            or self._remove_later
            or self._post_step_callbacks
        ):
            super().step(dt)
            return
        try:
            self._locked = True
            _cp.cpSpaceStep(self._space, dt)
            self._removed_shapes.clear()
        finally:
            self._locked = False
        if self._add_later or self._remove_later or self._post_step_callbacks:
            raise RuntimeError("LeanSpace: a collision callback changed the space during a step")
