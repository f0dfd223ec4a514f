"""A sweep's results per cell (``DIR/summary.csv``): for each combination of the varied parameters
but the seed (a seed axis makes repeats of a cell), how many variants ran, how many succeeded,
the success rate and its Wilson 95 % interval, and how many could not run (an error, an invalid
variant: no outcome, so not in the rate). Written with the table when the sweep ends."""

from __future__ import annotations

import csv
import math
import re
from pathlib import Path
from typing import Any

from replay.log.output import write_output
from replay.sweep.table import TableError, as_bool, refuse_foreign

SUMMARY = "summary.csv"
COLUMNS = ["runs", "successes", "rate", "rate_lo_95", "rate_hi_95", "not_run"]
_NOT_RUN = ("error", "invalid", "interrupted")  # a row's reason: the variant has no outcome
Z95 = 1.959964  # the normal quantile of a two-sided 95 % interval


def wilson(k: int, n: int, z: float = Z95) -> tuple[float, float]:
    """The Wilson score 95 % interval of a rate k/n (Wilson 1927); (0, 1) for n = 0."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, mid - half), min(1.0, mid + half)


def cells(rows: list[dict[str, Any]], params: list[str]) -> list[dict[str, Any]]:
    """One summary row per cell (the values of ``params`` but ``seed``, in first-seen order)."""
    axes = [p for p in params if p != "seed"]
    groups: dict[tuple, list[dict[str, Any]]] = {}
    for r in rows:
        groups.setdefault(tuple(str(r.get(p, "")) for p in axes), []).append(r)
    out = []
    for values, members in groups.items():
        ran = [r for r in members if not str(r.get("reason", "")).startswith(_NOT_RUN)]
        k, n = sum(as_bool(r.get("success")) for r in ran), len(ran)
        lo, hi = wilson(k, n)
        rate = f"{k / n:.3f}" if n else ""
        summary = [n, k, rate, f"{lo:.3f}", f"{hi:.3f}", len(members) - n]
        out.append({**dict(zip(axes, values)), **dict(zip(COLUMNS, summary))})
    return out


def refuse_foreign_summary(path: Path) -> None:
    """:class:`TableError` (exit 2) when ``path`` holds a file that is not a sweep's summary
    (its header ends with :data:`COLUMNS`): never replaced."""
    tail = ",".join(COLUMNS).encode()
    refuse_foreign(
        path,
        rb"(.*,)?" + re.escape(tail) + rb"\r?\n",
        f"a sweep's summary (a header ending {tail!r})",
    )


def write_summary(path: Path, rows: list[dict[str, Any]], params: list[str]) -> None:
    """``cells(rows, params)`` to ``path``, written beside it and renamed onto it, over nothing
    but an earlier summary (TableError when it cannot be written)."""
    axes = [p for p in params if p != "seed"]

    def write(tmp: Path) -> None:
        with tmp.open("w", newline="", encoding="utf-8") as f:
            w = csv.DictWriter(f, fieldnames=axes + COLUMNS)
            w.writeheader()
            w.writerows(cells(rows, params))

    refuse_foreign_summary(path)
    try:
        write_output(path, write)
    except OSError as exc:
        raise TableError(f"cannot write summary {path}: {exc.strerror or exc}", 1) from None
