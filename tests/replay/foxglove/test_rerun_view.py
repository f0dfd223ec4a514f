"""``replay rerun LOG``: the log converted on a duration timeline (simulated seconds, not 1970
dates), the viewer's whole process group stopped when the command ends (the web server Rerun
starts included), a one-line error when the extra is missing."""

from __future__ import annotations

import os
import socket
import sys
import time
import urllib.request
from pathlib import Path

import pyarrow as pa
import pytest
from click.testing import CliRunner
from rerun.chunk import RrdReader  # rerun-sdk: the test extra

from replay.cli import main
from replay.foxglove import rerun_view
from replay.foxglove.rerun_view import RerunError, running, viewer_command

from conftest import ROOT

GOLDEN = ROOT / "data" / "golden" / "catch_optimised.mcap"


def _time_columns(rrd: Path) -> dict[str, pa.DataType]:
    out = {}
    for chunk in RrdReader(rrd).store().stream():
        for f in chunk.to_record_batch().schema:
            if pa.types.is_timestamp(f.type) or pa.types.is_duration(f.type):
                out[f.name] = f.type
    return out


def _group_alive(pgid: int) -> list[int]:
    """Processes (pids) whose process group is ``pgid`` (from /proc)."""
    alive = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            alive.append(int(d.name))
    return alive


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


def test_the_timeline_is_in_simulated_seconds(tmp_path):
    log = tmp_path / "catch.mcap"
    log.write_bytes(GOLDEN.read_bytes())
    rrd = rerun_view.convert(log)
    cols = _time_columns(rrd)
    assert "message_log_time" in cols
    assert all(pa.types.is_duration(t) for t in cols.values()), cols  # no epoch timestamps
    assert rerun_view.blueprint(log).is_file()


def test_every_process_of_the_group_is_stopped(tmp_path):
    # a child that starts its own children, and one that ignores SIGTERM
    script = "trap '' TERM; sleep 60 & sleep 60 & wait"
    with running(["sh", "-c", script], grace=0.5) as proc:
        pgid = proc.pid
        deadline = time.monotonic() + 20
        while len(_group_alive(pgid)) < 3 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(_group_alive(pgid)) >= 3
    assert _group_alive(pgid) == []


def test_the_rerun_web_server_is_stopped_with_the_command(tmp_path):
    log = tmp_path / "catch.mcap"
    log.write_bytes(GOLDEN.read_bytes())
    rrd, rbl = rerun_view.convert(log), rerun_view.blueprint(log)
    port = _free_port()
    with running(viewer_command(rrd, rbl, web=True, port=port)) as proc:
        pgid = proc.pid
        deadline = time.monotonic() + 60
        served = False
        while time.monotonic() < deadline and proc.poll() is None:
            try:
                with urllib.request.urlopen(f"http://127.0.0.1:{port}/", timeout=2) as r:
                    served = r.status == 200
                    break
            except OSError:
                time.sleep(0.2)
        assert served, "Rerun's web viewer did not answer on 127.0.0.1"
        assert _group_alive(pgid)
    assert _group_alive(pgid) == []
    with socket.socket() as s:  # the port is free again: nothing listens on it
        s.bind(("127.0.0.1", port))


def test_without_the_extra_one_line_says_how_to_install_it(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "rerun", None)  # import rerun -> ImportError
    with pytest.raises(RerunError, match=r"paper-replay\[rerun\]"):
        rerun_view.rerun_cli()
    log = tmp_path / "catch.mcap"
    log.write_bytes(GOLDEN.read_bytes())
    r = CliRunner().invoke(main, ["rerun", str(log)], catch_exceptions=False)
    lines = [line for line in r.output.splitlines() if line.strip()]
    assert r.exit_code != 0 and len(lines) == 1, r.output
    assert lines[0].startswith("error: ") and "pip install 'paper-replay[rerun]'" in lines[0]
    assert not log.with_suffix(".rrd").exists()
    assert os.path.exists(log)
