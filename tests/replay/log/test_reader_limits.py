"""A log's reader loads at most ``message_bytes`` at once, and a log's stored scenario is data:
hostile logs give one ``error:`` line (or a damaged-chunk note), in bounded memory and time."""

from __future__ import annotations

import json
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest
from mcap.writer import CompressionType, Writer

from replay.log import LogError, LogReader, LogWriter
from replay.log.errors import LogLimitError
from replay.messages import Event, ScenarioInfo

SMALL = {"REPLAY_LIMIT_MESSAGE_BYTES": "1000000"}
# the child runs the command line and says how much its peak RSS grew past the imports
RUNNER = """
import atexit, resource, sys
import replay.cli, replay.log, numpy, yaml
base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
grown = lambda: resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - base
atexit.register(lambda: sys.stderr.write(f"\\nRSS_GROWTH_KB {grown()}\\n"))
sys.argv = ["replay", *sys.argv[1:]]
from replay.entry import main
main()
"""


def _cli(*args, env=None, timeout=60) -> tuple[subprocess.CompletedProcess, int]:
    import os

    full = {**os.environ, **(env or {})}
    p = subprocess.run(
        [sys.executable, "-c", RUNNER, *args],
        capture_output=True,
        text=True,
        env=full,
        timeout=timeout,
    )
    lines = p.stderr.splitlines()
    growth = [int(x.split()[1]) for x in lines if x.startswith("RSS_GROWTH_KB")]
    p.stderr = "\n".join(x for x in lines if x and not x.startswith("RSS_GROWTH_KB"))
    return p, growth[0] if growth else -1


def _log(path: Path, payload_bytes: int, *, chunked=True, compression=CompressionType.ZSTD):
    """A log of a /scenario and one /events message of ``payload_bytes`` (compressible)."""
    with open(path, "wb") as f:
        w = Writer(f, compression=compression, chunk_size=1 << 20, use_chunking=chunked)
        w.start()
        sc = w.register_channel("/scenario", "json", 0)
        ev = w.register_channel("/events", "json", 0)
        info = {"t": 0.0, "name": "big", "paper": "p", "yaml": "a: 1\n", "seed": 0}
        w.add_message(sc, 0, json.dumps(info).encode(), 0)
        head, tail = b'{"t": 0.0, "kind": "note", "data": {"s": "', b'"}}'
        w.add_message(ev, 1, head + b"a" * (payload_bytes - len(head) - len(tail)) + tail, 1)
        w.finish()
    return path


def _one_error_line(p: subprocess.CompletedProcess, *words: str) -> str:
    assert p.returncode == 2, p.stderr
    assert "Traceback" not in p.stderr
    errors = [x for x in p.stderr.splitlines() if x.startswith("error:")]
    assert len(errors) == 1, p.stderr
    for w in words:
        assert w in errors[0]
    return errors[0]


def _patch_sizes(path: Path, size: int, *, record=True, index=True) -> None:
    """Overwrite the stated uncompressed size of the (only) chunk in its record and/or its
    index entry (the summary's ChunkIndex)."""
    data = bytearray(path.read_bytes())
    chunk = 8 + 9 + struct.unpack_from("<Q", data, 8 + 1)[0]  # after the magic and header
    assert data[chunk] == 0x06
    if record:
        struct.pack_into("<Q", data, chunk + 9 + 16, size)
    if index:
        pos = data.find(b"\x08", struct.unpack_from("<Q", data, len(data) - 8 - 20)[0])
        while data[pos] != 0x08:  # the ChunkIndex record of the summary
            pos += 9 + struct.unpack_from("<Q", data, pos + 1)[0]
        # (start and end times, chunk offset and length, the message index map, its length,
        # the compression's name, the compressed size, then the uncompressed size)
        at = pos + 9 + 32
        at += 4 + struct.unpack_from("<I", data, at)[0] + 8
        at += 4 + struct.unpack_from("<I", data, at)[0] + 8
        struct.pack_into("<Q", data, at, size)
    path.write_bytes(bytes(data))


# -- the reproducer: a small log holding one huge message ---------------------------------------


@pytest.mark.parametrize("size", [50_000_000, 3_000_000])
def test_a_small_log_with_a_huge_message_is_one_line_in_bounded_memory(tmp_path, size):
    log = _log(tmp_path / "big.mcap", size)
    assert log.stat().st_size < 100_000
    t0 = time.perf_counter()
    p, growth = _cli("info", str(log), env=SMALL)
    assert time.perf_counter() - t0 < 30
    _one_error_line(p, "big.mcap", f"{size:,}"[:-4], "uncompressed", "MESSAGE_BYTES=N")
    assert p.stdout == ""
    assert 0 <= growth < 40_000  # KB: nothing of the message was decompressed


def test_raising_the_limit_reads_the_message(tmp_path):
    log = _log(tmp_path / "big.mcap", 3_000_000)
    p, _ = _cli("info", str(log), env={"REPLAY_LIMIT_MESSAGE_BYTES": "4000000"})
    assert p.returncode == 0, p.stderr
    assert "note" in p.stdout


def test_a_bad_limit_variable_is_one_line(tmp_path):
    log = _log(tmp_path / "big.mcap", 1000)
    p, _ = _cli("info", str(log), env={"REPLAY_LIMIT_MESSAGE_BYTES": "lots"})
    _one_error_line(p, "REPLAY_LIMIT_MESSAGE_BYTES")


def test_the_reader_refuses_before_reading(tmp_path, monkeypatch):
    for k, v in SMALL.items():
        monkeypatch.setenv(k, v)
    log = _log(tmp_path / "big.mcap", 2_000_000)
    with pytest.raises(LogLimitError, match="message_bytes|MESSAGE_BYTES") as exc:
        LogReader(log)
    assert isinstance(exc.value, LogError) and isinstance(exc.value, ValueError)
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize("compression", [CompressionType.ZSTD, CompressionType.LZ4])
def test_a_chunk_claiming_a_huge_size_is_refused(tmp_path, compression):
    """The chunk's own record states 2**40 bytes (its index the truth): refused on reading."""
    log = _log(tmp_path / "claims.mcap", 2000, compression=compression)
    _patch_sizes(log, 1 << 40, index=False)
    p, growth = _cli("info", str(log))
    _one_error_line(p, f"{1 << 40:,}", "REPLAY_LIMIT_MESSAGE_BYTES")
    assert growth < 40_000


def test_an_index_claiming_a_huge_size_is_refused_at_once(tmp_path):
    log = _log(tmp_path / "claims.mcap", 2000)
    _patch_sizes(log, 1 << 62)
    t0 = time.perf_counter()
    with pytest.raises(LogLimitError, match="the chunk at byte"):
        LogReader(log)
    assert time.perf_counter() - t0 < 1


def test_a_chunk_that_decompresses_past_its_stated_size_is_damage_not_memory(tmp_path):
    """The zstd frame holds 50 MB (and says so), the chunk states 1000 bytes: at most 1001
    bytes are decompressed; the chunk is damaged, said, and the rest reads."""
    log = _log(tmp_path / "liar.mcap", 50_000_000)
    _patch_sizes(log, 1000)
    p, growth = _cli("info", str(log))
    assert p.returncode == 0, p.stderr
    assert "Traceback" not in p.stderr
    assert "DAMAGED" in p.stdout
    assert growth < 40_000


def test_an_unchunked_message_over_the_limit_is_refused(tmp_path, monkeypatch):
    log = _log(tmp_path / "flat.mcap", 2_000_000, chunked=False)
    p, growth = _cli("info", str(log), env=SMALL)
    _one_error_line(p, "the record at byte", "REPLAY_LIMIT_MESSAGE_BYTES")
    assert growth < 40_000
    monkeypatch.setenv("REPLAY_LIMIT_MESSAGE_BYTES", "3000000")
    assert len(LogReader(log).check().events()) == 1


@pytest.mark.parametrize("length, status", [(1 << 29, "TRUNCATED"), (1 << 50, "DAMAGED")])
def test_a_message_record_claiming_a_huge_length_is_a_torn_tail(tmp_path, length, status):
    """A record whose length runs past the file's end is a log cut short (or, past 1 GiB,
    garbage): read up to it, nothing allocated for it."""
    log = _log(tmp_path / "flat.mcap", 1000, chunked=False)
    data = log.read_bytes()
    cut = data.rindex(b'{"t": 0.0, "kind"') - 22 - 9  # the /events message's record
    assert data[cut] == 0x05
    torn = data[:cut] + bytes([0x05]) + struct.pack("<Q", length) + data[cut + 9 :][:100]
    log.write_bytes(torn)
    p, growth = _cli("info", str(log))
    assert p.returncode == 0, p.stderr
    assert status in p.stdout and "Traceback" not in p.stderr
    assert growth < 40_000


# -- many tiny events: linear ---------------------------------------------------------------------


def test_events_are_read_once_and_in_linear_time(tmp_path):
    def write(n: int) -> Path:
        path = tmp_path / f"ev{n}.mcap"
        with LogWriter(path) as log:
            log.write("/scenario", ScenarioInfo(0.0, "e", "p", "a: 1\n", 0, "x"), 0)
            for i in range(n):
                log.write("/events", Event(i * 1e-6, "tick", {}), i * 1000)
        return path

    def cost(path: Path) -> float:
        """CPU time of a paper's many asks for the events; the least of three (a loaded
        machine's noise only adds)."""
        times = []
        for _ in range(3):
            t0 = time.process_time()
            r = LogReader(path).check()
            for _ in range(10):
                r.events()
            times.append(time.process_time() - t0)
        return min(times)

    small, big = write(5_000), write(50_000)
    reads = []
    counted = LogReader(small)
    series = counted.series
    counted.series = lambda *a, **k: reads.append(a) or series(*a, **k)  # type: ignore[method-assign]
    assert [len(counted.events()) for _ in range(5)] == [5_000] * 5
    assert len(reads) == 1  # read once, then kept
    ratio = cost(big) / cost(small)
    assert ratio < 40  # 10x the events: ~10x the time (quadratic would be ~100x)
    r = LogReader(big)
    events = r.events()
    assert len(events) == 50_000 and [e["t"] for e in events] == sorted(e["t"] for e in events)
    events.clear()  # (a caller's copy)
    assert len(r.events()) == 50_000


# -- the stored scenario -------------------------------------------------------------------------


def _scenario_log(path: Path, text) -> Path:
    with LogWriter(path) as log:
        log.write("/scenario", ScenarioInfo(0.0, "x", "p", text, 0, "v"), 0)
        log.write("/events", Event(0.0, "outcome", {"success": True}), 0)
    return path


@pytest.mark.parametrize(
    "text, words",
    [
        ("12345", "not a mapping of sections (int)"),
        ("- a\n- b\n", "not a mapping of sections (list)"),
        ("[" * 20_000 + "]" * 20_000, "nested deeper"),
        ("a:\n" + "".join(" " * i + "b:\n" for i in range(1, 200)), "nested deeper"),
        ("plant:\n  type: stick\n  params: [1, 2]\n", "plant.params is not a mapping (list)"),
        ("plant: [1]\n", "plant is not a mapping (list)"),
        ("sensors: {cam: {type: c, params: 3}}\n", "sensors.cam.params is not a mapping"),
        ("tasks: [a]\n", "tasks is not a mapping"),
        ("a: !!python/object:os.system x\n", "tag"),
        ("a: [1\n", "not valid YAML"),
        ("a: 1\n# " + "x" * 2_000_000 + "\n", "REPLAY_LIMIT_SCENARIO_BYTES"),
        ("a: 1\n# " + "é" * 600_000 + "\n", "REPLAY_LIMIT_SCENARIO_BYTES"),
        (12345, "not text"),
    ],
)
def test_a_bad_stored_scenario_is_one_log_error(tmp_path, text, words):
    r = LogReader(_scenario_log(tmp_path / "s.mcap", text))
    t0 = time.perf_counter()
    with pytest.raises(LogError) as exc:
        r.scenario()
    assert time.perf_counter() - t0 < 5
    message = str(exc.value)
    assert words in message and "\n" not in message and len(message) < 400
    assert str(r.path) in message


def test_a_good_stored_scenario_is_read_once(tmp_path):
    r = LogReader(_scenario_log(tmp_path / "s.mcap", "plant: {type: toy, params: {a: 1}}\n"))
    assert r.scenario()["name"] == "x"
    assert r.scenario_config() == {"plant": {"type": "toy", "params": {"a": 1}}}


def test_raising_the_scenario_limit_reads_a_big_one(tmp_path, monkeypatch):
    r = LogReader(_scenario_log(tmp_path / "s.mcap", "a: 1\n# " + "x" * 1_200_000 + "\n"))
    monkeypatch.setenv("REPLAY_LIMIT_SCENARIO_BYTES", "2000000")
    assert r.scenario_config() == {"a": 1}
