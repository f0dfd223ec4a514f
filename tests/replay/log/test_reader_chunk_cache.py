"""A log reader decompresses each chunk once however many topics are read from it (the
analysis reads a grasp log topic by topic: ~30 topics over 80 chunks), and reads the same
messages in the same order as a reader that keeps nothing."""

from __future__ import annotations

from replay.log import LogReader
from replay.log import reader as reader_module
from synthetic_logs import write_stick_log


def _all(reader: LogReader) -> dict[str, list]:
    topics = sorted(reader.topic_counts())
    out = {t: reader.series(t) for t in topics}
    out["*"] = [(m.topic, m.t, m.data) for m in reader.messages()]
    return out


def test_each_chunk_is_read_once_and_the_messages_are_those_of_an_uncached_read(
    tmp_path, monkeypatch
):
    path = write_stick_log(tmp_path / "stick.mcap", duration=2.0)
    reads: list[int] = []
    real = LogReader._read_chunk

    def counted(self, f, index):
        reads.append(index.chunk_start_offset)
        return real(self, f, index)

    monkeypatch.setattr(LogReader, "_read_chunk", counted)
    cached = _all(LogReader(path))
    chunks = len(set(reads))
    assert chunks > 1 and len(reads) == chunks, (len(reads), chunks)
    assert len(cached) > 3  # several topics, each read from the kept chunks

    reads.clear()
    monkeypatch.setattr(reader_module, "CACHED_CHUNK_BYTES", 0)  # keeps nothing
    uncached = _all(LogReader(path))
    assert len(reads) > chunks  # each topic read its chunks again
    assert cached == uncached
