"""The sweep's table: one CSV row per variant, rewritten (atomically) as each variant finishes.

Columns: ``index``, ``key``, the varied parameters, ``seed``, ``success``, ``reason``, the
``outcome`` event's metrics (``m.NAME``), the sweep's own metrics read from each log
(``x.NAME``), the count of each event kind (``e.KIND``), ``stopped_by``, ``t_end``, ``wall_time``, ``cpu_time`` and ``log``. The
file is the sweep's memory: rows whose key is still a variant of the sweep are done; a killed sweep
loses at most the variants that were running.
"""

from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any, Iterable

FIRST = ["index", "key"]
LAST = ["seed", "success", "reason"]
TAIL = ["stopped_by", "t_end", "wall_time", "cpu_time", "log"]


def read_table(path: str | Path) -> list[dict[str, str]]:
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as f:
        return list(csv.DictReader(f))


def write_table(path: str | Path, rows: Iterable[dict[str, Any]], params: list[str]) -> None:
    path = Path(path)
    rows = sorted(rows, key=lambda r: int(r["index"]))
    metrics = sorted({k for r in rows for k in r if str(k)[:2] in ("m.", "x.", "e.")})
    columns = FIRST + [p for p in params if p not in LAST] + LAST + metrics + TAIL
    extra = sorted({k for r in rows for k in r} - set(columns))
    tmp = path.with_name(path.name + ".tmp")
    path.parent.mkdir(parents=True, exist_ok=True)
    with tmp.open("w", newline="", encoding="utf-8") as f:
        w = csv.DictWriter(f, fieldnames=columns + extra, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow({k: _text(v) for k, v in r.items()})
    os.replace(tmp, path)


def _text(v: Any) -> Any:
    return "" if v is None else v


def as_bool(cell: Any) -> bool:
    return str(cell).strip().lower() in ("true", "1", "yes")


def as_float(cell: Any) -> float:
    try:
        return float(cell)
    except (TypeError, ValueError):
        return float("nan")
