"""Declaring scenario parameters: a dataclass field with its unit, range and meaning.

Every plug-in (plant, controller, sensor) declares a ``Params`` dataclass whose fields are made
with :func:`param`. The scenario loader validates YAML against it field by field (type, every list
item and the list's length, finiteness, range, choices) and the docs list the unit of each field,
so the YAML mirrors the code field for field.

Defaults that hold unless a field says otherwise (so that memory and run time stay bounded and no
meaningless number reaches a simulator):

- a float is finite (NaN never; +-inf only with ``allow_inf=True``) and ``|x| <= MAX_FLOAT``,
  and zero or a normal float (a subnormal such as 1e-320, or 1e-400 read as 0, is refused:
  a simulator dividing by it gets infinity);
- an integer is ``|n| <= MAX_INT``;
- a list has at most ``MAX_ITEMS`` items, a string at most ``MAX_CHARS`` characters.

Checks between fields (a lower limit above its upper limit, a list as long as the arm's joints)
go in the dataclass's ``__post_init__`` and raise :class:`ParamError` naming the field, so the
error points at that field's line.

A size that decides how much memory or time a plug-in will spend (a table's rows, an image's
pixels) is bounded by a resource limit of :mod:`replay.limits`, which a user can raise: one
field with ``param(limit="table_rows")`` (the loader checks it), a product of fields with
:func:`check_limit` in ``__post_init__``.
"""

from __future__ import annotations

import dataclasses
from typing import Any

from replay.limits import LIMITS, LimitError, check

_MISSING = dataclasses.MISSING

MAX_FLOAT = 1e9  # SI: no scenario quantity is larger (a field may set its own bounds)
MAX_INT = 2**31 - 1
MAX_ITEMS = 256
MAX_CHARS = 10_000


class ParamError(ValueError):
    """A check of a ``Params`` (``__post_init__``) failed; ``field`` is the dotted field name
    relative to that dataclass (e.g. ``initial_q`` or ``initial_q[2]``)."""

    def __init__(self, field: str, message: str) -> None:
        self.field = field
        self.message = message
        super().__init__(f"{field}: {message}")


def param(
    default: Any = _MISSING,
    *,
    unit: str = "",
    doc: str = "",
    ge: float | None = None,
    gt: float | None = None,
    le: float | None = None,
    lt: float | None = None,
    choices: tuple | None = None,
    length: int | None = None,
    min_length: int | None = None,
    max_length: int | None = None,
    allow_inf: bool = False,
    pattern: str | None = None,
    omit_empty: bool = False,
    limit: str | None = None,
) -> Any:
    """A dataclass field with validation metadata.

    ``unit`` is the SI unit of the value ("m", "kg", "kg*m^2", "s", "rad", "rad/s", "m/s", "Hz",
    "1" for dimensionless). ``ge/gt/le/lt`` bound numbers (and every item of a list of numbers),
    ``choices`` lists the allowed values, ``length`` fixes the length of a list (``min_length``,
    ``max_length`` bound it; of a string: its characters), ``allow_inf`` admits +-inf for a
    float (meaning "no limit"), ``pattern`` is a regular expression a string must match whole.
    A field without a default is required in the YAML. ``omit_empty``: left out of the resolved
    scenario when empty (a field added later, so older scenarios resolve to the same text).
    ``limit``: the :mod:`replay.limits` limit an integer is checked against (a size that
    allocates in proportion: a table's rows).
    """
    meta = {
        "unit": unit,
        "doc": doc,
        "ge": ge,
        "gt": gt,
        "le": le,
        "lt": lt,
        "choices": choices,
        "length": length,
        "min_length": min_length,
        "max_length": max_length,
        "allow_inf": allow_inf,
        "pattern": pattern,
    }
    if omit_empty:
        meta["omit_empty"] = True
    if limit is not None:
        meta["limit"] = LIMITS[limit].name
    if isinstance(default, (list, dict)):
        value = default
        return dataclasses.field(default_factory=lambda: _copy(value), metadata=meta)
    if default is _MISSING:
        return dataclasses.field(metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


def check_limit(name: str, value: int | float, field: str, what: str) -> None:
    """:func:`replay.limits.check` from a ``__post_init__``: over the limit is a
    :class:`ParamError` naming ``field`` (so the error points at its line)."""
    try:
        check(name, value, what)
    except LimitError as exc:
        raise ParamError(field, str(exc)) from None


def _copy(value):
    import copy

    return copy.deepcopy(value)


def describe(cls) -> list[dict]:
    """Rows (name, type, unit, default, range, doc) for docs and `replay params`."""
    rows = []
    for f in dataclasses.fields(cls):
        m = f.metadata
        if f.default is not _MISSING:
            default = f.default
        elif f.default_factory is not _MISSING:  # type: ignore[misc]
            default = f.default_factory()  # type: ignore[misc]
        else:
            default = "(required)"
        bounds = []
        for key, sym in (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<")):
            if m.get(key) is not None:
                bounds.append(f"{sym} {m[key]}")
        if m.get("limit"):
            bounds.append(f"at most {LIMITS[m['limit']].env}")
        if m.get("choices"):
            bounds.append("one of " + ", ".join(map(str, m["choices"])))
        if m.get("length") is not None:
            bounds.append(f"{m['length']} items")
        elif m.get("min_length") is not None or m.get("max_length") is not None:
            bounds.append(f"{m.get('min_length') or 0}..{m.get('max_length') or MAX_ITEMS} items")
        rows.append(
            {
                "name": f.name,
                "type": str(f.type),
                "unit": m.get("unit", ""),
                "default": default,
                "range": ", ".join(bounds),
                "doc": m.get("doc", ""),
            }
        )
    return rows
