"""Reading a sweep's table for the ablation plots (analysis/ablation_*.py): rates per group."""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from replay.sweep.table import as_bool, as_float


def count(row: dict, kind: str) -> int:
    """How many events of ``kind`` the variant's run had (the table's ``e.KIND`` column)."""
    v = as_float(row.get(f"e.{kind}"))
    return 0 if np.isnan(v) else int(v)


def caught(row: dict) -> bool:
    """The ball was caught and kept: a ``catch`` event, no ``drop``, and the outcome a success."""
    return as_bool(row.get("success")) and count(row, "catch") > 0 and count(row, "drop") == 0


def captured(row: dict) -> bool:
    """The stick was captured (a ``capture`` event) and the outcome a success."""
    return as_bool(row.get("success")) and count(row, "capture") > 0


def grasped(row: dict) -> bool:
    """The object was grasped and held (the outcome a success: at least one grasp held long enough
    while the human kept moving it)."""
    n = as_float(row.get("m.grasps"))
    return as_bool(row.get("success")) and not np.isnan(n) and n > 0


def counts_by(rows: list[dict], x: str, line: str | None, ok) -> dict[str, tuple[list, list, list]]:
    """{line value: (sorted x values, successes k, runs n at each)} over the rows."""
    groups: dict = defaultdict(lambda: defaultdict(list))
    for r in rows:
        groups[r.get(line, "") if line else ""][as_float(r[x])].append(bool(ok(r)))
    out = {}
    for name, by_x in groups.items():
        xs = sorted(by_x)
        out[name] = (xs, [sum(by_x[v]) for v in xs], [len(by_x[v]) for v in xs])
    return out


def rate_by(rows: list[dict], x: str, line: str | None, ok) -> dict[str, tuple[list, list]]:
    """{line value: (sorted x values, success rate at each)} over the rows."""
    return {
        name: (xs, [k / n for k, n in zip(ks, ns)])
        for name, (xs, ks, ns) in counts_by(rows, x, line, ok).items()
    }


def mean_by(
    rows: list[dict], x: str, line: str | None, column: str
) -> dict[str, tuple[list, list]]:
    """{line value: (sorted x values, mean of a numeric column at each, nan-skipping)}."""
    groups: dict = defaultdict(lambda: defaultdict(list))
    for r in rows:
        groups[r.get(line, "") if line else ""][as_float(r[x])].append(as_float(r.get(column)))
    out = {}
    for name, by_x in groups.items():
        xs = sorted(by_x)
        out[name] = (
            xs,
            [
                float(np.nanmean(by_x[v])) if not np.all(np.isnan(by_x[v])) else float("nan")
                for v in xs
            ],
        )
    return out


def failures(rows: list[dict]) -> list[str]:
    """Reasons of the variants that did not run to an outcome (errors, invalid parameters)."""
    return [
        f"{r.get('index')}: {r.get('reason')}"
        for r in rows
        if str(r.get("reason", "")).startswith(("error", "invalid"))
    ]


def pct(x: float) -> str:
    return "n/a" if x is None or np.isnan(x) else f"{100 * x:.0f}%"


def rate_at(curves: dict, line: str, x: float) -> float:
    """The success rate of one line at one x (nan if that point was not run)."""
    xs, ys = curves.get(line, ([], []))
    for xv, yv in zip(xs, ys):
        if abs(xv - x) <= 1e-6 * max(1.0, abs(x)):
            return yv
    return float("nan")


def overall(rows: list[dict], ok, verb: str = "succeeded") -> str:
    n = len(rows)
    k = sum(bool(ok(r)) for r in rows)
    bad = failures(rows)
    text = f"{k} of {n} variants {verb}"
    if bad:
        text += f"; {len(bad)} failed to run (first: {bad[0]})"
    return text
