"""A log topic as NumPy arrays, field by field (the figures' and claims' common reader)."""

from __future__ import annotations

import numpy as np

from replay.log import LogReader


def arrays(log: LogReader, topic: str, fields: list[str]) -> dict[str, np.ndarray]:
    """``{"t": ..., field: ...}`` for each message of ``topic`` (empty arrays if none)."""
    rows = log.series(topic)
    out = {"t": np.array([r["t"] for r in rows], dtype=float)}
    for f in fields:
        out[f] = np.array([r[f] for r in rows], dtype=float)
    return out


def events(log: LogReader, kind: str | None = None) -> list[dict]:
    return [e for e in log.events() if kind is None or e["kind"] == kind]
