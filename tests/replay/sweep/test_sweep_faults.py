"""Sweeps that survive faults (issue #26): a dead worker fails only its own variant, a plain rerun
redoes what did not finish, --retry-failed moves only the failed rows, a folder is one sweep's
at a time, tables of different grids merge, workers die with their parent."""

from __future__ import annotations

import errno
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.sweep.engine import run_sweep
from replay.sweep.executors import WORKER_DIED
from replay.sweep.lock import FolderLock, SweepOutputError
from replay.sweep.spec import from_options
from replay.sweep.table import read_table
from replay.sweep.variants import expand

TESTS = Path(__file__).resolve().parents[2]
ROOT = TESTS.parent


def _sweep(toy_yaml, out, grid="plant.params.mass=1,2,3,4,5,6,7,8", version="test", **kw):
    spec = from_options([grid], [], None)
    kw.setdefault("workers", 2)
    kw.setdefault("progress", False)
    return run_sweep(expand(toy_yaml, spec, 0, version=version), out, **kw)


def _oom_at_mass_3(monkeypatch, marker: Path):
    """The worker running mass 3 is SIGKILLed (as the OOM killer would) while ``marker`` exists."""
    import toy_plugins

    init = toy_plugins.ToyPlant.__init__

    def dying(self, params, *, dt, rng):
        if params.mass == 3 and marker.exists():
            os.kill(os.getpid(), signal.SIGKILL)
        init(self, params, dt=dt, rng=rng)

    monkeypatch.setattr(toy_plugins.ToyPlant, "__init__", dying)


def test_a_dead_worker_fails_only_its_variant_and_a_rerun_redoes_it(
    toy_yaml, tmp_path, monkeypatch
):
    marker = tmp_path / "oom"
    marker.touch()
    _oom_at_mass_3(monkeypatch, marker)
    out = tmp_path / "D"
    s = _sweep(toy_yaml, out)
    rows = {r["plant.params.mass"]: r for r in read_table(out / "table.csv")}
    assert len(rows) == 8 and s.ran == 8
    dead = rows.pop("3")
    assert dead["reason"].startswith(WORKER_DIED) and "SIGKILL" in dead["reason"]
    assert all(r["success"] == "True" and Path(r["log"]).is_file() for r in rows.values())
    marker.unlink()  # memory enough now: the plain rerun runs the one that did not finish
    again = _sweep(toy_yaml, out)
    assert (again.ran, again.skipped) == (1, 7)
    rows = read_table(out / "table.csv")
    assert len(rows) == 8 and len({r["key"] for r in rows}) == 8
    assert all(r["success"] == "True" for r in rows)
    assert _sweep(toy_yaml, out).ran == 0


def test_a_variant_whose_log_is_gone_is_run_again(toy_yaml, tmp_path):
    out = tmp_path / "D"
    _sweep(toy_yaml, out, grid="plant.params.mass=1,2")
    gone = read_table(out / "table.csv")[1]["log"]
    Path(gone).unlink()
    s = _sweep(toy_yaml, out, grid="plant.params.mass=1,2")
    assert (s.ran, s.skipped) == (1, 1) and Path(gone).is_file()


def test_retry_failed_moves_only_the_failed_rows(toy_yaml, tmp_path):
    out = tmp_path / "D"
    grid = "plant.params.blow_up_at=-1,0.3,0.5"  # two NaN errors, one success
    _sweep(toy_yaml, out, grid=grid, keep_logs=False)
    before = {r["key"]: r for r in read_table(out / "table.csv")}
    failed = {k for k, r in before.items() if r["success"] == "False"}
    assert len(failed) == 2
    s = _sweep(toy_yaml, out, grid=grid, keep_logs=False, retry_failed=True)
    assert (s.ran, s.skipped, s.stale) == (2, 1, 0)
    assert not (out / "table.stale.csv").exists()
    after = {r["key"]: r for r in read_table(out / "table.csv")}
    assert set(after) == set(before)
    (ok,) = set(before) - failed
    assert after[ok]["wall_time"] == before[ok]["wall_time"]  # the success untouched


def test_different_grids_into_one_folder_merge(toy_yaml, tmp_path):
    out = tmp_path / "D"
    a = _sweep(toy_yaml, out, grid="plant.params.mass=1,2", keep_logs=False)
    b = _sweep(toy_yaml, out, grid="plant.params.x0=0.5,0.25,0.125", keep_logs=False)
    assert (a.ran, b.ran, b.stale) == (2, 3, 0)
    rows = read_table(out / "table.csv")
    assert len(rows) == 5 and len({r["key"] for r in rows}) == 5
    assert sorted(r["plant.params.mass"] for r in rows if r["plant.params.mass"]) == ["1", "2"]
    assert len([r for r in rows if r["plant.params.x0"]]) == 3
    again = _sweep(toy_yaml, out, grid="plant.params.mass=1,2", keep_logs=False)
    assert (again.ran, again.skipped) == (0, 2)
    assert len(read_table(out / "table.csv")) == 5
    assert [int(r["index"]) for r in read_table(out / "table.csv")] == list(range(5))


def test_rows_set_aside_accumulate_over_versions(toy_yaml, tmp_path):
    out = tmp_path / "D"
    keys = {}
    for v in ("v1", "v2", "v3"):
        _sweep(toy_yaml, out, grid="plant.params.mass=1,2", version=v, keep_logs=False)
        keys[v] = {r["key"] for r in read_table(out / "table.csv")}
    stale = {r["key"] for r in read_table(out / "table.stale.csv")}
    assert stale == keys["v1"] | keys["v2"] and len(stale) == 4
    assert keys["v3"].isdisjoint(stale)


def test_a_locked_folder_says_who_holds_it(toy_yaml, tmp_path):
    out = tmp_path / "D"
    out.mkdir()
    with FolderLock(out):
        with pytest.raises(SweepOutputError, match=f"in use by sweep process {os.getpid()}"):
            _sweep(toy_yaml, out, grid="plant.params.mass=1,2", keep_logs=False)
        r = CliRunner().invoke(
            main,
            ["sweep", str(toy_yaml), "--grid", "plant.params.mass=1", "-o", str(out), "-q"],
        )
        assert r.exit_code == 2 and "Traceback" not in r.output
        assert r.output.strip().startswith("error: sweep folder") and "in use" in r.output
    assert not (out / "table.csv").exists()
    assert _sweep(toy_yaml, out, grid="plant.params.mass=1,2", keep_logs=False).ran == 2


def test_the_lock_is_removed_when_the_sweep_ends_and_a_stale_one_taken_over(toy_yaml, tmp_path):
    out = tmp_path / "D"
    out.mkdir()
    (out / "sweep.lock").write_text("12345\n0\nreplay sweep (killed)\n")  # (unlocked: stale)
    assert _sweep(toy_yaml, out, grid="plant.params.mass=1,2", keep_logs=False).ran == 2
    assert sorted(p.name for p in out.iterdir()) == ["summary.csv", "table.csv"]


def test_a_lock_file_removed_under_a_sweep_is_opened_again(tmp_path, monkeypatch):
    """A sweep that opened the lock file just before the sweep holding it ended (and removed
    it) must not hold a lock on a file without a name: it opens the name again."""
    out = tmp_path / "D"
    out.mkdir()
    lock, opened = FolderLock(out), []
    real = FolderLock._lock

    def removed_once(self):
        fd = real(self)
        if not opened:
            os.unlink(self.path)  # (as the sweep that held it does when it ends)
        opened.append(fd)
        return fd

    monkeypatch.setattr(FolderLock, "_lock", removed_once)
    with lock:
        assert len(opened) == 2 and (out / "sweep.lock").is_file()
        assert os.fstat(opened[1]).st_ino == os.stat(out / "sweep.lock").st_ino
    assert not (out / "sweep.lock").exists()


def test_a_full_disk_is_one_line_exit_1_and_no_tmp_left(toy_yaml, tmp_path, monkeypatch):
    import replay.sweep.table as table

    real = table.os.replace

    def full(src, dst):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(table.os, "replace", full)
    out = tmp_path / "D"
    args = ["sweep", str(toy_yaml), "--grid", "plant.params.mass=1,2", "-o", str(out), "-q"]
    r = CliRunner().invoke(main, [*args, "--no-logs"])
    assert r.exit_code == 1 and "Traceback" not in r.output
    assert r.output.strip() == f"error: cannot write table {out / 'table.csv'}: " + os.strerror(
        errno.ENOSPC
    )
    assert sorted(p.name for p in out.iterdir()) == []  # (no table, no tmp, the lock removed)
    monkeypatch.setattr(table.os, "replace", real)


def test_an_unusable_sweep_folder_is_one_line(toy_yaml, tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    for out, code in ((afile / "D", 2),):
        r = CliRunner().invoke(
            main, ["sweep", str(toy_yaml), "--grid", "plant.params.mass=1", "-o", str(out)]
        )
        assert r.exit_code == code and "Traceback" not in r.output
        assert r.output.strip().startswith("error: cannot make sweep folder")


SLOW_SWEEP = r"""
import sys, time
sys.path.insert(0, {tests!r})
import toy_plugins; toy_plugins.install()
step = toy_plugins.ToyPlant.step
def slow(self):
    time.sleep(0.001)
    step(self)
toy_plugins.ToyPlant.step = slow
import replay.sweep.executors
replay.sweep.executors.STOP_GRACE = 60.0  # a worker that does not end by itself: the wait fails
from replay.cli import main
sys.argv = ["replay", "sweep", {yaml!r}, "--grid", "plant.params.mass=1,2,3,4,5,6",
            "-o", {out!r}, "--workers", "2", "-q", "--set", "timing.duration=60"]
main()
"""


def _children(pid: int) -> set[int]:
    try:
        text = Path(f"/proc/{pid}/task/{pid}/children").read_text()
    except OSError:
        return set()
    return {int(c) for c in text.split()}


def _alive(pid: int) -> bool:
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"  # a zombie has ended


def _start_slow_sweep(toy_yaml, out: Path):
    code = SLOW_SWEEP.format(tests=str(TESTS), yaml=str(toy_yaml), out=str(out))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        start_new_session=True,  # its own group: killed whole at the end whatever happens
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        workers = _children(proc.pid)
        if len(workers) == 2 and len(list(out.glob("logs/*.part"))) == 2:
            return proc, workers
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGKILL)
    pytest.fail("the sweep's workers did not start")


def _session(sid: int) -> set[int]:
    """Every live process of session ``sid`` (the sweep, its workers and anything they
    started): a survivor the workers' list taken at the start would miss is found here."""
    found = set()
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if fields[0] != "Z" and int(fields[3]) == sid:  # (state, ppid, pgrp, session)
            found.add(int(stat.parent.name))
    return found


def _lock_free_within(out: Path, seconds: float) -> None:
    """The folder's lock is free once every process that shared it has ended; the kernel may
    release it a moment after the last one reads as gone, so allow a short wait."""
    deadline = time.monotonic() + seconds
    while True:
        try:
            with FolderLock(out):
                return
        except SweepOutputError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.1)


def _gone_within(pids: set[int], seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if not any(_alive(p) for p in pids):
            return True
        time.sleep(0.1)
    return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_workers_die_with_their_parent_and_a_rerun_races_none(toy_yaml, tmp_path, sig):
    out = tmp_path / "D"
    proc, workers = _start_slow_sweep(toy_yaml, out)
    try:
        os.kill(proc.pid, sig)
        proc.wait(timeout=30)
        assert _gone_within(workers, 15), "a worker outlived the sweep"
        assert _gone_within(_session(proc.pid), 15), f"outlived the sweep: {_session(proc.pid)}"
        if sig == signal.SIGTERM:
            assert proc.returncode == 143
            assert "Traceback" not in proc.stderr.read()
    finally:
        with_group = proc.pid
        try:
            os.killpg(with_group, signal.SIGKILL)
        except ProcessLookupError:
            pass
        for p in workers:
            if _alive(p):
                os.kill(p, signal.SIGKILL)
    assert not list(out.glob("logs/*.mcap.*.part")) or all(
        not _alive(int(p.name.split(".")[-2].split("-")[0])) for p in out.glob("logs/*.part")
    )
    _lock_free_within(out, 5)  # free: no survivor holds it


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_a_sweep_started_with_sigint_ignored_still_stops_on_sigint(toy_yaml, tmp_path):
    """A sweep started in the background of a script inherits SIGINT ignored (``cmd &``): a
    Ctrl-C / ``kill -INT`` must stop it all the same (exit 130), its workers with it."""
    out = tmp_path / "D"
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)  # inherited by the child, as `&` does
    try:
        proc, workers = _start_slow_sweep(toy_yaml, out)
    finally:
        signal.signal(signal.SIGINT, before)
    try:
        os.kill(proc.pid, signal.SIGINT)
        proc.wait(timeout=60)
        assert proc.returncode == 130, proc.stderr.read()[-2000:]
        assert _gone_within(workers, 15), "a worker outlived the sweep"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="AF_UNIX reset on close")
def test_a_worker_whose_row_is_left_unread_at_the_stop_ends_without_a_traceback(
    toy_yaml, tmp_path, capfd
):
    """Stopped while a worker's finished row waits unread in its pipe (Ctrl-C between two
    rows): the sweep closing its end resets the pipe, and the worker's next read is a
    ConnectionResetError, which must end it quietly as an end of input does."""
    from replay.sweep.engine import _tasks
    from replay.sweep.executors import run_local

    spec = from_options(["plant.params.mass=1,2,3"], [], None)
    tasks = _tasks(expand(toy_yaml, spec, 0, version="test"), tmp_path / "D", False, "")
    stream = run_local(tasks, 2)
    first = next(stream)  # (held at the yield: the other worker's row comes and stays unread)
    running = stream.gi_frame.f_locals["running"]  # conn -> task of the worker still busy
    workers = list(stream.gi_frame.f_locals["procs"].values())
    deadline = time.monotonic() + 30
    while not any(conn.poll() for conn in running) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert any(conn.poll() for conn in running), "the other worker sent no row"
    stream.close()
    err = capfd.readouterr().err
    assert first["key"] and [p.exitcode for p in workers] == [0, 0]  # (an exception: 1)
    assert "Traceback" not in err and "ConnectionResetError" not in err, err


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="POSIX signals")
def test_a_worker_takes_sigterm_as_a_held_ctrl_c_once_a_variant():
    """A worker's SIGTERM is its Ctrl-C: held while a log record (or the log's close) is
    written, raised after it; a second one (the watchdog's after the kernel's PDEATHSIG, 0-0.5 s
    apart) is ignored instead of breaking the close, which left the log as a ``.part`` (6 in
    10 sweeps whose parent was SIGKILLed)."""
    from replay.log.output import HeldSigint
    from replay.sweep.executors import _as_interrupt

    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    held = HeldSigint()
    try:
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, _as_interrupt)
        held.install()
        with pytest.raises(KeyboardInterrupt):
            with held:  # (a record being written)
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(0.01)  # (the handler runs: held, not raised)
                assert held.pending
                os.kill(os.getpid(), signal.SIGTERM)  # the second: ignored
                time.sleep(0.01)
        assert signal.getsignal(signal.SIGTERM) is signal.SIG_IGN
    finally:
        held.uninstall()
        signal.signal(signal.SIGTERM, before[0])
        signal.signal(signal.SIGINT, before[1])
