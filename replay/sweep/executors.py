"""Where variants run: a local process pool, or Ray tasks (one machine or a cluster).

Both take task dicts and yield rows as they finish, in completion order; the engine orders the
table. Ray is optional (``pip install 'paper-replay[cluster]'``): ``address=None`` starts a private
local instance (:mod:`.ray_local`: 127.0.0.1 only, ``workers`` CPUs, no dashboard, gone when the
sweep ends or dies); ``address="auto"`` or ``"HOST:PORT"`` joins an existing cluster, which then
sets the parallelism, and leaves it running.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import re
import signal
import socket
import sys
import threading
import time
from multiprocessing.connection import wait as mp_wait
from typing import Iterator

from replay.sweep import ray_local
from replay.sweep.worker import run_variant

EXECUTORS = ("local", "ray")


class ExecutorError(Exception):
    """The executor cannot start (Ray missing, no cluster at the address)."""


def crashed(task: dict, exc: BaseException | str) -> dict:
    """The row of a variant whose worker died under it."""
    if isinstance(exc, str):
        why = exc
    else:
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        why = f"{type(exc).__name__}{': ' + text if text else ''}"
    return {
        "key": task["key"],
        "index": task["index"],
        "success": False,
        "reason": f"{WORKER_DIED}{why}",
        "wall_time": "",
        "cpu_time": "",
        "log": "",
    }


WORKER_DIED = "error: worker died: "  # a row's reason: the variant did not finish (rerun it)
_RAY_NODE = re.compile(r"Node IP: ([0-9A-Fa-f.:\[\]]+), node ID: ([0-9a-f]+)")
STOP_GRACE = 5.0  # s a worker has to close its log as interrupted before it is killed


def default_workers() -> int:
    return max(
        1,
        len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1),
    )


def _died(exitcode: int | None) -> str:
    if exitcode is not None and exitcode < 0:
        try:
            name = signal.Signals(-exitcode).name
        except ValueError:
            name = f"signal {-exitcode}"
        hint = " (out of memory?)" if -exitcode == signal.SIGKILL else ""
        return f"killed by {name}{hint}"
    return f"exited with code {exitcode}"


def _die_with(parent: int) -> None:
    """In a worker: SIGTERM when the sweep's process dies (Linux ``PR_SET_PDEATHSIG``, and a
    watchdog thread wherever that is missing or was set too late), SIGTERM being a Ctrl-C here
    (the variant's log closed as interrupted); killed outright if that does not end it."""
    signal.signal(signal.SIGTERM, _as_interrupt)
    if sys.platform.startswith("linux"):
        try:
            import ctypes

            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(1, signal.SIGTERM, 0, 0, 0)  # PR_SET_PDEATHSIG
        except (OSError, AttributeError):
            pass

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(STOP_GRACE)
        os._exit(1)

    threading.Thread(target=watch, daemon=True, name="die-with-parent").start()


def _as_interrupt(signum, frame) -> None:
    """SIGTERM in a worker: what Ctrl-C does there (its handler holds it while a log record or
    the log's close is written, then raises KeyboardInterrupt), once a variant: a second one
    (the watchdog's after the kernel's, the sweep's after a group's) would break the log's
    close and leave its ``.part``; a worker that does not end is killed after ``STOP_GRACE``."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    handler = signal.getsignal(signal.SIGINT)
    if not callable(handler):
        raise KeyboardInterrupt
    handler(signal.SIGINT, frame)


def _serve(conn, parent: int, not_ours: list) -> None:
    """A worker: variants in, rows out, until the pipe closes, or is reset (the sweep stopped
    with a row of this worker's unread). ``not_ours``: the sweep's ends of the pipes, this
    worker's and those of the workers forked before it, which a fork copies: closed here, so
    that the sweep closing its end is an end of input (``EOFError``) for this worker, instead
    of a wait for the kill after ``STOP_GRACE``."""
    for end in not_ours:
        end.close()
    _die_with(parent)
    try:
        while True:
            signal.signal(signal.SIGTERM, _as_interrupt)  # (again: one a variant, see there)
            try:
                task = conn.recv()
            except EOFError:
                return
            conn.send(run_variant(task))
    except (KeyboardInterrupt, ConnectionError, EOFError):
        return
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)  # (a late stop ends it quietly)


def run_local(tasks: list[dict], workers: int) -> Iterator[dict]:
    """``workers`` processes (forked: the imports are already paid for), each given one variant
    at a time, so the variant a worker was running when it died (the OOM killer, a crash in C
    code) is the only one that fails: the worker is replaced and the rest go on. Workers die
    with this process (SIGTERM, SIGKILL), and are stopped when the consumer stops (Ctrl-C)."""
    if not tasks:
        return
    ctx = mp.get_context("fork") if "fork" in mp.get_all_start_methods() else mp.get_context()
    queue = list(reversed(tasks))
    n = max(1, min(workers, len(tasks)))
    procs: dict = {}  # conn -> process
    running: dict = {}  # conn -> its task

    def start() -> None:
        ours, theirs = ctx.Pipe()
        proc = ctx.Process(target=_serve, args=(theirs, os.getpid(), [ours, *procs]), daemon=True)
        proc.start()
        theirs.close()
        procs[ours] = proc

    def give(conn) -> None:
        if queue:
            running[conn] = queue.pop()
            conn.send(running[conn])

    try:
        for _ in range(n):
            start()
        for conn in list(procs):
            give(conn)
        while running:
            by_sentinel = {procs[c].sentinel: c for c in running}
            ready = mp_wait(list(running) + list(by_sentinel))
            seen = set()
            for item in ready:
                conn = by_sentinel.get(item, item)
                if conn in seen or conn not in running:
                    continue
                seen.add(conn)
                row = None
                try:
                    if conn.poll():
                        row = conn.recv()
                except (EOFError, OSError):
                    row = None
                if row is not None:
                    del running[conn]
                    yield row
                    give(conn)
                    continue
                if procs[conn].is_alive():
                    continue  # (woken by the other one of its pair)
                task = running.pop(conn)
                procs[conn].join()
                why = _died(procs.pop(conn).exitcode)
                conn.close()
                yield crashed(task, why)
                if queue:  # a new worker for the rest
                    start()
                    give(list(procs)[-1])
    finally:  # done, Ctrl-C, SIGTERM or the consumer stopped: no worker outlives this
        _stop(procs)


def _stop(procs: dict) -> None:
    for conn in procs:
        conn.close()  # an idle worker ends at once
    busy = []
    for p in procs.values():
        p.join(0.2)
        if p.is_alive():
            with contextlib.suppress(OSError):
                p.terminate()  # a running one closes its log as interrupted
            busy.append(p)
    deadline = time.monotonic() + STOP_GRACE
    for p in busy:
        p.join(max(0.0, deadline - time.monotonic()))
        if p.is_alive():
            p.kill()
            p.join()


last_ray_init = float("nan")  # s starting or joining Ray took (bench, tests)
PROBE_TIMEOUT = 5.0  # s to wait for a cluster's head to accept a connection


def _check_reachable(address: str) -> None:
    """Fail fast where nothing listens at ``HOST:PORT``: ``ray.init`` retries for minutes."""
    if address == "auto" or "://" in address:
        return  # (Ray finds "auto" itself; a ray:// client address is Ray's to check)
    host, sep, port = address.rpartition(":")
    host = host.strip("[]")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise ExecutorError(f"--address {address!r}: expected HOST:PORT or auto")
    try:
        with socket.create_connection((host, int(port)), timeout=PROBE_TIMEOUT):
            pass
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise ExecutorError(f"no Ray cluster answers at {address!r}: {why}") from None


def _start_ray(ray, workers: int, address: str | None):
    """Join ``address``, or start a private local Ray and join it (:mod:`.ray_local`); the
    private cluster's handle (None when joining)."""
    where = f" at {address}" if address else ""
    cluster = None
    if address:
        _check_reachable(address)
    try:
        if address:
            ray.init(address=address, log_to_driver=False, logging_level="ERROR")
        else:
            cluster = ray_local.PrivateRay(workers)
            ray_local.connect(ray, cluster)
    except BaseException as exc:  # (Ray raises bare Exception on timeouts)
        ray.shutdown()
        if cluster is not None:
            cluster.close()
        if not isinstance(exc, Exception):
            raise  # Ctrl-C while starting
        text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ExecutorError(f"cannot start or join Ray{where}: {text}") from None
    return cluster


def _lost(exc: Exception) -> Exception | str:
    """A Ray error that names a lost node (``NodeDiedError``: the node's raylet was killed, the
    machine went away) as one short line naming it; any other error as it is."""
    node = _RAY_NODE.search(str(exc))
    if node is None:
        return exc
    return f"node {node[1]} (ID {node[2]}) is dead or unavailable ({type(exc).__name__})"


def run_ray(tasks: list[dict], workers: int, address: str | None = None) -> Iterator[dict]:
    try:
        import ray
    except ImportError:
        raise ExecutorError(
            "--executor ray needs Ray: pip install 'paper-replay[cluster]'"
        ) from None
    global last_ray_init
    started = not ray.is_initialized()  # (else: a Ray this process joined before, kept)
    cluster = None
    if started:
        t0 = time.perf_counter()
        cluster = _start_ray(ray, workers, address)
        last_ray_init = time.perf_counter() - t0
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
                    yield crashed(of[ref], _lost(exc))
    finally:
        if started:
            try:
                ray.shutdown()
            finally:
                if cluster is not None:
                    cluster.close()
