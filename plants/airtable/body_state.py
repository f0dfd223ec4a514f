"""Reading and setting Pymunk body state without Pymunk's per-call ``Vec2d`` objects.

``Body.position`` / ``velocity`` build a ``Vec2d`` on every read (~6 of the ~7 us a read costs);
the air table reads the stick's and both tips' state every physics step, so it goes through the
Chipmunk calls Pymunk itself wraps (``pymunk._chipmunk_cffi.lib``, Pymunk 7). Where that module
is not there, the public properties are used: the same numbers, only slower.
"""

from __future__ import annotations

from typing import Callable

import pymunk

try:  # Pymunk 7's own cffi binding of Chipmunk
    from pymunk._chipmunk_cffi import lib as _cp
except ImportError:  # pragma: no cover - another Pymunk layout
    _cp = None


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
