"""The log's MCAP file (foxglove-sdk's writer, replay/log/chunks.py): an index the
library's readers follow, CRCs that check, sequence numbers per channel, and channels of any
encoding."""

import pytest

from mcap.reader import make_reader
from mcap.stream_reader import StreamReader

from replay.log import LogError, LogReader, LogWriter
from replay.messages import Event, StickState


def test_a_log_reads_through_its_index_and_its_crcs_check(tmp_path):
    path = tmp_path / "x.mcap"
    sent = []
    with LogWriter(path, chunk_size=4_000) as log:
        for k in range(2_000):
            payload = StickState(k * 1e-3, k * 0.5, -1.0, 0.25, 0.0, 1e-9, float(k))
            log.write("/stick/state", payload, k * 1_000_000)
            sent.append(("/stick/state", k * 1_000_000))
            if k % 97 == 0:
                log.write("/events", Event(k * 1e-3, "tick", {"k": k}), k * 1_000_000)
                sent.append(("/events", k * 1_000_000))
    with open(path, "rb") as f:
        reader = make_reader(f)
        summary = reader.get_summary()
        assert summary.statistics.message_count == len(sent) and len(summary.chunk_indexes) > 10
        got = [(c.topic, m.log_time) for _, c, m in reader.iter_messages(log_time_order=False)]
    assert got == sent
    with open(path, "rb") as f:
        records = list(StreamReader(f, validate_crcs=True).records)  # raises on a bad CRC
    assert len(records) > len(sent)
    r = LogReader(path).check()
    assert r.status == "complete" and len(r.series("/stick/state")) == 2_000


def test_channels_of_any_encoding_take_raw_bytes(tmp_path):
    """The way to add e.g. Foxglove's protobuf channels (CompressedImage) next to the JSON ones:
    the bytes come back as written, and the JSON reader is not confused by them."""
    path = tmp_path / "x.mcap"
    descriptor = b"\n\x0bfake.proto\x12\x03pkg"  # stands for a FileDescriptorSet
    images = [bytes([k]) * (k + 1) + b"\x00\xff" for k in range(50)]
    with LogWriter(path) as log:
        schema = log.register_schema("foxglove.CompressedImage", "protobuf", descriptor)
        channel = log.register_channel("/camera/image", "protobuf", schema)
        for k, data in enumerate(images):
            log.write_raw(channel, data, k * 1_000_000)
            log.write("/events", Event(k * 1e-3, "frame", {"k": k}), k * 1_000_000)
        assert log.count == 100
    with open(path, "rb") as f:
        got = [
            (s.name, s.encoding, s.data, c.message_encoding, m.data, m.sequence)
            for s, c, m in make_reader(f).iter_messages(topics=["/camera/image"])
        ]
    assert got == [
        ("foxglove.CompressedImage", "protobuf", descriptor, "protobuf", data, k)
        for k, data in enumerate(images, 1)  # (each channel numbered from 1: foxglove-sdk's)
    ]
    r = LogReader(path).check()
    assert r.status == "complete" and not r.problems
    assert [e["data"]["k"] for e in r.events()] == list(range(50))
    assert r.topic_counts() == {"/camera/image": 50, "/events": 50}


def test_a_topic_has_one_channel(tmp_path):
    with LogWriter(tmp_path / "x.mcap") as log:
        log.write("/events", Event(0.0, "a"), 0)
        with pytest.raises(LogError, match="/events already has a channel"):
            log.register_channel("/events", "protobuf")


def test_a_failed_write_raises_from_the_write_that_made_it(tmp_path, monkeypatch, caplog):
    """foxglove-sdk's writer only logs a failed write of its file: LogWriter raises it (errno
    kept) from the write whose chunk could not be written, and the SDK's own warning line is
    not shown besides."""
    import errno
    import logging

    from conftest import fail_writes_after

    from replay.log.errors import LogWriteError

    fail_writes_after(monkeypatch, 4)  # the header and a chunk fit, the next does not
    caplog.set_level(logging.DEBUG)
    log = LogWriter(tmp_path / "x.mcap", chunk_size=1_000)
    written = 0
    with pytest.raises(LogWriteError, match="No space left on device") as failed:
        for k in range(1_000):
            log.write("/events", Event(k * 1e-3, "tick", {"k": k}), k * 1_000_000)
            written += 1
    assert failed.value.errno == errno.ENOSPC and 0 < written < 100 and log.count == written
    assert not [r for r in caplog.records if r.name.startswith("foxglove")]
    with pytest.raises(LogWriteError):
        log.close("failed")
