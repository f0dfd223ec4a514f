"""Declaring scenario parameters: a dataclass field with its unit, range and meaning.

Every plug-in (plant, controller, sensor) declares a ``Params`` dataclass whose fields are made
with :func:`param`. The scenario loader validates YAML against it field by field (type, range,
choices) and the docs list the unit of each field, so the YAML mirrors the code field for field.
"""

from __future__ import annotations

import dataclasses
from typing import Any

_MISSING = dataclasses.MISSING


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
    omit_empty: bool = False,
) -> Any:
    """A dataclass field with validation metadata.

    ``unit`` is the SI unit of the value ("m", "kg", "kg*m^2", "s", "rad", "rad/s", "m/s", "Hz",
    "1" for dimensionless). ``ge/gt/le/lt`` bound numbers (and every item of a list of numbers),
    ``choices`` lists the allowed values, ``length`` fixes the length of a list.
    A field without a default is required in the YAML. ``omit_empty``: left out of the resolved
    scenario when empty (a field added later, so older scenarios resolve to the same text).
    """
    meta = {"unit": unit, "doc": doc, "ge": ge, "gt": gt, "le": le, "lt": lt,
            "choices": choices, "length": length}
    if omit_empty:
        meta["omit_empty"] = True
    if isinstance(default, (list, dict)):
        value = default
        return dataclasses.field(default_factory=lambda: _copy(value), metadata=meta)
    if default is _MISSING:
        return dataclasses.field(metadata=meta)
    return dataclasses.field(default=default, metadata=meta)


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
        if m.get("choices"):
            bounds.append("one of " + ", ".join(map(str, m["choices"])))
        rows.append({"name": f.name, "type": str(f.type), "unit": m.get("unit", ""),
                     "default": default, "range": ", ".join(bounds), "doc": m.get("doc", "")})
    return rows
