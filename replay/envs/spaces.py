"""Observations and actions of a scenario's environment as flat float64 vectors.

**Observations.** For each sensor topic, the newest measurement delivered to the controller (at
its rate and after its latency, as the controller receives it) as one vector: its capture time
``t`` first (-1 before anything was delivered), then every numeric field of the payload in the
dataclass's order, lists flattened (e.g. ``/arm/encoders``: t, position[n], velocity[n],
effort[n]); strings, mappings (a camera's ``features``) and None are left out. A field's length
is its annotation's (``Vec3``: 3) or the sensor's first measurement's, taken once when the
environment is made.

**Actions.** The plant's command as one vector in SI units, its fields in the command's order,
bounded by the plant's limits (:func:`action_layout`); the environment passes it to the plant
unclipped (the plant clamps as its physics says and logs it, as in ``replay run``). A field whose
values are all NaN is left out of the command (None): that actuator keeps its previous command
(the arm's hand targets, the grasping rig's servos; the 2-D hand takes whole commands only); an
action all NaN is no command at all.
"""

from __future__ import annotations

import dataclasses
import typing
from typing import Annotated, Any

import numpy as np

from replay.messages import TOPICS, Length


def numbers(payload: Any) -> list[float]:
    """The numeric fields of a payload (a dataclass or a mapping) in order, lists flattened."""
    items = (
        [getattr(payload, f.name) for f in dataclasses.fields(payload)]
        if dataclasses.is_dataclass(payload)
        else list(payload.values())
        if isinstance(payload, dict)
        else []
    )
    out: list[float] = []
    for v in items:
        _flatten(v, out)
    return out


def _flatten(v: Any, out: list[float]) -> None:
    if isinstance(v, (bool, int, float, np.integer, np.floating)):
        out.append(float(v))
    elif isinstance(v, (list, tuple, np.ndarray)):
        for x in v:
            _flatten(x, out)


def _annotated_length(tp: Any) -> int | None:
    """The fixed number of values of an annotation (a number: 1, ``Vec3``: 3), else None."""
    if tp in (float, int, bool):
        return 1
    origin = typing.get_origin(tp)
    if tp is str or origin is dict or typing.get_args(tp) == (str,):
        return 0  # not a number: left out
    if typing.get_origin(tp) is Annotated:
        for meta in typing.get_args(tp)[1:]:
            if isinstance(meta, Length):
                return meta.n
    return None


def payload_length(topic: str, probe: Any) -> int:
    """How many values a topic's vector holds besides ``t``: the payload class's annotations
    where they fix it, else the ``probe`` measurement's."""
    cls = type(probe) if dataclasses.is_dataclass(probe) else TOPICS.get(topic)
    if cls is not None:
        hints = typing.get_type_hints(cls, include_extras=True)
        fixed = [_annotated_length(tp) for name, tp in hints.items() if name != "t"]
        if all(n is not None for n in fixed) or probe is None:
            if any(n is None for n in fixed):
                raise ValueError(f"{topic}: no measurement at t = 0 to size its fields from")
            return sum(typing.cast(list[int], [n for n in fixed if n is not None]))
    if probe is None:
        raise ValueError(f"{topic}: no measurement at t = 0 and no payload type to size it from")
    return len(numbers(probe)) - 1  # (its t)


@dataclasses.dataclass(frozen=True)
class ActionLayout:
    """The command type, its fields' names and lengths, and the bounds of the flat vector."""

    command: type
    fields: tuple[tuple[str, int], ...]
    low: np.ndarray
    high: np.ndarray
    optional: frozenset[str]  # the fields that may be None (that actuator keeps its command)

    def command_of(self, action: Any) -> Any:
        """The plant's command from an action vector: an all-NaN field None, all of them None
        (no command: the plant keeps the last one)."""
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape[0] != self.low.shape[0]:
            raise ValueError(f"an action has {self.low.shape[0]} values, got {a.shape[0]}")
        kwargs: dict[str, Any] = {}
        i = 0
        for name, n in self.fields:
            part = a[i : i + n]
            i += n
            kwargs[name] = None if n and np.isnan(part).all() else _shaped(self.command, name, part)
        if all(v is None for v in kwargs.values()):
            return None
        missing = [k for k, v in kwargs.items() if v is None and k not in self.optional]
        if missing:
            raise ValueError(
                f"{self.command.__name__}: {', '.join(missing)} cannot be left out (NaN)"
            )
        return self.command(**kwargs)

    def action_of(self, command: Any, previous: np.ndarray | None = None) -> np.ndarray:
        """The action vector of a command (a list: the parallel tasks' partial commands, later
        fields over earlier ones); a None field takes ``previous``'s values, else NaN."""
        out = (
            np.array(previous, dtype=np.float64)
            if previous is not None
            else np.full(self.low.shape, np.nan)
        )
        for c in command if isinstance(command, list) else [command]:
            if c is None:
                continue
            i = 0
            for name, n in self.fields:
                v = getattr(c, name)
                if v is not None:
                    vals: list[float] = []
                    _flatten(v, vals)
                    out[i : i + n] = vals
                i += n
        return out


def _shaped(command: type, name: str, part: np.ndarray) -> Any:
    if command.__name__ == "HandCommand":  # tuples as the 2-D hand's (frozen) command holds
        return (
            (float(part[0]), float(part[1]))
            if name == "base"
            else ((float(part[0]), float(part[1])), (float(part[2]), float(part[3])))
        )
    return part.tolist()


def action_layout(command: type, spec: Any) -> ActionLayout:
    """The action of the plant's command type, bounded by its spec's limits: the 2-D hand's
    ``HandCommand`` (base x, y in m within the sliders' range; q1, q2 of each finger in rad
    within the joint limits), an arm's ``ArmCommand`` (torque of every arm joint in N m within
    +-the torque limits; the hand's joint targets in rad within its joint range) and the
    grasping rig's ``ServoCommand`` (velocities in rad/s: the arm's within +-its velocity
    limits, the hand's within +-its closing speed, the head's within +-its velocity limits)."""
    name = command.__name__
    parts: list[tuple[str, Any, Any]]  # (field, low, high)
    if name == "HandCommand":
        h = spec.hand
        (xl, xh), (yl, yh) = h.base_limits
        (a, b), (c, d) = h.joint_limits
        parts = [("base", [xl, yl], [xh, yh]), ("joints", [a, c] * 2, [b, d] * 2)]
        return _layout(command, parts, ())
    if name == "ArmCommand":
        tl = np.asarray(spec.torque_limits, float)
        parts = [("torque", -tl, tl)]
        if spec.hand is not None:
            parts.append(("hand", spec.hand.lower, spec.hand.upper))
        return _layout(command, parts, ("hand",))
    if name == "ServoCommand":
        vl = np.asarray(spec.velocity_limits, float)
        parts = [("arm", -vl, vl)]
        if spec.hand is not None:
            w = np.full(spec.hand.n, float(spec.hand.closing_speed))
            parts.append(("hand", -w, w))
        if getattr(spec, "head", None) is not None:
            hv = np.asarray(spec.head.velocity_limit, float)
            parts.append(("head", -hv, hv))
        return _layout(command, parts, ("arm", "hand", "head"))
    raise ValueError(
        f"no action space for the command type {name} (HandCommand, ArmCommand, ServoCommand)"
    )


def _layout(command: type, parts: list, optional: tuple[str, ...]) -> ActionLayout:
    low = np.concatenate([np.asarray(lo, float).reshape(-1) for _, lo, _ in parts])
    high = np.concatenate([np.asarray(hi, float).reshape(-1) for _, _, hi in parts])
    if not (np.isfinite(low).all() and np.isfinite(high).all()) or (low > high).any():
        raise ValueError(f"{command.__name__}: the plant's limits are not finite bounds")
    fields = tuple((n, int(np.asarray(lo).size)) for n, lo, _ in parts)
    return ActionLayout(command, fields, low, high, frozenset(optional))
