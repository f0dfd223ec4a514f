"""What the viewer keeps of a log is bounded, whatever the log says (issue #36).

- The count in a log's statistics only sizes the first allocation: a 3-message log that claims
  10^9 messages allocates kilobytes, not gigabytes.
- A topic whose first message is wide and whose other messages are not (ragged rows) is one
  error line naming ``REPLAY_LIMIT_VIEWER_BYTES``, before the memory is spent; in a live run
  the accumulator stops keeping messages and notes why, never raising into the run.
- Event fields and labels too big to be a detail or a name are left out, with a note.
- A 2 MB scenario name is a short label; a host the server cannot listen on (an IPv4-mapped
  IPv6 address) is one error line at once, not a hang.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import tracemalloc

import pytest
from mcap.writer import Writer

from replay.log import LogWriter
from replay.messages import TOPIC_EVENTS, TOPIC_STICK_STATE
from replay.viewer import ViewerError, load_run
from replay.viewer.app import Viewer, free_port
from replay.viewer.data import EVENT_FIELD_BYTES, LABEL_BYTES, RunAccumulator
from replay.viewer.markup import LABEL_CHARS
from synthetic_logs import write_hostile_log

REPLAY = [sys.executable, "-m", "replay.cli"]


def _peak(fn) -> tuple[object, int]:
    """``fn()`` and the peak bytes it allocated (NumPy reports its arrays to tracemalloc)."""
    tracemalloc.start()
    try:
        out = fn()
        return out, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _lying_log(path, claimed: int):
    """Three /stick/state messages, the statistics claiming ``claimed`` of them."""
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        sid = w.register_schema("x", "jsonschema", b'{"type":"object"}')
        cid = w.register_channel(TOPIC_STICK_STATE, "json", sid)
        for i in range(3):
            state = {"t": i * 1e-3, "x": 0.1, "y": 0.2, "theta": 0.0, "vx": 0, "vy": 0}
            w.add_message(cid, i * 10**6, json.dumps(state | {"omega": 0}).encode(), i * 10**6)
        w._Writer__statistics.channel_message_counts[cid] = claimed  # type: ignore[attr-defined]
        w.finish()
    return path


def _wide_log(path, rows: int, width: int):
    """A first /x message of ``width`` numbers, then ``rows`` messages with none."""
    with LogWriter(path) as w:
        w.write("/x", {"t": 0.0, "v": [0.0] * width}, 0)
        for i in range(1, rows):
            w.write("/x", {"t": i * 1e-3}, i * 10**6)
    return path


def test_a_lying_message_count_allocates_little(tmp_path):
    log = _lying_log(tmp_path / "lie.mcap", 10**9)
    run, peak = _peak(lambda: load_run(log))
    assert len(run.tracks[TOPIC_STICK_STATE]) == 3
    assert peak < 64 * 2**20, f"{peak:,} bytes for 3 messages"


def test_ragged_wide_rows_are_one_error_naming_the_limit(tmp_path, monkeypatch):
    log = _wide_log(tmp_path / "wide.mcap", 2000, 10_000)  # 160 MB of NaN rows if kept
    monkeypatch.setenv("REPLAY_LIMIT_VIEWER_BYTES", str(20 * 2**20))
    tracemalloc.start()
    try:
        with pytest.raises(ViewerError) as err:
            load_run(log)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 64 * 2**20, f"{peak:,} bytes kept"
    text = str(err.value)
    assert "REPLAY_LIMIT_VIEWER_BYTES" in text and "/x" in text and "\n" not in text
    monkeypatch.setenv("REPLAY_LIMIT_VIEWER_BYTES", str(200 * 2**20))
    assert len(load_run(log).tracks["/x"]) == 2000  # raised, it loads


def test_view_of_a_wide_log_is_one_error_line(tmp_path):
    log = _wide_log(tmp_path / "wide.mcap", 2000, 10_000)
    env = {**os.environ, "REPLAY_LIMIT_VIEWER_BYTES": str(20 * 2**20)}
    r = subprocess.run(
        [*REPLAY, "view", str(log), "--port", "0", "--timeout", "1"],
        capture_output=True,
        text=True,
        timeout=120,
        env=env,
    )
    assert r.returncode == 2, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error:"), r.stderr
    assert "REPLAY_LIMIT_VIEWER_BYTES" in lines[0] and "MemoryError" not in lines[0]


def test_a_live_run_past_the_limit_stops_keeping_and_says_so(monkeypatch):
    monkeypatch.setenv("REPLAY_LIMIT_VIEWER_BYTES", str(2**20))
    acc = RunAccumulator()
    for k in range(100_000):  # 100k x 2 numbers x 8 bytes: past 1 MiB
        acc.add(TOPIC_STICK_STATE, k * 10**6, {"t": k * 1e-3, "x": 1.0})
    assert acc.full and "REPLAY_LIMIT_VIEWER_BYTES" in acc.full
    run = acc.snapshot()
    kept = len(run.tracks[TOPIC_STICK_STATE])
    assert 0 < kept < 100_000
    assert "not kept" in run.notes[0] and "REPLAY_LIMIT_VIEWER_BYTES" in run.notes[0]


def test_big_event_fields_and_labels_are_left_out_with_a_note():
    acc = RunAccumulator()
    big = [0.0] * 100_000
    acc.add(TOPIC_STICK_STATE, 0, {"t": 0.0, "x": 1.0, "name": ["j"] * 100_000, "mode": "a"})
    acc.add(TOPIC_EVENTS, 0, {"t": 0.0, "kind": "collision", "data": {"x": big, "finger": 1}})
    acc.add(TOPIC_EVENTS, 0, {"t": 0.1, "kind": "rest", "extra": big})
    run = acc.snapshot()
    assert run.events[0]["data"] == {"finger": 1}
    assert run.events[1] == {"t": 0.1, "kind": "rest", "data": {}}
    assert run.tracks[TOPIC_STICK_STATE].labels == {"mode": "a"}
    notes = " | ".join(run.notes)
    assert f"{TOPIC_STICK_STATE}.name: over {LABEL_BYTES:,} bytes" in notes
    assert f"1 event field(s) over {EVENT_FIELD_BYTES:,} bytes" in notes


def test_a_2_mb_name_is_a_short_label_and_opens_quickly(tmp_path):
    log = write_hostile_log(tmp_path / "long.mcap", name="A" * 2_000_000, paper="P" * 2_000_000)
    t0 = time.perf_counter()
    run = load_run(log)
    assert len(run.label) <= LABEL_CHARS
    Viewer.open([log], port=0).stop()
    assert time.perf_counter() - t0 < 30


def test_an_ipv4_mapped_host_is_refused_at_once(tmp_path):
    with pytest.raises(ViewerError, match="give 127.0.0.1 instead"):
        free_port("::ffff:127.0.0.1", 0)
    log = write_hostile_log(tmp_path / "run.mcap", name="run")
    t0 = time.monotonic()
    r = subprocess.run(
        [*REPLAY, "view", str(log), "--host", "::ffff:0.0.0.0", "--port", "0", "--timeout", "1"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert r.returncode == 2 and time.monotonic() - t0 < 30
    assert r.stderr.strip().splitlines()[-1].startswith("error: cannot listen on host")


def test_many_fields_and_topics_count_against_the_limit(monkeypatch):
    monkeypatch.setenv("REPLAY_LIMIT_VIEWER_BYTES", str(2**20))
    acc = RunAccumulator()
    acc.add("/wide", 0, {f"k{i}": 1.0 for i in range(10_000)})  # 10,000 columns of one row
    assert "REPLAY_LIMIT_VIEWER_BYTES" in acc.full
    acc = RunAccumulator()
    for i in range(1000):  # a thousand topics of one message
        acc.add(f"/t{i}", 0, {"t": 0.0, "x": 1.0})
    assert "REPLAY_LIMIT_VIEWER_BYTES" in acc.full and len(acc.builders) < 1000
