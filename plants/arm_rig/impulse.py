"""Scenario-set external impulses on the free object (a disturbance: a kick mid-flight).

Generic physics, no method: ``object_impulses: [[t, Jx, Jy, Jz], ...]`` (s, N*s, world frame)
adds J / m to the object's linear velocity at the first physics step at or after each t, and the
plant reports an ``impulse`` event. A controller is not told; it may only see the consequence.
"""

from __future__ import annotations

import numpy as np


class ImpulseSchedule:
    def __init__(self, entries, dt: float) -> None:
        self.due: dict[int, np.ndarray] = {}  # physics step -> summed impulse (N*s), not yet given
        for e in entries:
            e = [float(x) for x in e]
            if len(e) != 4 or not np.all(np.isfinite(e)) or e[0] < 0.0:
                raise ValueError("object_impulses: each entry is [t >= 0, Jx, Jy, Jz] (s, N*s)")
            k = int(np.ceil(e[0] / dt - 1e-9))
            self.due[k] = self.due.get(k, np.zeros(3)) + np.asarray(e[1:])

    def __bool__(self) -> bool:
        return bool(self.due)

    def pop(self, step: int) -> np.ndarray | None:
        """The summed impulse due at physics step ``step`` (None if there is none)."""
        return self.due.pop(step, None)
