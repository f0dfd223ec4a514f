"""A sweep, start to end: expand, skip what the table already holds, run the rest, keep the table.

``run_sweep`` writes ``DIR/table.csv`` (and ``DIR/logs/KEY.mcap`` per variant unless
``keep_logs=False``), rewriting the table after every finished variant, so a killed or interrupted
sweep resumes where it stopped and a rerun of a finished one runs nothing (``retry_failed``: except
the variants that failed to run at all, e.g. after installing a missing plug-in).
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

from replay.sweep.executors import default_workers, run_local, run_ray
from replay.sweep.table import as_bool, read_table, write_table
from replay.sweep.variants import Variant
from replay.sweep.worker import INTERRUPTED

TABLE = "table.csv"


@dataclass
class SweepSummary:
    total: int
    ran: int
    skipped: int
    ok: int
    failed: int
    wall_time: float
    table: Path
    rows: list = field(default_factory=list)
    interrupted: bool = False
    stale: int = 0

    @property
    def rate(self) -> float:
        return self.ran / self.wall_time if self.wall_time > 0 else 0.0

    def line(self) -> str:
        text = (
            f"sweep: {self.total} variants: {self.ran} ran, {self.skipped} skipped (done "
            f"before); {self.ok} succeeded, {self.failed} failed; {self.wall_time:.1f} s "
            f"({self.rate:.2f} variants/s); table: {self.table}"
        )
        if self.stale:
            text += (
                f" ({self.stale} rows of another code or scenario version moved to table.stale.csv)"
            )
        return ("interrupted: " if self.interrupted else "") + text


def _progress(total: int, enabled: bool):
    from tqdm import tqdm

    return tqdm(
        total=total,
        unit="variant",
        dynamic_ncols=True,
        file=sys.stderr,
        disable=(not enabled) or None,
        leave=False,
        desc="sweep",
        bar_format="{desc}: {n_fmt}/{total_fmt} |{bar}| {rate_fmt} ETA {remaining}{postfix}",
    )


def run_sweep(
    variants: list[Variant],
    out_dir: str | Path,
    *,
    workers: int | None = None,
    executor: str = "local",
    address: str | None = None,
    keep_logs: bool = True,
    progress: bool = True,
    metrics: str = "",
    retry_failed: bool = False,
) -> SweepSummary:
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    table = out_dir / TABLE
    params = list(dict.fromkeys(k for v in variants for k in v.params))
    by_key = {v.key: v for v in variants}
    old = read_table(table)
    rows: dict[str, dict] = {
        r["key"]: dict(r)
        for r in old
        if r.get("key") in by_key and not (retry_failed and is_error(r))
    }
    for key, r in rows.items():  # the index follows this sweep's order
        r["index"] = by_key[key].index
    stale = len(old) - len(rows)
    if stale:  # rows of another code or scenario version: kept aside
        table.replace(out_dir / "table.stale.csv")
    todo = [v for v in variants if v.key not in rows]
    workers = workers or default_workers()
    tasks = [
        {
            "key": v.key,
            "index": v.index,
            "resolved": v.resolved,
            "error": v.error,
            "log": str((out_dir / "logs" / f"{v.name or 'variant'}-{v.key}.mcap").resolve())
            if keep_logs
            else "",
            "cwd": os.getcwd(),
            "metrics": metrics,
        }
        for v in todo
    ]
    t0 = time.perf_counter()
    ran = failed_now = 0
    interrupted = False
    bar = _progress(len(todo), progress)
    if stale or (old and not todo) or todo:
        write_table(table, _with_params(rows.values(), by_key), params)
    try:
        stream = (
            run_local(tasks, workers) if executor == "local" else run_ray(tasks, workers, address)
        )
        for row in stream:
            if row.get("reason") == INTERRUPTED:  # Ctrl-C reached the worker: not done
                interrupted = True
                continue
            rows[row["key"]] = row
            ran += 1
            failed_now += not as_bool(row.get("success"))
            write_table(table, _with_params(rows.values(), by_key), params)
            bar.update(1)
            if failed_now:
                bar.set_postfix_str(f" {failed_now} failed", refresh=False)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        bar.close()
    done = list(_with_params(rows.values(), by_key))
    ok = sum(as_bool(r.get("success")) for r in done)
    return SweepSummary(
        total=len(variants),
        ran=ran,
        skipped=len(variants) - len(todo),
        ok=ok,
        failed=len(done) - ok,
        wall_time=time.perf_counter() - t0,
        table=table,
        rows=sorted(done, key=lambda r: int(r["index"])),
        interrupted=interrupted,
        stale=stale,
    )


def is_error(row: dict) -> bool:
    """A row that failed to run (an exception, a dead worker, a scenario that did not load), as
    opposed to a run that ended without success."""
    return str(row.get("reason", "")).startswith(("error", "invalid"))


def _with_params(rows, by_key):
    for r in rows:
        v = by_key[r["key"]]
        yield {**r, **v.params, "index": v.index, "seed": v.seed}
