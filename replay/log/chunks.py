"""An indexed, chunked, zstd-compressed MCAP file written with little Python per message.

The ``mcap`` library's ``Writer`` builds a ``Message`` dataclass and makes ~10 small writes to a
``BytesIO`` per message; here a message is one call of a small compiled chunk buffer
(``_chunk.c``: the record appended, its (log time, offset) kept for the channel's message index,
packed once per chunk; ~0.3 us instead of the ~2 us of the same steps in Python). Every other
record (header, schemas, channels, metadata, statistics, indexes, footer) is written by the ``mcap`` library's own record classes,
in the order its ``Writer`` writes them, so that a file written here is byte for byte the file
``mcap.writer.Writer(compression=ZSTD)`` writes for the same calls (a test checks it), readable by
the ``mcap`` tools and by :class:`replay.log.LogReader`.
"""

from __future__ import annotations

import contextlib
import struct
import zlib
from contextlib import AbstractContextManager
from typing import Any, Callable, Protocol

import zstandard

from replay.log._chunk import Chunk
from mcap.data_stream import RecordBuilder
from mcap.opcode import Opcode
from mcap.records import (
    Channel,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)

MAGIC = b"\x89MCAP0\r\n"
_INDEX_HEAD = struct.Struct("<BQHI")  # opcode, length, channel id, byte length of the entries


class Sink(Protocol):
    """Where the file goes: anything with ``write(bytes)`` (a binary file, ``io.BytesIO``)."""

    def write(self, data: bytes, /) -> Any: ...


def _record(record) -> bytes:
    """One record (an ``mcap.records`` instance) as bytes, written by the library itself."""
    builder = RecordBuilder()
    record.write(builder)
    return builder.end()


class McapFile:
    """``start()``, ``schema()`` / ``channel()``, many ``message()``, ``metadata()``, ``finish()``
    on a binary stream; ``stream.write`` is called once a chunk (with its message indexes), under
    ``guard`` (a context manager) when a message fills the chunk. ``message()`` is compiled: a
    signal handler runs in it only there."""

    def __init__(
        self,
        stream: Sink,
        *,
        chunk_size: int = 1024 * 1024,
        compression: str = "zstd",
        level: int = 3,
        guard: AbstractContextManager | None = None,
    ) -> None:
        if compression not in ("zstd", ""):
            raise ValueError(f"compression {compression!r}: zstd or '' (none)")
        self._stream = stream
        self._guard = (
            guard or contextlib.nullcontext()
        )  # held around writing a finished chunk (the only Python a message runs)
        self._chunk_size = chunk_size
        self._compression = compression
        self._compressor = zstandard.ZstdCompressor(level=level) if compression else None
        self._offset = 0  # bytes written to the stream
        self._schemas: list[Schema] = []
        self._channels: list[Channel] = []
        self._order: list[int] = []  # channel ids in the order of their first message
        # the records of the chunk being built, its channels' message indexes and counts
        self._chunk = Chunk(chunk_size, self._finish_chunk)
        # one message (channel id, log time, publish time, data); its sequence number is its
        # count on the channel; the chunk is finished once it outgrows chunk_size
        self.message = self._chunk.message
        self._chunk_indexes: list[ChunkIndex] = []
        self._metadata_indexes: list[MetadataIndex] = []

    def _write(self, data: bytes) -> None:
        self._stream.write(data)
        self._offset += len(data)

    def start(self, profile: str = "", library: str = "") -> None:
        self._write(MAGIC + _record(Header(profile, library)))

    def schema(self, name: str, encoding: str, data: bytes) -> int:
        """Register a schema (its record goes into the chunk being built); returns its id."""
        schema = Schema(id=len(self._schemas) + 1, name=name, encoding=encoding, data=data)
        self._schemas.append(schema)
        self._add(_record(schema))
        return schema.id

    def channel(
        self, topic: str, message_encoding: str, schema_id: int, metadata: dict | None = None
    ) -> int:
        """Register a channel (its record goes into the chunk being built); returns its id."""
        channel = Channel(
            id=len(self._channels) + 1,
            topic=topic,
            message_encoding=message_encoding,
            schema_id=schema_id,
            metadata=dict(metadata or {}),
        )
        self._channels.append(channel)
        self._add(_record(channel))
        return channel.id

    def json_messages(
        self, channels: dict[str, int], dumps: Callable[[Any], bytes], finite: Callable[[Any], Any]
    ) -> Callable[[str, Any, int], bool]:
        """``json(topic, payload, t_ns)``, compiled: a message of a topic of ``channels`` (topic
        -> channel id) as ``dumps(payload)`` (when it holds ``null``, only if ``finite(payload)``
        is True), at log and publish time ``t_ns``; False, nothing written, otherwise (a new
        topic, a TypeError of ``dumps``, a ``null`` not known finite: the caller decides)."""
        self._chunk.use_json(channels, dumps, finite)
        return self._chunk.json

    @property
    def json_all(self) -> Callable[[dict[str, Any], int, int], int]:
        """``json_all(messages, start, t_ns)``, compiled: ``json_messages``' call for each
        (topic, payload) of the dict ``messages`` from its item ``start`` on, in order; the index
        of the first it leaves to the caller (a list, or one ``json`` would say False of), or -1
        when all were written."""
        return self._chunk.json_all

    @property
    def message_count(self) -> int:
        return self._chunk.total

    def metadata(self, name: str, data: dict[str, str]) -> None:
        """A metadata record, written at once (outside chunks) and indexed in the summary."""
        record = _record(Metadata(name=name, metadata=data))
        self._metadata_indexes.append(
            MetadataIndex(offset=self._offset, length=len(record), name=name)
        )
        self._write(record)

    def _add(self, record: bytes) -> None:
        if self._chunk.append(record) > self._chunk_size:
            self._finish_chunk()

    def _finish_chunk(self) -> None:
        with self._guard:
            self._write_chunk()

    def _write_chunk(self) -> None:
        taken = self._chunk.take()
        if taken is None:
            return  # (schemas and channels alone wait for the first message, as mcap's do)
        raw, indexes = taken
        # the chunk's channels in the order of their first message in it
        present = sorted(indexes)
        for _, c, entries, _, _ in present:
            if self._chunk.count(c) == len(entries) // 16:  # its first chunk
                self._order.append(c)
        start = min(i[3] for i in present)
        end = max(0, max(i[4] for i in present))
        data = self._compressor.compress(raw) if self._compressor else raw
        comp = self._compression.encode()
        head = struct.pack(
            f"<BQQQQII{len(comp)}sQ",
            Opcode.CHUNK,
            8 + 8 + 8 + 4 + 4 + len(comp) + 8 + len(data),
            start,
            end,
            len(raw),
            zlib.crc32(raw),
            len(comp),
            comp,
            len(data),
        )
        chunk_start = self._offset
        chunk_length = len(head) + len(data)
        index_start = chunk_start + chunk_length
        offsets = {}
        parts = [head, data]
        position = index_start
        for _, channel_id, entries, _, _ in present:
            n = len(entries)
            part = _INDEX_HEAD.pack(Opcode.MESSAGE_INDEX, 2 + 4 + n, channel_id, n) + entries
            offsets[channel_id] = position
            position += len(part)
            parts.append(part)
        self._write(b"".join(parts))  # the chunk and its indexes in one write
        self._chunk_indexes.append(
            ChunkIndex(
                message_start_time=start,
                message_end_time=end,
                chunk_start_offset=chunk_start,
                chunk_length=chunk_length,
                message_index_offsets=offsets,
                message_index_length=position - index_start,
                compression=self._compression,
                compressed_size=len(data),
                uncompressed_size=len(raw),
            )
        )

    def finish(self) -> None:
        """The last chunk, the data end, the summary (schemas, channels, statistics, chunk and
        metadata indexes, summary offsets), the footer and the closing magic."""
        self._write_chunk()
        self._write(_record(DataEnd(0)))
        summary_start = self._offset
        groups: list[tuple[int, bytes]] = [
            (Opcode.SCHEMA, b"".join(_record(s) for s in self._schemas)),
            (Opcode.CHANNEL, b"".join(_record(c) for c in self._channels)),
            (
                Opcode.STATISTICS,
                _record(
                    Statistics(
                        message_count=self.message_count,
                        schema_count=len(self._schemas),
                        channel_count=len(self._channels),
                        attachment_count=0,
                        metadata_count=len(self._metadata_indexes),
                        chunk_count=len(self._chunk_indexes),
                        message_start_time=min(
                            (i.message_start_time for i in self._chunk_indexes), default=0
                        ),
                        message_end_time=max(
                            (i.message_end_time for i in self._chunk_indexes), default=0
                        ),
                        channel_message_counts={c: self._chunk.count(c) for c in self._order},
                    )
                ),
            ),
            (Opcode.CHUNK_INDEX, b"".join(_record(i) for i in self._chunk_indexes)),
            (Opcode.ATTACHMENT_INDEX, b""),
            (Opcode.METADATA_INDEX, b"".join(_record(i) for i in self._metadata_indexes)),
        ]
        summary = bytearray()
        offsets = []
        for opcode, data in groups:
            offsets.append(
                SummaryOffset(
                    group_opcode=opcode,
                    group_start=summary_start + len(summary),
                    group_length=len(data),
                )
            )
            summary += data
        summary_offset_start = summary_start + len(summary)
        summary += b"".join(_record(o) for o in offsets)
        crc = zlib.crc32(summary)
        crc = zlib.crc32(
            struct.pack("<BQQQ", Opcode.FOOTER, 8 + 8 + 4, summary_start, summary_offset_start),
            crc,
        )
        footer = Footer(
            summary_start=summary_start, summary_offset_start=summary_offset_start, summary_crc=crc
        )
        self._write(bytes(summary) + _record(footer) + MAGIC)
