"""The log's own MCAP chunk builder (replay/log/chunks.py): the ``mcap`` library's bytes, an
index the library's readers follow, CRCs that check, and channels of any encoding."""

import io
import random

import pytest

from mcap.reader import make_reader
from mcap.stream_reader import StreamReader
from mcap.writer import CompressionType, Writer

from replay.log import LogError, LogReader, LogWriter
from replay.log.chunks import McapFile
from replay.messages import Event, StickState


def _script(seed: int):
    """A random sequence of calls: channels registered mid-run, metadata between messages,
    messages of random sizes at times that sometimes go back (so min/max are exercised)."""
    rng = random.Random(seed)
    calls = [("schema", "s1", "jsonschema", b'{"type":"object"}'), ("channel", "/a", "json", 1)]
    channels, t = 1, 0
    for i in range(3000):
        r = rng.random()
        if r < 0.003:
            calls.append(("metadata", f"m{i}", {"k": str(i)}))
        elif r < 0.006:
            calls.append(
                ("schema", f"s{i}", "protobuf", bytes(rng.randrange(256) for _ in range(9)))
            )
            calls.append(("channel", f"/c{i}", "protobuf", 2))
            channels += 1
        else:
            t = max(0, t + rng.randrange(-2_000, 1_000_000))
            data = bytes(rng.randrange(97, 123) for _ in range(rng.randrange(0, 400)))
            calls.append(("message", rng.randrange(1, channels + 1), t, data))
    return calls


def test_same_bytes_as_the_mcap_writer_for_the_same_calls():
    for seed in range(3):
        ours, theirs = io.BytesIO(), io.BytesIO()
        a = McapFile(ours, chunk_size=8_000, level=3)
        b = Writer(theirs, chunk_size=8_000, compression=CompressionType.ZSTD)
        a.start(profile="p", library="lib")
        b.start(profile="p", library="lib")
        sequence: dict[int, int] = {}
        for call in _script(seed):
            kind, args = call[0], call[1:]
            if kind == "schema":
                assert a.schema(*args) == b.register_schema(*args)
            elif kind == "channel":
                topic, encoding, schema = args
                assert a.channel(topic, encoding, schema) == b.register_channel(
                    topic, encoding, schema
                )
            elif kind == "metadata":
                a.metadata(*args)
                b.add_metadata(*args)
            else:
                channel, t, data = args
                a.message(channel, t, t, data)
                n = sequence[channel] = sequence.get(channel, -1) + 1
                b.add_message(channel, log_time=t, data=data, publish_time=t, sequence=n)
        a.finish()
        b.finish()
        assert ours.getvalue() == theirs.getvalue()


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
        for k, data in enumerate(images)
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
