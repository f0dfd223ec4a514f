"""One writer per output (issue #26): a run's .part is its own, a second run onto a live one is
refused naming it, a finished log replaces the target only if nothing else got there meanwhile;
outputs that are not regular files are refused before the run; a full disk is exit 1."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner
from conftest import fail_writes_after

from replay.cli import main
from replay.log import LogError, LogReader, LogWriter
from replay.log.output import OutputConflictError, live_writers, part_paths
from replay.messages import Event

HOLDER = r"""
import sys
from replay.log import LogWriter
from replay.messages import Event
w = LogWriter({out!r})
w.write("/events", Event(0.0, "holder"), 0)
print("ready", flush=True)
sys.stdin.readline()
w.write("/events", Event(0.001, "outcome", {{"success": True}}), 1_000_000)
w.close()
print("closed", flush=True)
"""


def _holder(out: Path) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[3])}
    proc = subprocess.Popen(
        [sys.executable, "-c", HOLDER.format(out=str(out))],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        text=True,
        env=env,
    )
    assert proc.stdout.readline().strip() == "ready"
    return proc


def _error_line(r) -> str:
    lines = [ln for ln in r.output.splitlines() if ln.strip() and "pybullet build" not in ln]
    assert len(lines) == 1, r.output
    assert "Traceback" not in r.output
    return lines[0]


def _old_log(path: Path) -> bytes:
    with LogWriter(path) as w:
        w.write("/events", Event(0.0, "old"), 0)
    return path.read_bytes()


def test_a_second_run_onto_a_live_one_is_refused_and_neither_log_is_torn(toy_yaml, tmp_path):
    out = tmp_path / "g.mcap"
    old = _old_log(out)
    proc = _holder(out)
    try:
        (part,) = live_writers(out)
        assert part.name == f"g.mcap.{proc.pid}.part"
        r = CliRunner().invoke(main, ["run", str(toy_yaml), "-o", str(out), "-q"])
        assert r.exit_code == 2
        line = _error_line(r)
        assert line.startswith("error: will not write log") and f"process {proc.pid}" in line
        assert out.read_bytes() == old  # untouched while the other run lives
        # the library refuses it too (not only the command line's early check)
        with pytest.raises(LogError, match=f"process {proc.pid}"):
            LogWriter(out)
        proc.stdin.write("\n")
        proc.stdin.flush()
        assert proc.stdout.readline().strip() == "closed"
    finally:
        proc.kill()
        proc.wait(timeout=30)
    r = LogReader(out).check()
    assert r.status == "complete" and [e["kind"] for e in r.events()] == ["holder", "outcome"]
    assert not part_paths(out)
    # the first run gone, the output is free again
    r = CliRunner().invoke(main, ["run", str(toy_yaml), "-o", str(out), "-q"])
    assert r.exit_code == 0, r.output
    assert LogReader(out).check().outcome() is not None


def test_a_killed_runs_part_neither_blocks_nor_is_overwritten(toy_yaml, tmp_path):
    out = tmp_path / "g.mcap"
    proc = _holder(out)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    (stale,) = part_paths(out)
    kept = stale.read_bytes()
    assert not live_writers(out)  # its lock died with it
    r = CliRunner().invoke(main, ["run", str(toy_yaml), "-o", str(out), "-q"])
    assert r.exit_code == 0, r.output
    assert stale.read_bytes() == kept  # still the killed run's partial log, readable
    assert LogReader(stale).truncated  # (its one message was in the chunk being built)
    assert LogReader(out).check().status == "complete"


def test_two_writers_in_one_process_get_their_own_parts(tmp_path):
    out = tmp_path / "g.mcap"
    w = LogWriter(out)
    assert w.part_path.name == f"g.mcap.{os.getpid()}.part"
    with pytest.raises(LogError, match="another run"):
        LogWriter(out)
    w.close()
    assert LogReader(out).check().status == "complete"


def test_a_log_put_there_meanwhile_is_not_replaced(tmp_path):
    """A writer that does not take the lock (cp, another tool) finished first: this run's log is
    kept aside under its own name and the error says where."""
    out = tmp_path / "g.mcap"
    _old_log(out)
    w = LogWriter(out)
    w.write("/events", Event(0.0, "mine"), 0)
    theirs = tmp_path / "theirs.mcap"
    _old_log(theirs)
    os.replace(theirs, out)  # someone else's finished log lands at the target
    before = out.read_bytes()
    with pytest.raises(OutputConflictError, match="conflict-") as info:
        w.close()
    assert out.read_bytes() == before
    kept = tmp_path / f"g.conflict-{os.getpid()}.mcap"
    assert str(kept) in str(info.value)
    assert [e["kind"] for e in LogReader(kept).check().events()] == ["mine"]
    assert not part_paths(out)


def test_a_log_unchanged_since_the_start_is_replaced(tmp_path):
    out = tmp_path / "g.mcap"
    _old_log(out)
    with LogWriter(out) as w:
        w.write("/events", Event(0.0, "new"), 0)
    assert [e["kind"] for e in LogReader(out).events()] == ["new"]


def _odd(kind: str, path: Path):
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(path))
        return s
    elif kind == "empty":
        path.write_bytes(b"")
    elif kind == "device":
        os.symlink("/dev/null", path)  # (a device node itself needs mknod: the link's target)
    return None


@pytest.mark.parametrize(
    "kind, words",
    [
        ("fifo", "a FIFO"),
        ("socket", "a socket"),
        ("device", "a character device"),
        ("empty", "an empty file"),
    ],
)
def test_outputs_that_are_not_regular_files_are_refused_before_the_run(
    toy_yaml, tmp_path, kind, words
):
    out = tmp_path / "odd.mcap"
    held = _odd(kind, out)
    try:
        before = os.lstat(out)
        r = CliRunner().invoke(main, ["run", str(toy_yaml), "-o", str(out), "-q"])
        assert r.exit_code == 2
        assert words in _error_line(r)
        after = os.lstat(out)
        assert (after.st_ino, after.st_mode, after.st_size) == (
            before.st_ino,
            before.st_mode,
            before.st_size,
        )
        assert not part_paths(out)
    finally:
        if held is not None:
            held.close()


def test_a_full_disk_mid_run_is_exit_1_and_leaves_no_part(toy_yaml, tmp_path, monkeypatch):
    out = tmp_path / "full.mcap"
    calls = fail_writes_after(monkeypatch, 3)  # header and a few chunks fit, then the disk is full
    r = CliRunner().invoke(
        main, ["run", str(toy_yaml), "-o", str(out), "-q", "--set", "timing.duration=20"]
    )
    assert r.exit_code == 1
    line = _error_line(r)
    assert "No space left on device" in line and "partial log is removed" in line
    assert len(calls) > 3 and not out.exists() and not part_paths(out)
