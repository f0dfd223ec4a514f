"""Resource limits, checked before work starts (one home for every one of them).

A scenario, a ``--set`` or a log is data from someone else: each size that decides how much
memory or time a command will spend is bounded here, and the check comes before the work. A
limit can be raised for one command by its environment variable, e.g.
``REPLAY_LIMIT_CAMERA_PIXELS=100000000 replay run big_camera.yaml``; the error says which.
``docs/security.md`` lists them.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

__all__ = ["LIMITS", "Limit", "LimitError", "check", "limit"]


class LimitError(ValueError):
    """A size is over its limit (the message names the limit and how to raise it)."""


@dataclass(frozen=True)
class Limit:
    name: str  # the key, and the environment variable's suffix
    default: int
    unit: str  # what is counted: "pixels", "bytes", "variants", ...
    what: str  # what it bounds, for the error and the docs

    @property
    def env(self) -> str:
        return f"REPLAY_LIMIT_{self.name.upper()}"


LIMITS: dict[str, Limit] = {
    x.name: x
    for x in (
        Limit(
            "camera_pixels", 16_777_216, "pixels", "the pixels of one camera image (width x height)"
        ),
        Limit("table_rows", 100_000, "rows", "the rows of a generated table (a human's path)"),
        Limit("sweep_variants", 100_000, "variants", "the variants of one sweep"),
        Limit("scenario_bytes", 1_000_000, "bytes", "the text of one scenario (a file or a log's)"),
        Limit("message_bytes", 64_000_000, "bytes", "one message a log reader will load"),
        Limit(
            "series_bytes",
            64_000_000,
            "bytes",
            "the messages of one topic a reader decodes and keeps (e.g. all events)",
        ),
        Limit(
            "viewer_bytes",
            1_000_000_000,
            "bytes",
            "what the viewer keeps of one run (its series as numbers, its camera images)",
        ),
        Limit("log_bytes", 8_000_000_000, "bytes", "the projected size of a run's log"),
    )
}


def limit(name: str) -> int:
    """The limit in force: its environment variable if set (a positive integer), else the
    default. A bad variable is a :class:`LimitError`, not a silent default."""
    lim = LIMITS[name]
    raw = os.environ.get(lim.env)
    if raw is None or raw.strip() == "":
        return lim.default
    try:
        value = int(raw.strip().replace("_", ""))
    except ValueError:
        raise LimitError(f"{lim.env}={raw[:40]!r}: expected a positive integer") from None
    if value <= 0:
        raise LimitError(f"{lim.env}={value}: expected a positive integer")
    return value


def check(name: str, value: int | float, what: str | None = None) -> None:
    """Raise :class:`LimitError` if ``value`` is over the limit ``name``. ``what`` says what was
    measured (default: the limit's own description)."""
    cap = limit(name)
    if value > cap:
        lim = LIMITS[name]
        raise LimitError(
            f"{what or lim.what} is {_count(value)} {lim.unit}, over the limit of {cap:,} "
            f"(raise it with {lim.env}=N)"
        )


def _count(value: int | float) -> str:
    """``value`` with thousands separators, exactly for an integer (10**30 is not a float's)."""
    return f"{value:,}" if isinstance(value, int) else f"{value:,.0f}"
