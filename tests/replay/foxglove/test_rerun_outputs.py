"""``replay rerun LOG``: its Rerun files go in a private temporary folder (never beside the log,
never through a link planted there), ``--shot FILE`` is checked as any output, and SIGTERM,
SIGHUP or even SIGKILL of the command leave none of Rerun's processes listening."""

from __future__ import annotations

import contextlib
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main
from replay.foxglove import rerun_view
from replay.foxglove.rerun_view import RerunError

from conftest import ROOT

import rerun  # noqa: E402, F401  (the rerun extra, which make test installs)

GOLDEN = ROOT / "data" / "golden" / "catch_optimised.mcap"
REPLAY = str(Path(sys.executable).with_name("replay"))


def _free_port() -> int:
    while True:
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        with socket.socket() as s:  # its +1 (Rerun's data port) free as well
            try:
                s.bind(("127.0.0.1", port + 1))
                return port
            except OSError:
                continue


def _children(pid: int) -> list[int]:
    """Live processes whose parent is ``pid`` (from /proc)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == pid and fields[0] != "Z":
                out.append(int(d.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def _folder(tmp_path: Path) -> Path:
    """A log beside a link named like its blueprint and the user's own run.rrd."""
    (tmp_path / "run.mcap").write_bytes(GOLDEN.read_bytes())
    (tmp_path / "precious.txt").write_text("my notes\n")
    (tmp_path / "run.rbl").symlink_to("precious.txt")
    (tmp_path / "run.rrd").write_text("my own rrd\n")
    (tmp_path / "tmp").mkdir()
    return tmp_path


def _start(folder: Path, port: int) -> tuple[subprocess.Popen, list[int]]:
    """``replay rerun --web`` on ``port``, once its web viewer answers: (the command, Rerun's
    processes it started)."""
    env = {**os.environ, "TMPDIR": str(folder / "tmp")}
    cmd = [REPLAY, "rerun", "run.mcap", "--web", "--port", str(port), "--at", "0.05"]
    proc = subprocess.Popen(
        cmd, cwd=folder, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline and proc.poll() is None:
        try:
            with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as r:
                if r.status == 200:
                    break
        except OSError:
            time.sleep(0.2)
    else:
        proc.kill()
        pytest.fail(f"Rerun's web viewer did not answer: {proc.communicate()}")
    started = _children(proc.pid)
    assert started
    return proc, started


def _untouched(folder: Path) -> None:
    assert (folder / "precious.txt").read_text() == "my notes\n"
    assert (folder / "run.rbl").is_symlink()
    assert (folder / "run.rrd").read_text() == "my own rrd\n"
    assert sorted(p.name for p in folder.iterdir()) == [
        "precious.txt",
        "run.mcap",
        "run.rbl",
        "run.rrd",
        "tmp",
    ]


def _listening(port: int) -> bool:
    """Whether any socket of this machine listens on TCP ``port`` (from /proc/net/tcp{,6}: a
    bind test would also trip over a closed client connection's TIME_WAIT on that port)."""
    for table in ("/proc/net/tcp", "/proc/net/tcp6"):
        with contextlib.suppress(OSError), open(table) as f:
            next(f)
            for row in f:
                local, state = row.split()[1], row.split()[3]
                if state == "0A" and int(local.rsplit(":", 1)[1], 16) == port:
                    return True
    return False


def _gone(pids: list[int], port: int, within: float = 20.0) -> None:
    """Within ``within`` seconds, none of ``pids`` runs and nothing listens on ``port`` or its
    +1. (A process whose main thread has exited shows as a zombie while its other threads still
    close its sockets, so the ports are waited for too.)"""

    def left() -> tuple[list[int], list[int]]:
        return [p for p in pids if _alive(p)], [p for p in (port, port + 1) if _listening(p)]

    deadline = time.monotonic() + within
    while any(left()) and time.monotonic() < deadline:
        time.sleep(0.1)
    running, listening = left()
    for p in running:  # (a failed test leaves nothing behind either)
        os.kill(p, signal.SIGKILL)
    assert not running, f"Rerun's processes {running} outlived the command"
    assert not listening, f"ports {listening} still listened on {within} s after the command"


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGHUP])
def test_a_signal_stops_rerun_and_nothing_is_written_beside_the_log(tmp_path, sig):
    folder = _folder(tmp_path)
    port = _free_port()
    proc, started = _start(folder, port)
    proc.send_signal(sig)
    try:
        out, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 128 + sig, err
    assert "Traceback" not in err
    _gone(started, port)
    _untouched(folder)
    assert list((folder / "tmp").iterdir()) == []  # its temporary folder removed


def test_sigkill_of_the_command_takes_rerun_with_it(tmp_path):
    folder = _folder(tmp_path)
    port = _free_port()
    proc, started = _start(folder, port)
    proc.kill()
    proc.communicate(timeout=30)
    _gone(started, port)  # (the kernel's PR_SET_PDEATHSIG: SIGTERM to Rerun)
    _untouched(folder)


@pytest.mark.parametrize("kind", ["link", "dangling", "not a png"])
def test_a_screenshot_path_is_checked_before_anything_starts(tmp_path, kind):
    folder = _folder(tmp_path)
    shot = folder / "shot.png"
    if kind == "link":
        shot.symlink_to("precious.txt")
    elif kind == "dangling":
        shot.symlink_to(folder / "elsewhere.png")
    else:
        shot.write_text("my notes\n")
    r = CliRunner().invoke(main, ["rerun", str(folder / "run.mcap"), "--web", "--shot", str(shot)])
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert r.exit_code == 2 and len(lines) == 1 and lines[0].startswith("error: "), r.output
    assert ("symbolic link" if kind != "not a png" else "not an earlier screenshot") in lines[0]
    assert not (folder / "elsewhere.png").exists()
    assert (folder / "precious.txt").read_text() == "my notes\n"


def test_files_beside_the_log_only_when_asked_and_checked(tmp_path):
    folder = _folder(tmp_path)
    with pytest.raises(RerunError, match="symbolic link"):
        rerun_view.blueprint(folder / "run.mcap")  # (no folder given: beside the log)
    with pytest.raises(RerunError, match="not an earlier Rerun file"):
        rerun_view.convert(folder / "run.mcap", at=0.01)
    _untouched(folder)
    rrd = rerun_view.convert(folder / "run.mcap", at=0.01, folder=folder / "tmp")
    assert rrd == folder / "tmp" / "run.rrd" and rrd.read_bytes()[:4] == rerun_view.RRD_MAGIC
