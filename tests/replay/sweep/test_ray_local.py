"""A private local Ray (``replay sweep --executor ray`` without ``--address``, issue #36): every
listener of its processes is on loopback, and none of them outlives the sweep, ended or SIGKILLed.
The cluster is told apart from anything else on the machine by its session: the keeper that the
sweep starts leads one, and every Ray process lives in it (see replay/sweep/ray_local.py)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from ray_procs import listeners as _listeners
from ray_procs import loopback as _loopback
from ray_procs import procs as _procs
from ray_procs import session as _session
from ray_procs import wait_for as _wait
from ray_procs import ending

from replay.sweep import ray_local
from replay.sweep.table import read_table

ROOT = Path(__file__).resolve().parents[3]
GONE_WITHIN = 30.0  # s after the sweep ends or dies
STARTS_WITHIN = 120.0  # s for Ray to come up on a loaded machine


def _keeper(sweep: int) -> int | None:
    """The pid of the sweep's keeper: its child that leads a session and runs ray_local."""
    for p, (ppid, sid, _, _) in _procs().items():
        if ppid == sweep and sid == p and _cmdline(p)[2:3] == ["replay.sweep.ray_local"]:
            return p  # (once exec'd: a fresh fork still shows the sweep's command)
    return None


def _cmdline(pid: int) -> list[str]:
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().decode(errors="replace").split("\0")
    except OSError:
        return []


def _temp_dir(keeper: int) -> Path:
    return Path(_cmdline(keeper)[4])  # python -m replay.sweep.ray_local WORKERS TEMP_DIR


def _sweep(out: Path, frictions: int, *extra: str, env=None) -> subprocess.Popen:
    grid = ",".join(f"{i / frictions:.3f}" for i in range(frictions))
    return subprocess.Popen(
        [sys.executable, "-m", "replay.cli", "sweep", "scenarios/stick_3step.yaml"]
        + ["--grid", f"plant.params.stick.friction={grid}", "--set", "timing.duration=0.33"]
        + ["--executor", "ray", "--workers", "2", "--no-logs", "-q", "-o", str(out), *extra],
        cwd=ROOT,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def test_loopback_is_a_loopback_address():
    assert all(
        map(_loopback, ["127.0.0.1:80", "[::1]:80", "[::ffff:127.0.0.1]:80", "127.0.0.53%lo:53"])
    )
    assert not any(
        map(_loopback, ["*:80", "0.0.0.0:80", "[::]:80", "192.0.2.2:80", "[::ffff:10.0.0.1]:80"])
    )


KEEPER_LIKE = """
import os, subprocess, sys
from replay.sweep import ray_local
ray_local._subreaper()
quiet = dict(stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
inside = subprocess.Popen(["sleep", "60"], **quiet)  # in the session
# a process that leaves the session, then its parent exits
escape = "import subprocess as s; print(s.Popen(['sleep', '60'], start_new_session=True, " + \\
    "stdin=s.DEVNULL, stdout=s.DEVNULL, stderr=s.DEVNULL).pid)"
escaped = subprocess.run([sys.executable, "-c", escape], capture_output=True, text=True).stdout
print(inside.pid, escaped.strip(), flush=True)
sys.stdin.read()
ray_local.kill_session(os.getsid(0), adopted=True)
"""


def test_the_keeper_clears_its_session_and_the_orphans_that_left_it():
    """No Ray: what the keeper does when its pipe closes, on a process that left the session."""
    keeper = subprocess.Popen(
        [sys.executable, "-c", KEEPER_LIKE],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    with ending(keeper):
        inside, escaped = map(int, keeper.stdout.readline().split())  # type: ignore[union-attr]
        procs = _procs()
        assert procs[inside][1] == keeper.pid and procs[escaped][1] != keeper.pid
        assert procs[escaped][0] == keeper.pid  # (adopted: a subreaper)
        keeper.stdin.close()  # type: ignore[union-attr]
        assert keeper.wait(GONE_WITHIN) == 0
    assert not {inside, escaped} & set(_procs())


def test_private_ray_listens_on_loopback_only_and_ends_with_the_sweep(tmp_path):
    with ending(_sweep(tmp_path / "S", 3)) as sweep:
        keeper = _wait(lambda: _keeper(sweep.pid), STARTS_WITHIN, sweep)
        assert keeper, sweep.communicate()
        temp_dir = _temp_dir(keeper)
        seen: dict[str, set[str]] = {}  # process name -> its listening addresses
        while sweep.poll() is None:  # every Ray process of this sweep, and the sweep (a driver)
            ours = _session(keeper) | {sweep.pid: "sweep"}
            for pid, address, line in _listeners():
                if pid in ours:
                    seen.setdefault(ours[pid], set()).add(address)
                    assert _loopback(address), f"a Ray listener not on loopback: {line}"
            time.sleep(0.2)
        out, err = sweep.communicate()
    assert sweep.returncode == 0, err
    assert "3 ran" in out and len(read_table(tmp_path / "S" / "table.csv")) == 3
    assert {"gcs_server", "raylet", "sweep"} <= set(seen), seen  # (the watch saw them)
    assert _wait(lambda: not _session(keeper), GONE_WITHIN), f"left: {_session(keeper)}"
    assert not temp_dir.exists()


def test_a_sigkilled_sweep_leaves_no_ray_process(tmp_path):
    with ending(_sweep(tmp_path / "K", 40)) as sweep:
        keeper = _wait(lambda: _keeper(sweep.pid), STARTS_WITHIN, sweep)
        assert keeper, sweep.communicate()
        temp_dir = _temp_dir(keeper)

        def running():  # variants on Ray's workers, the agents up
            names = list(_session(keeper).values())
            return any(n.startswith("ray::run_var") for n in names) and any(
                n.startswith("ray::RuntimeEnv") for n in names
            )

        assert _wait(running, STARTS_WITHIN, sweep), (_session(keeper), sweep.poll())
        cluster = _session(keeper)
        assert {"gcs_server", "raylet"} <= set(cluster.values()), cluster
        t0 = time.monotonic()
        sweep.kill()  # SIGKILL: no finally, no atexit
        sweep.communicate()
    assert sweep.returncode == -signal.SIGKILL  # (killed while variants still ran)
    assert _wait(lambda: not _session(keeper), GONE_WITHIN), f"left: {_session(keeper)}"
    print(f"the cluster's {len(cluster)} processes were gone {time.monotonic() - t0:.1f} s after")
    assert not set(cluster) & set(_procs())  # (none of them went elsewhere either)
    assert not temp_dir.exists()


def test_address_joins_a_running_cluster_and_leaves_it_running(tmp_path):
    theirs = ray_local.PrivateRay(1)  # someone's cluster on this machine (loopback, token)
    try:
        # its servers and agents (an idle worker may be retired at any time)
        cluster = {p: n for p, n in _session(theirs.keeper.pid).items() if n != "ray::IDLE"}
        env = dict(os.environ, RAY_AUTH_MODE="token", **ray_local.ENV)  # (how one joins it)
        with ending(_sweep(tmp_path / "J", 2, "--address", theirs.address, env=env)) as sweep:
            out, err = sweep.communicate(timeout=STARTS_WITHIN)
        assert sweep.returncode == 0, err
        assert "2 ran" in out
        lost = {p: name for p, name in cluster.items() if p not in _procs()}
        assert not lost, f"the joined cluster lost {lost}"
        assert theirs.keeper.poll() is None
    finally:
        theirs.close()
    assert not _session(theirs.keeper.pid)


def test_the_keeper_removes_only_a_folder_it_was_made_for(tmp_path):
    """The keeper deletes its folder at the end: run by hand on any other folder it refuses
    before starting anything, and remove_temp leaves such a folder alone."""
    from replay.sweep.ray_local import made_here, remove_temp

    mine = tmp_path / "replay-ray-x"  # the right name, not in the temporary directory
    mine.mkdir()
    (mine / "keep.txt").write_text("keep")
    assert not made_here(str(mine)) and not made_here(str(tmp_path))
    remove_temp(str(mine))
    # the right name in the temporary directory, but another program's (no marker): kept
    import tempfile

    theirs = Path(tempfile.mkdtemp(prefix="replay-ray-"))
    try:
        (theirs / "keep.txt").write_text("keep")
        assert not made_here(str(theirs))
        remove_temp(str(theirs))
        assert (theirs / "keep.txt").read_text() == "keep"
    finally:
        (theirs / "keep.txt").unlink()
        theirs.rmdir()
    r = subprocess.run(
        [sys.executable, "-m", "replay.sweep.ray_local", "1", str(mine)],
        capture_output=True,
        text=True,
        timeout=60,
        stdin=subprocess.DEVNULL,
    )
    assert r.returncode != 0 and "not a folder PrivateRay made" in r.stderr
    assert (mine / "keep.txt").read_text() == "keep"


def test_an_address_nothing_answers_at_fails_in_seconds(tmp_path):
    """``ray.init`` retries an unreachable head for minutes: the sweep says so at once."""
    with socket.socket() as s:  # a loopback port that nobody listens on
        s.bind(("127.0.0.1", 0))
        free = s.getsockname()[1]
    for address, words in [
        (f"127.0.0.1:{free}", "no Ray cluster answers at '127.0.0.1:"),
        ("999.1.1.1:1", "no Ray cluster answers at '999.1.1.1:1'"),
        ("nonsense", "expected HOST:PORT or auto"),
        ("127.0.0.1:99999", "expected HOST:PORT or auto"),
    ]:
        t0 = time.monotonic()
        r = subprocess.run(
            [sys.executable, "-m", "replay.entry", "sweep", "stick_3step", "--grid", "seed=1,2"]
            + ["--executor", "ray", "--address", address, "--no-logs", "-o", str(tmp_path / "s")],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert r.returncode == 2 and words in r.stderr, (address, r.stderr)
        assert time.monotonic() - t0 < 60.0 and "Traceback" not in r.stderr
