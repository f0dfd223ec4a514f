"""One variant, run anywhere (a pool process, a Ray worker): resolved scenario in, table row out.

The task carries the resolved YAML, not a file path, so a worker on another machine runs exactly
what was expanded here (it needs the same code and data files, e.g. the catching alpha). Nothing
raises out of :func:`run_variant`: an exception in a plug-in, a NaN, a scenario the plant rejects
are a row with ``success: False`` and the reason.
"""

from __future__ import annotations

import math
import os
import time
import traceback
from pathlib import Path
from typing import Any


INTERRUPTED = "interrupted"


def run_variant(task: dict[str, Any]) -> dict[str, Any]:
    """task: key, index, resolved, file_dirs (where relative ``*_file`` parameters resolve), error,
    log (path or ""), cwd, metrics ("module:function" of a log's reader -> extra columns, or "")
    -> a row (without the params). Without a log the metrics read the run's messages kept in
    memory (:mod:`replay.log.memory`): the same numbers, no file written."""
    wall0 = time.perf_counter()
    cpu0 = time.process_time()
    row: dict[str, Any] = {"key": task["key"], "index": task["index"]}
    if task.get("error"):
        row.update(success=False, reason=task["error"], wall_time=0.0, cpu_time=0.0, log="")
        return row
    log: str = task.get("log") or ""
    cwd = task.get("cwd")
    if cwd and Path(cwd).is_dir() and os.getcwd() != cwd:
        os.chdir(cwd)  # relative data paths (alpha files) as in the scenario
    from replay.runner import RunInterrupted, Runner

    try:
        from replay import registry
        from replay.scenario.loader import scenario_from_text, set_file_dirs

        for kind, name, folder in task.get("plugins", ()):  # (a forked worker has them already)
            registry.import_plugin(kind, name, folder)
        sc = scenario_from_text(task["resolved"], name=f"<variant {task['key']}>", resolved=True)
        set_file_dirs(sc, task.get("file_dirs") or {})
        if log:
            Path(log).parent.mkdir(parents=True, exist_ok=True)
        runner = Runner(sc)
        result = runner.run(log or None, keep=not log and bool(task.get("metrics")))
        outcome = dict(result.outcome)
        row["success"] = bool(outcome.pop("success", False))
        row["reason"] = str(outcome.pop("reason", ""))
        if result.stopped_by == "error" and not row["reason"]:
            row["reason"] = f"error: {result.error}"
        row["t_end"] = result.t_end
        row["stopped_by"] = result.stopped_by
        row.update({f"m.{k}": _cell(v) for k, v in outcome.items()})
        row.update({f"e.{k}": n for k, n in sorted(result.events.items())})
        if task.get("metrics"):
            row.update(
                {f"x.{k}": _cell(v) for k, v in _extract(task["metrics"], runner, log).items()}
            )
    except (RunInterrupted, KeyboardInterrupt):
        row.update(success=False, reason=INTERRUPTED)  # not a result: the engine drops it
    except Exception as exc:  # noqa: BLE001 - a failed variant is a row
        _drop_part_on_full_disk(exc, log)
        row["success"] = False
        last = traceback.extract_tb(exc.__traceback__)[-1]
        row["reason"] = (
            f"error: {type(exc).__name__}: {exc} ({Path(last.filename).name}:{last.lineno})"
        ).replace("\n", " ")
    row["wall_time"] = round(time.perf_counter() - wall0, 4)
    row["cpu_time"] = round(time.process_time() - cpu0, 4)
    row["log"] = log if log and Path(log).is_file() else ""
    return row


def _drop_part_on_full_disk(exc: BaseException, log: str) -> None:
    """A run stopped by a full disk leaves no ``.part`` (as ``replay run`` does): what it holds
    is not worth the disk it fills."""
    import errno

    from replay.log.errors import LogWriteError
    from replay.log.output import own_part

    if log and isinstance(exc, LogWriteError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        part = own_part(Path(log))
        if part is not None:
            part.unlink(missing_ok=True)


def load_function(ref: str):
    """``package.module:function`` -> the function. A module its package lists as moved (a
    ``MOVED = {old: new}`` in the top-level package, e.g. ``analysis``) is found at its new
    name, so that an old sweep table or sweep file still loads."""
    import importlib

    module, _, name = ref.partition(":")
    try:
        found = importlib.import_module(module)
    except ModuleNotFoundError as exc:
        moved = getattr(importlib.import_module(module.split(".")[0]), "MOVED", {})
        if exc.name != module or module not in moved:
            raise
        found = importlib.import_module(moved[module])
    return getattr(found, name)


def _extract(ref: str, runner, log: str) -> dict:
    """Extra table columns read by the sweep's ``metrics`` function from the variant's log, or
    from its messages kept in memory when it has none."""
    from replay.log import LogReader
    from replay.log.memory import KeptLog

    kept = runner.log
    reader = kept.reader() if isinstance(kept, KeptLog) else LogReader(log)
    return dict(load_function(ref)(reader) or {})


def _cell(v: Any) -> Any:
    """A metric as a CSV cell: numbers and strings as they are, the rest as JSON."""
    import json

    if isinstance(v, bool) or v is None or isinstance(v, (int, str)):
        return v
    if isinstance(v, float):
        return v if math.isfinite(v) else str(v)
    return json.dumps(v, separators=(",", ":"))
