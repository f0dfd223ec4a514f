"""``replay sweep --executor ray --address`` against a Ray cluster started outside it (issue #41):
a head and a second node on this machine, one CPU each, started with ``ray start``. The sweep's
table equals the local pool's row for row; a node SIGKILLed mid-sweep loses only the variant it
was running (a row naming the node, not a hang), and a rerun redoes only that one.

Every Ray process of the test lives in one of two sessions (one per ``ray start``) and listens on
loopback only; the test kills both sessions at the end (``ray stop`` would stop every Ray of this
user on the machine) and removes its folder.

On Linux Ray swaps a node's 127.0.0.1 for the host's external address unless
``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``, and with that setting ``ray start --address`` refuses to
start a second node: the second node runs Ray's own ``ray start`` with that check lifted and the
swap off (:data:`SECOND_NODE`). A cluster across machines needs neither.
"""

from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest
from ray_procs import ending, listeners, loopback, session, wait_for

from replay.sweep.executors import WORKER_DIED, _lost
from replay.sweep.ray_local import kill_session
from replay.sweep.table import read_table

pytest.importorskip("ray")

ROOT = Path(__file__).resolve().parents[3]
STARTS_WITHIN = 120.0  # s for a node to come up on a loaded machine
ENDS_WITHIN = 120.0  # s for a sweep of six short variants, a lost node included
# the variants: six throws of the stick at different frictions, 1.8 s each (~0.2 s of CPU)
GRID = ["--grid", "plant.params.stick.friction=0,0.2,0.4,0.6,0.8,1.0"]
SETS = ["--set", "timing.physics_rate=12000"]
TIMES = ("wall_time", "cpu_time", "log")  # what differs between two runs of the same variant

SECOND_NODE = """
import sys
from ray._private import ray_constants, services
ray_constants.ENABLE_RAY_CLUSTER = True  # (the multi-node check only: the env var stays 0)
services.resolve_ip_for_localhost = lambda host: host  # 127.0.0.1 stays 127.0.0.1
from ray.scripts.scripts import main
sys.argv[0] = "ray"
main()
"""


def _env(temp: Path) -> dict[str, str]:
    """Loopback nodes, no usage report, the cluster's own token (not ~/.ray's)."""
    return dict(
        os.environ,
        RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER="0",
        RAY_USAGE_STATS_ENABLED="0",
        RAY_AUTH_MODE="token",
        RAY_AUTH_TOKEN_PATH=str(temp / "auth_token"),
    )


def _start(argv: list[str], temp: Path, log: str) -> int:
    """Run a ``ray start`` in a new session: the session's id (every process of the node)."""
    with open(temp / log, "wb") as out:
        proc = subprocess.Popen(
            argv,
            env=_env(temp),
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        try:
            code = proc.wait(STARTS_WITHIN)
        except subprocess.TimeoutExpired:
            code = None
    if code != 0:
        kill_session(proc.pid)
        pytest.fail(f"{argv[2:4]} failed: {(temp / log).read_text()[-2000:]}")
    return proc.pid


@contextlib.contextmanager
def _cluster():
    """(address, temp folder, head session, second node session); all of it gone afterwards."""
    temp = Path(tempfile.mkdtemp(prefix="replay-raycl-"))  # (short: Ray's sockets live in it)
    (temp / "auth_token").write_text(secrets.token_hex(32))
    (temp / "auth_token").chmod(0o600)
    sessions: list[int] = []
    try:
        ray = str(Path(sys.executable).with_name("ray"))
        node = ["--num-cpus=1", "--node-ip-address=127.0.0.1", "--disable-usage-stats"]
        sessions.append(
            _start(
                [ray, "start", "--head", "--port=0", "--include-dashboard=false"]
                + [f"--temp-dir={temp}", *node],
                temp,
                "head.log",
            )
        )
        address = (temp / "ray_current_cluster").read_text().strip()
        second = [sys.executable, "-c", SECOND_NODE, "start", f"--address={address}", *node]
        sessions.append(_start(second, temp, "node.log"))
        yield address, temp, *sessions
    finally:
        for sid in sessions:
            kill_session(sid)
        left = wait_for(lambda: not any(map(session, sessions)), 30.0)
        shutil.rmtree(temp, ignore_errors=True)
        assert left, f"left: {[session(s) for s in sessions]}"


def _sweep(out: Path, *extra: str, env=None) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-m", "replay.cli", "sweep", "scenarios/stick_3step.yaml", *GRID, *SETS]
        + ["--workers", "2", "--no-logs", "-q", "-o", str(out), *extra],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _ended(sweep: subprocess.Popen) -> str:
    """The sweep's summary line, once it has ended by itself (within ENDS_WITHIN s) and well."""
    try:
        out, err = sweep.communicate(timeout=ENDS_WITHIN)
    except subprocess.TimeoutExpired:
        sweep.kill()
        out, err = sweep.communicate()
        pytest.fail(f"the sweep did not end within {ENDS_WITHIN} s: {err[-2000:]}")
    assert sweep.returncode == 0, err
    return out


def _outcomes(folder: Path) -> list[dict]:
    """The table's rows in order, without what differs between two runs of the same variant."""
    rows = sorted(read_table(folder / "table.csv"), key=lambda r: int(r["index"]))
    return [{k: v for k, v in r.items() if k not in TIMES} for r in rows]


def _running(sid: int) -> int:
    return sum(name.startswith("ray::run_var") for name in session(sid).values())


def _signal(sid: int, sig: int) -> None:
    for pid in session(sid):
        with contextlib.suppress(ProcessLookupError):
            os.kill(pid, sig)


def _kill_while_running(sid: int, sweep: subprocess.Popen) -> int:
    """SIGKILL every process of the node while it runs a variant, as when its machine goes away:
    the number it ran. (Its raylet's group alone is not enough: the raylet starts its workers in
    groups of their own, and a worker left alive finishes its variant and returns the row.) The node is stopped first
    (SIGSTOP), so what it runs cannot end between the look and the kill; a node found idle is
    let go on and looked at again."""
    while sweep.poll() is None:
        if wait_for(lambda: _running(sid), ENDS_WITHIN, sweep):
            _signal(sid, signal.SIGSTOP)
            running = _running(sid)
            if running:
                kill_session(sid)
                return running
            _signal(sid, signal.SIGCONT)
    pytest.fail(f"the sweep ended before a variant ran on the second node: {sweep.communicate()}")


def test_a_lost_node_is_named_in_one_line():
    text = (
        "Task failed because the node it was running on is dead or unavailable. Node IP: "
        "127.0.0.1, node ID: 5d063415. This can happen if the node was preempted, ..."
    )
    assert _lost(RuntimeError(text)) == (
        "node 127.0.0.1 (ID 5d063415) is dead or unavailable (RuntimeError)"
    )
    other = RuntimeError("The worker died unexpectedly")
    assert _lost(other) is other


def test_a_cluster_gives_the_local_table_and_a_lost_node_only_its_variant(tmp_path):
    local = _sweep(tmp_path / "local")  # (runs while the cluster starts)
    with ending(local), _cluster() as (address, temp, head, second):
        ray = ["--executor", "ray", "--address", address]
        seen: dict[str, set[str]] = {}  # process name -> its listening addresses
        with ending(_sweep(tmp_path / "cluster", *ray, env=_env(temp))) as sweep:
            while sweep.poll() is None:
                ours = session(head) | session(second) | {sweep.pid: "sweep"}
                for pid, where, line in listeners():
                    if pid in ours:
                        seen.setdefault(ours[pid], set()).add(where)
                        assert loopback(where), f"a Ray listener not on loopback: {line}"
                time.sleep(0.2)
            assert "6 ran" in _ended(sweep)
        assert {"gcs_server", "raylet"} <= set(seen), seen  # (the watch saw them)
        assert "6 ran" in _ended(local)
        assert _outcomes(tmp_path / "cluster") == _outcomes(tmp_path / "local")

        with ending(_sweep(tmp_path / "killed", *ray, env=_env(temp))) as killed:
            t0 = time.monotonic()
            running = _kill_while_running(second, killed)
            _ended(killed)
        print(f"the sweep ended {time.monotonic() - t0:.1f} s after the node was killed")
        assert wait_for(lambda: not session(second), 30.0), session(second)
        rows = read_table(tmp_path / "killed" / "table.csv")
        lost = [r for r in rows if r["reason"].startswith(WORKER_DIED)]
        assert 1 <= len(lost) <= running, lost  # (one CPU: one variant at a time)
        assert all(r["reason"].startswith(f"{WORKER_DIED}node 127.0.0.1 (ID ") for r in lost), lost
        rerun = _ended(_sweep(tmp_path / "killed", *ray, env=_env(temp)))  # the head alone
        assert f"{len(lost)} ran, {6 - len(lost)} skipped" in rerun, rerun
        assert _outcomes(tmp_path / "killed") == _outcomes(tmp_path / "local")
