"""A sweep, start to end: expand, skip what the table already holds, run the rest, keep the table.

``run_sweep`` writes ``DIR/table.csv`` (and ``DIR/logs/KEY.mcap`` per variant unless
``keep_logs=False``), rewriting the table after every finished variant (unless that would spend
more than ``SAVE_SHARE`` of the sweep's time: then when it would not, and at the end), so a killed
or interrupted sweep resumes where it stopped and a rerun of a finished one runs nothing but the variants that
did not finish (a worker died under it, its log is gone); ``retry_failed``: also the variants
that failed to run at all, e.g. after installing a missing plug-in.

The folder is one sweep's at a time (``DIR/sweep.lock``, held by the sweep and its workers); rows
of other sweeps of the same code into it stay in the table (after this sweep's rows), rows of
another code version are added to ``DIR/table.stale.csv``. SIGTERM stops a sweep as Ctrl-C does.
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterable

from replay import registry
from replay.sweep.executors import WORKER_DIED, default_workers, run_local, run_ray
from replay.sweep.lock import FolderLock, SweepOutputError
from replay.sweep.results import SUMMARY, refuse_foreign_summary, write_summary
from replay.sweep.table import (
    as_bool,
    param_columns,
    read_table,
    refuse_foreign,
    refuse_link,
    write_table,
)
from replay.sweep.variants import Variant
from replay.sweep.worker import INTERRUPTED

TABLE = "table.csv"
STALE = "table.stale.csv"
SAVE_SHARE = 0.05  # of a sweep's time at most spent rewriting its table after finished variants


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
    terminated: bool = False  # by SIGTERM (exit 143), not Ctrl-C (130)

    @property
    def rate(self) -> float:
        return self.ran / self.wall_time if self.wall_time > 0 else 0.0

    @property
    def not_run(self) -> int:
        """Variants that did not run to their end (an error, an invalid variant, a dead
        worker), as opposed to runs whose outcome was a failure of the method."""
        return sum(
            str(r.get("reason", "")).startswith(("error", "invalid", "worker died"))
            for r in self.rows
        )

    def line(self, outcomes: bool = True) -> str:
        """The summary; ``outcomes=False`` (an ablation that states its own measure) counts
        only the variants that could not run, not the runs' success flags: variants that stop
        before the paper's end by design are not failures."""
        if outcomes:
            verdicts = f"{self.ok} succeeded, {self.failed} failed"
        else:
            verdicts = f"{self.not_run} could not run" if self.not_run else "all ran"
        text = (
            f"sweep: {self.total} variants: {self.ran} ran, {self.skipped} skipped (done "
            f"before); {verdicts}; {self.wall_time:.1f} s "
            f"({self.rate:.2f} variants/s); table: {self.table}"
        )
        if self.stale:
            text += (
                f" ({self.stale} rows of another code or scenario version added to table.stale.csv)"
            )
        return ("interrupted: " if self.interrupted else "") + text


def _progress(total: int, enabled: bool, desc: str = "sweep"):
    from tqdm import tqdm

    return tqdm(
        total=total,
        unit="variant",
        dynamic_ncols=True,
        file=sys.stderr,
        disable=(not enabled) or None,
        leave=False,
        desc=desc,
        bar_format="{desc}: {n_fmt}/{total_fmt} |{bar}| {rate_fmt} ETA {remaining}{postfix}",
    )


def planned(variants: Iterable[Variant], total: int, progress: bool = True) -> list[Variant]:
    """The variants of :func:`replay.sweep.variants.plan`, made one by one under a bar on
    stderr (``total`` of them: each loads its scenario, so 10,000 take a minute or two)."""
    out = []
    with _progress(total, progress, desc="plan") as bar:
        for v in variants:
            out.append(v)
            bar.update(1)
    return out


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
    """Run the variants the table of ``out_dir`` does not hold yet (see the module); the folder
    is locked for the sweep (:class:`SweepOutputError` naming the sweep that holds it)."""
    out_dir = make_folder(out_dir)
    with FolderLock(out_dir), _sigterm_as_interrupt() as terminated:
        summary = _run_locked(
            variants,
            out_dir,
            workers=workers,
            executor=executor,
            address=address,
            keep_logs=keep_logs,
            progress=progress,
            metrics=metrics,
            retry_failed=retry_failed,
        )
    summary.terminated = bool(terminated)
    return summary


def make_folder(out_dir: str | Path) -> Path:
    """The sweep's folder, made if missing (:class:`SweepOutputError` if it cannot be: said
    before the variants are planned)."""
    out_dir = Path(out_dir)
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise SweepOutputError(
            f"cannot make sweep folder {out_dir}: {exc.strerror or exc}"
        ) from None
    return out_dir


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """SIGTERM (``kill``, a scheduler's stop) ends the sweep as Ctrl-C does: workers stopped,
    their logs closed as interrupted, the table whole; the list it yields says whether it came."""
    came: list[bool] = []
    if threading.current_thread() is not threading.main_thread():
        yield came
        return

    def handler(signum, frame) -> None:
        came.append(True)
        raise KeyboardInterrupt

    old = signal.signal(signal.SIGTERM, handler)
    # a sweep started in the background of a script inherits SIGINT ignored (the shell's rule
    # for `cmd &`) and would run to its end: Ctrl-C / `kill -INT` stop it however it started
    old_int = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield came
    finally:
        signal.signal(signal.SIGTERM, old)
        signal.signal(signal.SIGINT, old_int)


def _run_locked(
    variants: list[Variant],
    out_dir: Path,
    *,
    workers,
    executor,
    address,
    keep_logs,
    progress,
    metrics,
    retry_failed,
) -> SweepSummary:
    table = out_dir / TABLE
    _refuse_outputs(out_dir, keep_logs)
    params = list(dict.fromkeys(k for v in variants for k in v.params))
    by_key = {v.key: v for v in variants}
    old = read_table(table)
    rows, others, stale = _sort_old_rows(old, by_key, len(variants), retry_failed)
    columns = list(dict.fromkeys(params + [c for r in others for c in param_columns(r)]))
    if stale:
        _set_aside(out_dir / STALE, stale)
    todo = [v for v in variants if v.key not in rows]
    tasks = _tasks(todo, out_dir, keep_logs, metrics)

    last = [0.0, 0.0]  # when the table was last written, and how long that took

    def save(now: bool = True) -> None:
        """The table written; unless ``now``, only if the time since the last write is at least
        that write's cost over SAVE_SHARE (a table of 10,000 rows takes ~60 ms to write: after
        each variant, the sweep would be quadratic in its size)."""
        t = time.perf_counter()
        if not now and t - last[0] < last[1] / SAVE_SHARE:
            return
        write_table(table, [*_with_params(rows.values(), by_key), *others], columns)
        last[:] = [time.perf_counter(), time.perf_counter() - t]

    t0 = time.perf_counter()
    if stale or old or todo:
        save()
    ran, interrupted = _stream(
        tasks, rows, save, workers or default_workers(), executor, address, progress
    )
    done = sorted(_with_params(rows.values(), by_key), key=lambda r: int(r["index"]))
    if done:
        write_summary(out_dir / SUMMARY, done, params)  # (the rate of each cell)
    ok = sum(as_bool(r.get("success")) for r in done)
    return SweepSummary(
        total=len(variants),
        ran=ran,
        skipped=len(variants) - len(todo),
        ok=ok,
        failed=len(done) - ok,
        wall_time=time.perf_counter() - t0,
        table=table,
        rows=done,
        interrupted=interrupted,
        stale=len(stale),
    )


def _refuse_outputs(out_dir: Path, keep_logs: bool) -> None:
    """Refuse links (before anything is read from them) and files not of a sweep (a table.csv
    of the user's is not replaced)."""
    table = out_dir / TABLE
    for path in (
        table,
        out_dir / STALE,
        out_dir / SUMMARY,
        *([out_dir / "logs"] if keep_logs else []),
    ):
        refuse_link(path)
    for path in (table, out_dir / STALE):
        refuse_foreign(path)
    refuse_foreign_summary(out_dir / SUMMARY)


def _sort_old_rows(
    old: list[dict[str, Any]], by_key: dict[str, Variant], n: int, retry_failed: bool
) -> tuple[dict[str, dict[str, Any]], list[dict[str, Any]], list[dict[str, Any]]]:
    """The rows of an earlier table: (this sweep's finished rows by key, rows of other sweeps of
    this code into this folder: kept, rows of another code or scenario version: set aside)."""
    versions = {v.version for v in by_key.values()}
    rows: dict[str, dict[str, Any]] = {}
    others: list[dict[str, Any]] = []
    stale: list[dict[str, Any]] = []
    for r in old:
        key = r.get("key", "")
        if key in by_key:
            if not (retry_failed and is_error(r)) and not unfinished(r):
                rows[key] = dict(r)
        elif r.get("version") and r.get("version") in versions:
            others.append(dict(r))
        else:
            stale.append(r)
    for key, row in rows.items():  # the index follows this sweep's order
        row["index"] = by_key[key].index
    for i, row in enumerate(others):  # the other sweeps' rows after this one's
        row["index"] = n + i
    return rows, others, stale


def _tasks(todo: list[Variant], out_dir: Path, keep_logs: bool, metrics) -> list[dict]:
    """One task dict per variant to run (what a worker, local or Ray, is given)."""
    plugins = registry.imported_plugins()  # (the planning imported them)
    return [
        {
            "key": v.key,
            "index": v.index,
            "resolved": v.resolved,
            "file_dirs": v.file_dirs,  # (relative *_file parameters: the scenario's folder)
            "error": v.error,
            "log": str((out_dir / "logs" / f"{v.name or 'variant'}-{v.key}.mcap").resolve())
            if keep_logs
            else "",
            "cwd": os.getcwd(),
            "plugins": plugins,  # module:Class plug-ins to import again in a fresh worker
            "metrics": metrics,
        }
        for v in todo
    ]


def _stream(tasks, rows, save, workers, executor, address, progress) -> tuple[int, bool]:
    """Run ``tasks``, each finished row into ``rows`` and the table saved as they come;
    (how many ran, whether Ctrl-C stopped the sweep)."""
    ran = failed_now = 0
    interrupted = False
    bar = _progress(len(tasks), progress)
    stream: Any = None  # (a generator: closed below)
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
            save(now=False)
            bar.update(1)
            if failed_now:
                bar.set_postfix_str(f" {failed_now} failed", refresh=False)
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if stream is not None:
            stream.close()  # (its workers stopped before the folder is let go)
        bar.close()
        if ran:
            save()  # (every finished row, whatever the last writes left out)
    return ran, interrupted


def _set_aside(path: Path, stale: list[dict[str, Any]]) -> None:
    """Add ``stale`` rows to ``path`` (table.stale.csv), a row of the same key replaced: the
    rows set aside by every earlier sweep stay."""
    kept: dict[str, dict[str, Any]] = {r.get("key", ""): dict(r) for r in read_table(path)}
    kept.update({r.get("key", ""): r for r in stale})
    merged = list(kept.values())
    for r in merged:
        if not str(r.get("index", "")).strip().lstrip("-").isdigit():
            r["index"] = -1
    columns = list(dict.fromkeys(c for r in merged for c in param_columns(r)))
    write_table(path, merged, columns)


def unfinished(row: dict) -> bool:
    """A row of a variant that did not finish: its worker died under it, or the log it names
    is gone. A plain rerun runs it again."""
    log = str(row.get("log") or "")
    return str(row.get("reason", "")).startswith(WORKER_DIED) or bool(
        log and not Path(log).is_file()
    )


def is_error(row: dict) -> bool:
    """A row that failed to run (an exception, a dead worker, a scenario that did not load), as
    opposed to a run that ended without success."""
    return str(row.get("reason", "")).startswith(("error", "invalid"))


def _with_params(rows, by_key):
    for r in rows:
        v = by_key[r["key"]]
        yield {**r, **v.params, "index": v.index, "seed": v.seed, "version": v.version}
