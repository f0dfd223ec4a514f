"""A private local Ray for ``replay sweep --executor ray`` without ``--address``: loopback only,
and nothing of it outlives the sweep, even a SIGKILLed one.

Loopback: Ray binds its servers (GCS, raylet and object manager, workers, dashboard and
runtime-env agents, metrics export) to 127.0.0.1 only when the node's address is loopback, but on
Linux it swaps a loopback address for the host's external one (``resolve_ip_for_localhost``)
unless ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``. The cluster runs with that variable and
``127.0.0.1``; the sweep joins it with the same setting (:func:`connect`).

Lifetime: the sweep does not start Ray itself. It starts a keeper (``python -m
replay.sweep.ray_local``): a process in a session of its own (a Ctrl-C on the terminal does not
reach it) and a child subreaper (Ray's orphans come back to it, not to init), which starts Ray
as a head node, writes its address on stdout and then reads stdin, a pipe whose only writer is
the sweep. When that pipe closes (the sweep ended, raised, was interrupted, or was SIGKILLed: the
kernel closes the pipe) the keeper SIGKILLs every process of its session and below it, removes
Ray's temp folder and exits. Ray's own state is all in that folder; nothing is flushed on the way.
"""

from __future__ import annotations

import contextlib
import logging
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

LOCAL_IP = "127.0.0.1"
ENV = {
    "RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER": "0",  # keep 127.0.0.1 as the node's address
    "RAY_USAGE_STATS_ENABLED": "0",  # a private cluster reports nothing
}
INIT_ATTEMPTS = 3  # Ray gives its raylet 30 s to register; on a loaded machine, try again
CLOSE_WAIT = 10.0  # s the sweep waits for the keeper to clear the cluster


TEMP_PREFIX = "replay-ray-"  # the cluster's folder: tempfile.mkdtemp(prefix=TEMP_PREFIX)
MARKER = (
    ".paper-replay-ray"  # written into it at once: a folder of that name without it is not ours
)


def make_temp() -> str:
    """A new cluster folder in the temporary directory, marked as this module's."""
    path = tempfile.mkdtemp(prefix=TEMP_PREFIX)
    (Path(path) / MARKER).write_text("made by paper-replay's private Ray cluster\n")
    return path


def made_here(path: str) -> bool:
    """Whether ``path`` is a cluster folder of this module's making (:func:`make_temp`): a real
    folder named ``TEMP_PREFIX...`` directly in the temporary directory, holding its marker file
    (never a path given otherwise, nor another program's folder of that name)."""
    p = Path(path)
    return (
        p.name.startswith(TEMP_PREFIX)
        and not p.is_symlink()
        and p.is_dir()
        and p.parent.resolve() == Path(tempfile.gettempdir()).resolve()
        and (p / MARKER).is_file()
        and not (p / MARKER).is_symlink()
    )


def remove_temp(path: str) -> None:
    """Remove the cluster's folder, and only if :func:`made_here`."""
    if made_here(path):
        shutil.rmtree(path, ignore_errors=True)


class StartError(Exception):
    """The keeper could not start Ray (its one-line reason)."""


class PrivateRay:
    """The sweep's handle on its keeper: ``address`` to join; :meth:`close` ends the cluster."""

    def __init__(self, workers: int) -> None:
        self.temp_dir = make_temp()
        env = {k: v for k, v in os.environ.items() if k != "RAY_ADDRESS"}
        env.setdefault("RAY_agent_register_timeout_ms", "120000")  # slow agents on a busy host
        env.update(ENV)
        self.keeper = subprocess.Popen(
            [sys.executable, "-m", __name__, str(workers), self.temp_dir],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            start_new_session=True,
        )
        try:
            line = self.keeper.stdout.readline().decode(errors="replace").strip()  # type: ignore[union-attr]
        except BaseException:
            self.close()
            raise
        if not line.startswith("address "):
            self.close()
            raise StartError(line.removeprefix("error: ") or "the Ray keeper exited")
        self.address = line.split(" ", 1)[1]

    def close(self) -> None:
        """End the cluster and wait (bounded) until it is gone."""
        with contextlib.suppress(OSError):
            self.keeper.stdin.close()  # type: ignore[union-attr]
        try:
            self.keeper.wait(CLOSE_WAIT)
        except subprocess.TimeoutExpired:  # (a stuck keeper: do its work)
            kill_session(self.keeper.pid)
            self.keeper.wait()
        with contextlib.suppress(OSError):
            self.keeper.stdout.close()  # type: ignore[union-attr]
        remove_temp(self.temp_dir)


@contextlib.contextmanager
def loopback_node(ray):
    """In the sweep's process, Ray reads ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER`` once, at import:
    while joining the private cluster, 127.0.0.1 stays 127.0.0.1."""
    constants = ray._private.ray_constants
    old = constants.ENABLE_RAY_CLUSTER
    constants.ENABLE_RAY_CLUSTER = False
    try:
        yield
    finally:
        constants.ENABLE_RAY_CLUSTER = old


def connect(ray, cluster: PrivateRay) -> None:
    """Join the private cluster, with the token Ray made for it (``~/.ray/auth_token``, as for
    any local ``ray.init()``; Ray asks for it only when joining a cluster it found itself)."""
    with contextlib.suppress(ImportError):
        from ray._private.authentication.authentication_token_setup import (
            maybe_enable_token_auth_if_token_available,
        )

        quiet = logging.getLogger(maybe_enable_token_auth_if_token_available.__module__)
        level = quiet.level
        quiet.setLevel(logging.ERROR)  # (a warning that the token is on: as it should be)
        try:
            maybe_enable_token_auth_if_token_available(warn_if_disabled=False)
        finally:
            quiet.setLevel(level)
    with loopback_node(ray):
        ray.init(
            address=cluster.address,
            _temp_dir=cluster.temp_dir,
            log_to_driver=False,
            logging_level=logging.ERROR,
        )


def _stat(pid: str) -> tuple[int, int, str] | None:
    """(parent, session, state) of a process, from /proc."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            fields = f.read().rsplit(b")", 1)[1].split()
    except OSError:
        return None
    return int(fields[1]), int(fields[3]), fields[0].decode()


def kill_session(sid: int, adopted: bool = False, deadline: float = 5.0) -> None:
    """SIGKILL every live process of session ``sid`` (and, ``adopted``, every child of this one: a
    subreaper's orphans) until none is left; this process is spared. Without /proc: its group."""
    me = os.getpid()
    if not os.path.isdir("/proc/self"):
        with contextlib.suppress(OSError):
            os.killpg(sid, signal.SIGKILL)
        return
    end = time.monotonic() + deadline
    while time.monotonic() < end:
        left = []
        for name in os.listdir("/proc"):
            info = _stat(name) if name.isdigit() and int(name) != me else None
            if not info or (info[2] == "Z" and info[0] != me):
                continue  # (gone, or a zombie for another parent to reap)
            if info[1] == sid or (adopted and info[0] == me):
                left.append(int(name))
        for pid in left:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
        if adopted:
            with contextlib.suppress(ChildProcessError):
                while os.waitpid(-1, os.WNOHANG)[0]:  # reap them
                    pass
        if not left:
            return
        time.sleep(0.02)


def _subreaper() -> None:
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(36, 1, 0, 0, 0)  # PR_SET_CHILD_SUBREAPER


def _keep(workers: int, temp_dir: str) -> None:
    """The keeper (see the module): start Ray, say where, clear it all when stdin closes."""
    # the pipes stay the keeper's (Ray's processes inherit 0, 1 and 2): stdout carries the
    # address only, whatever Ray prints goes to stderr
    out, pipe = os.fdopen(os.dup(1), "w"), os.dup(0)
    os.dup2(2, 1)
    os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
    _subreaper()

    def clear(*_) -> None:
        kill_session(os.getsid(0), adopted=True)
        remove_temp(temp_dir)
        os._exit(0)

    def watch() -> None:
        with contextlib.suppress(OSError):
            while os.read(pipe, 512):  # until the sweep closes the pipe or dies
                pass
        clear()

    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):  # (a kill aimed at the keeper)
        signal.signal(sig, clear)

    threading.Thread(target=watch, daemon=True, name="keeper").start()
    import ray

    for attempt in range(INIT_ATTEMPTS):
        try:
            ray.init(
                address="local",
                num_cpus=workers,
                include_dashboard=False,
                dashboard_host=LOCAL_IP,
                _node_ip_address=LOCAL_IP,
                _temp_dir=temp_dir,
                log_to_driver=False,
                logging_level=logging.ERROR,
            )
            break
        except Exception as exc:  # noqa: BLE001 - Ray raises bare Exception on timeouts
            ray.shutdown()
            if attempt == INIT_ATTEMPTS - 1:
                text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
                print(f"error: {text}", file=out, flush=True)
                threading.Event().wait()  # the sweep closes the pipe: watch() clears up
    signal.signal(signal.SIGTERM, clear)  # (again: Ray's own would leave the agents)
    with contextlib.suppress(OSError):
        print(f"address {ray.get_runtime_context().gcs_address}", file=out, flush=True)
    threading.Event().wait()


if __name__ == "__main__":
    if not made_here(sys.argv[2]):  # (the keeper removes its folder at the end: only its own)
        sys.exit(f"error: {sys.argv[2]!r} is not a folder PrivateRay made")
    _keep(int(sys.argv[1]), sys.argv[2])
