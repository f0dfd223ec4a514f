"""The optional shaped reward of an environment (``ScenarioEnv(shaped=True)``): a dense term
from the plant's ground truth after each step, added to the sparse one; never part of the
verdict (the plant's outcome) nor of the observation.

Each step adds ``-d * dt`` (m s): ``d`` the distance the task should close, ``dt`` the step, so
an episode's shaped sum is minus the time integral of ``d`` whatever the control period:

- an arm with a free object (catch, grasp): ``d`` from the tool frame's origin
  (``/effector/motion``) to the object's centre (``/object/state``), m;
- the air table (stick): ``d`` from the midpoint of the two fingertips (``/fingers/state``) to
  the stick's centre (``/stick/state``), in the table's plane, m.
"""

from __future__ import annotations

import math
from typing import Any

from replay.messages import (
    TOPIC_EFFECTOR_MOTION,
    TOPIC_FINGERS_STATE,
    TOPIC_OBJECT_STATE,
    TOPIC_STICK_STATE,
)


def gap(truth: dict[str, Any]) -> float | None:
    """``d`` (m) of the module docstring from a plant's ``truth(t)``; None: no shaping for it."""
    obj, hand = truth.get(TOPIC_OBJECT_STATE), truth.get(TOPIC_EFFECTOR_MOTION)
    if obj is not None and hand is not None:
        return math.dist(obj.position, hand.position)
    stick, fingers = truth.get(TOPIC_STICK_STATE), truth.get(TOPIC_FINGERS_STATE)
    if stick is not None and fingers is not None:
        (ax, ay), (bx, by) = fingers.tips
        return math.hypot(stick.x - (ax + bx) / 2.0, stick.y - (ay + by) / 2.0)
    return None
