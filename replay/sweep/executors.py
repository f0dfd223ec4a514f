"""Where variants run: a local process pool, or Ray tasks (one machine or a cluster).

Both take task dicts and yield rows as they finish, in completion order; the engine orders the
table. Ray is optional (``pip install 'paper-replay[cluster]'``): ``address=None`` starts a private
local instance (127.0.0.1, ``workers`` CPUs, no dashboard) and shuts it down at the end;
``address="auto"`` or ``"HOST:PORT"`` joins an existing cluster, which then sets the parallelism.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from typing import Iterator

from replay.sweep.worker import run_variant

EXECUTORS = ("local", "ray")


class ExecutorError(Exception):
    """The executor cannot start (Ray missing, no cluster at the address)."""


def crashed(task: dict, exc: BaseException) -> dict:
    """The row of a variant whose worker died under it."""
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
    return {
        "key": task["key"],
        "index": task["index"],
        "success": False,
        "reason": f"error: worker died: {type(exc).__name__}{': ' + text if text else ''}",
        "wall_time": "",
        "cpu_time": "",
        "log": "",
    }


def default_workers() -> int:
    return max(
        1,
        len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1),
    )


def run_local(tasks: list[dict], workers: int) -> Iterator[dict]:
    """A pool of ``workers`` processes (forked: the imports are already paid for)."""
    if not tasks:
        return
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else None
    pool = ProcessPoolExecutor(max_workers=max(1, min(workers, len(tasks))), mp_context=ctx)
    try:
        of = {pool.submit(run_variant, t): t for t in tasks}
        pending = set(of)
        while pending:
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for f in done:
                try:
                    yield f.result()
                except Exception as exc:  # noqa: BLE001 - a dead worker (a crash in C code)
                    yield crashed(of[f], exc)
    except BaseException:  # Ctrl-C, or the consumer stopped: do not wait for them
        for proc in list(getattr(pool, "_processes", {}).values()):
            proc.terminate()
        pool.shutdown(wait=False, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def ray_available() -> bool:
    try:
        import ray  # noqa: F401
    except ImportError:
        return False
    return True


last_ray_init = float("nan")  # s the last ray.init took (bench, tests)
INIT_ATTEMPTS = 3  # Ray gives its raylet 30 s to register; on a loaded machine, try again


def _init_ray(ray, workers: int, address: str | None) -> float:
    """Start a private local Ray (or join ``address``); the seconds it took."""
    kw = dict(log_to_driver=False, logging_level="ERROR")
    if not address:
        kw.update(num_cpus=workers, include_dashboard=False, _node_ip_address="127.0.0.1")
    # the raylet waits for its agents' port files; on a loaded machine they start slowly
    os.environ.setdefault("RAY_agent_register_timeout_ms", "120000")
    t0 = time.perf_counter()
    for attempt in range(INIT_ATTEMPTS):
        try:
            ray.init(address=address, **kw)
            return time.perf_counter() - t0
        except Exception as exc:  # noqa: BLE001 - Ray raises bare Exception on timeouts
            ray.shutdown()
            if address or attempt == INIT_ATTEMPTS - 1:
                text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
                raise ExecutorError(
                    f"cannot start or join Ray{' at ' + address if address else ''}: {text}"
                ) from None
    return time.perf_counter() - t0


def run_ray(tasks: list[dict], workers: int, address: str | None = None) -> Iterator[dict]:
    try:
        import ray
    except ImportError:
        raise ExecutorError(
            "--executor ray needs Ray: pip install 'paper-replay[cluster]'"
        ) from None
    global last_ray_init
    started = False
    if not ray.is_initialized():
        last_ray_init = _init_ray(ray, workers, address)
        started = True
    try:
        remote = ray.remote(num_cpus=1, max_retries=0)(run_variant)
        of = {remote.remote(t): t for t in tasks}
        pending = list(of)
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                try:
                    yield ray.get(ref)
                except Exception as exc:  # noqa: BLE001 - a dead worker or a lost node
                    yield crashed(of[ref], exc)
    finally:
        if started:
            ray.shutdown()
