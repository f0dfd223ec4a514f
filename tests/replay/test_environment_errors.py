"""A hostile environment (issue #26): a terminal encoding without ω or …, a folder that takes no
files, an address-space limit: one ``error:`` line and the right exit code, never a traceback."""

from __future__ import annotations

import errno
import os
import subprocess
import sys
from pathlib import Path

import pytest
from click.testing import CliRunner

from replay.cli import main

ROOT = Path(__file__).resolve().parents[2]
GOLDEN = ROOT / "data/golden/stick_3step.mcap"


def _replay(*args, env=None, cwd=None, preexec_fn=None, timeout=300):
    """The installed entry point, as `replay ARGS` runs it."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
    return subprocess.run(
        [sys.executable, "-c", "from replay.entry import main; main()", *map(str, args)],
        capture_output=True,
        env=env,
        cwd=cwd or ROOT,
        preexec_fn=preexec_fn,
        timeout=timeout,
    )


def test_the_fallback_characters():
    assert "ω = 1.5 rad/s …".encode("ascii", "replay-fallback") == b"w = 1.5 rad/s ..."
    assert "√ ∑".encode("ascii", "replay-fallback") == b"sqrt ?"
    assert "θ° ±".encode("latin-1", "replay-fallback") == "theta° ±".encode("latin-1")


def _log_with_symbols(path: Path) -> Path:
    from replay.log import LogWriter
    from replay.messages import Event

    with LogWriter(path) as w:
        data = {"success": True, "reason": "ω reached", "omega": [1.0, 2.0, 3.0, 4.0, 5.0]}
        w.write("/events", Event(0.0, "outcome", data), 0)
    return path


@pytest.mark.parametrize("encoding", ["latin-1", "ascii"])
@pytest.mark.parametrize("command", ["claims", "info"])
def test_any_terminal_encoding_prints(encoding, command, tmp_path):
    log = GOLDEN if command == "claims" else _log_with_symbols(tmp_path / "x.mcap")
    utf8 = _replay(command, log, env={"PYTHONIOENCODING": "utf-8"})
    assert utf8.returncode == 0
    text = utf8.stdout.decode("utf-8")
    assert "ω" in text, "the output would not test the fallback"
    r = _replay(command, log, env={"PYTHONIOENCODING": encoding})
    assert r.returncode == 0, r.stderr.decode("latin-1")
    assert b"Traceback" not in r.stderr and b"UnicodeEncodeError" not in r.stderr
    if encoding == "ascii":  # (click takes an ASCII stream for a misconfigured one: UTF-8)
        return
    out = r.stdout.decode(encoding)
    assert out.count("\n") == text.count("\n")  # every line printed
    assert ("..." in out) == ("…" in text) and "w" in out and "ω" not in out


def test_a_report_into_a_file_is_one_line(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("x")
    r = CliRunner().invoke(main, ["report", "-o", str(afile / "report"), "--logs", str(tmp_path)])
    assert r.exit_code == 2 and "Traceback" not in r.output
    assert r.output.strip().splitlines()[-1].startswith("error: cannot write the report to")


def test_a_read_only_working_folder_is_one_line_for_sweep_and_report(
    toy_yaml, tmp_path, monkeypatch
):
    monkeypatch.chdir(tmp_path)
    mkdir = Path.mkdir

    def read_only(self, *a, **kw):
        if not self.is_absolute():  # (what the commands make under the working folder)
            raise OSError(errno.EROFS, os.strerror(errno.EROFS), str(self))
        return mkdir(self, *a, **kw)

    monkeypatch.setattr(Path, "mkdir", read_only)
    for args in (
        ["sweep", str(toy_yaml), "--grid", "plant.params.mass=1,2", "-q"],
        ["report"],
    ):
        r = CliRunner().invoke(main, args)
        assert r.exit_code == 2, r.output
        last = r.output.strip().splitlines()[-1]
        assert last.startswith("error: ") and "Read-only file system" in last
        assert "Traceback" not in r.output


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS as on Linux")
@pytest.mark.parametrize("mb", [150, 250, 450])
def test_an_address_space_limit_is_one_line_or_a_run(tmp_path, mb):
    import resource

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (mb << 20, resource.RLIM_INFINITY))

    out = tmp_path / "x.mcap"
    r = _replay(
        "run", "stick_3step", "-o", out, "-q", "--set", "timing.duration=0.2", preexec_fn=limit
    )
    err = r.stderr.decode("utf-8", "replace")
    assert r.returncode in (0, 1), err  # (not a signal: -11 was the crash in the cv2 import)
    assert "Traceback" not in err
    if r.returncode:
        lines = [ln for ln in err.splitlines() if ln.strip() and "pybullet build" not in ln]
        assert len(lines) == 1 and lines[0].startswith("error: "), err
        if mb < 200:
            assert f"ulimit -v) is {mb} MB" in lines[0]
    else:
        assert out.is_file()


def test_an_import_broken_by_ctrl_c_is_an_interrupt_not_a_load_error():
    """A C extension whose init a KeyboardInterrupt broke raises ImportError from it: that is
    Ctrl-C (exit 130), while an ImportError of its own stays 'cannot load' (exit 1)."""
    from replay.entry import _by_ctrl_c

    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as k:
            raise ImportError("initialization failed") from k
    except ImportError as exc:
        assert _by_ctrl_c(exc)
    assert not _by_ctrl_c(ImportError("libGL.so.1: cannot open shared object file"))
