"""The sweep's table: one CSV row per variant, rewritten (atomically) as each variant finishes.

Columns: ``index``, ``key``, the varied parameters, ``seed``, ``success``, ``reason``, the
``outcome`` event's metrics (``m.NAME``), the sweep's own metrics read from each log
(``x.NAME``), the count of each event kind (``e.KIND``), ``stopped_by``, ``t_end``,
``wall_time``, ``cpu_time``, ``log`` and ``version`` (the code version that ran it). A column
with a known unit says it in its header (``t_end [s]``, ``e.catch [1]``, ``m.contact_speed [m/s]``:
:data:`UNITS`); :func:`read_table` reads a header with or without units alike. Measured numbers
(metrics, ``t_end``) are written to 6 significant digits, varied parameters as given. The file is
the sweep's memory: rows whose key is still a variant of the sweep are done; a killed sweep loses
at most the variants that were running and those finished since the table was last written
(``engine.SAVE_SHARE``); rows of other sweeps into the same folder stay.
"""

from __future__ import annotations

import csv
import errno
import os
import re
import stat
import tempfile
from pathlib import Path
from typing import Any, Iterable

FIRST = ["index", "key"]
LAST = ["seed", "success", "reason"]
TAIL = ["stopped_by", "t_end", "wall_time", "cpu_time", "log", "version"]

# the unit of a column (an outcome metric ``m.NAME`` or a log metric ``x.NAME`` by NAME, as its
# writer documents it: plants/arm_rig/outcome.py, plants/airtable's outcome in docs/DESIGN.md);
# an event count ``e.KIND`` is a number [1]; other columns have none or a unit not known here
UNITS = {
    "t_end": "s",
    "wall_time": "s",
    "cpu_time": "s",
    "catch_time": "s",
    "first_contact_time": "s",
    "closest_time": "s",
    "contact_speed": "m/s",
    "contact_offset": "m",
    "closest_distance": "m",
    "approach_angle": "deg",
    "t_capture": "s",
    "t_capture_method": "s",
}
_UNIT = re.compile(r" \[[^\]]*\]$")  # a header's " [unit]"


def header(column: str) -> str:
    """A column's header: its name, and its unit in brackets when known."""
    if column.startswith("e."):
        return f"{column} [1]"
    unit = UNITS.get(column[2:] if column[:2] in ("m.", "x.") else column)
    return f"{column} [{unit}]" if unit else column


def column_name(head: str) -> str:
    """A header's column name (its unit left out): ``t_end [s]`` -> ``t_end``."""
    return _UNIT.sub("", head)


def read_table(path: str | Path) -> list[dict[str, str]]:
    """The rows of a table, keyed by column name, whether its header has units or not (tables
    written before units, e.g. data/ablations/, load as they are)."""
    path = Path(path)
    if not path.is_file():
        return []
    with path.open(newline="", encoding="utf-8") as f:
        head = next(csv.reader(f), None)
        if head is None:
            return []
        return list(csv.DictReader(f, fieldnames=[column_name(h) for h in head]))


class TableError(Exception):
    """The table cannot be written (a full disk, a folder that takes no files); ``code`` is the
    exit code (1: a system fault, 2: the folder given)."""

    def __init__(self, message: str, code: int = 1) -> None:
        super().__init__(message)
        self.code = code


def refuse_link(path: Path) -> None:
    """:class:`TableError` (exit 2) when ``path`` is a symbolic link: a sweep's table, its
    stale rows and its logs folder are never read or written through one (a folder shipped
    with ``table.csv -> ~/notes`` would have the notes read as rows and copied)."""
    if os.path.islink(path):
        raise TableError(
            f"will not write {path} through a symbolic link (to {os.readlink(path)}); "
            "remove the link or give another -o",
            2,
        )


def refuse_foreign(
    path: Path,
    first: bytes = rb"index,key(,|\r?\n|$)",
    what: str = "a sweep's table (its first line does not start 'index,key')",
) -> None:
    """:class:`TableError` (exit 2) when ``path`` exists and is not a sweep's own file (a
    regular file, empty or whose first line matches ``first``): the sweep rewrites its table
    and summary whole, so ``-o`` at a folder holding a ``table.csv`` of the user's must not
    replace it."""
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise TableError(f"will not write {path}: it is not a regular file; give another -o", 2)
        with path.open("rb") as f:
            head = f.readline(4096)
    except FileNotFoundError:
        return
    except OSError as exc:
        raise TableError(f"cannot read {path}: {exc.strerror or exc}", 2) from None
    if head and not re.match(first, head):
        raise TableError(f"will not overwrite {path}: it is not {what}; give another -o", 2)


def param_columns(row: dict[str, Any]) -> list[str]:
    """The varied parameters' columns of a row read back (everything but the fixed columns and
    the metrics)."""
    fixed = set(FIRST + LAST + TAIL)
    return [k for k in row if k not in fixed and str(k)[:2] not in ("m.", "x.", "e.")]


def write_table(path: str | Path, rows: Iterable[dict[str, Any]], params: list[str]) -> None:
    """Write ``rows`` to ``path`` atomically (a temporary file of this writer's own, replacing
    ``path`` only once whole); :class:`TableError` when it cannot, nothing left behind."""
    path = Path(path)
    refuse_link(path)
    rows = sorted(rows, key=lambda r: int(r["index"]))
    metrics = sorted({k for r in rows for k in r if str(k)[:2] in ("m.", "x.", "e.")})
    columns = FIRST + [p for p in params if p not in LAST + TAIL] + LAST + metrics + TAIL
    extra = sorted({k for r in rows for k in r} - set(columns))
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        with os.fdopen(fd, "w", newline="", encoding="utf-8") as f:
            csv.writer(f).writerow([header(c) for c in columns + extra])
            w = csv.DictWriter(f, fieldnames=columns + extra, extrasaction="ignore")
            for r in rows:
                w.writerow({k: _cell(k, v) for k, v in r.items()})
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError as exc:
        if tmp is not None:
            Path(tmp).unlink(missing_ok=True)
        full = exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EIO)
        raise TableError(
            f"cannot write table {path}: {exc.strerror or exc}", 1 if full else 2
        ) from None


def _cell(column: str, v: Any) -> Any:
    """A value as written: a measured number (a metric, ``t_end``) to 6 significant digits,
    a varied parameter as given, None as empty."""
    if v is None:
        return ""
    if type(v) is float and (column[:2] in ("m.", "x.") or column == "t_end"):
        return float(f"{v:.6g}")
    return v


def as_bool(cell: Any) -> bool:
    return str(cell).strip().lower() in ("true", "1", "yes")


def as_float(cell: Any) -> float:
    try:
        return float(cell)
    except (TypeError, ValueError):
        return float("nan")
