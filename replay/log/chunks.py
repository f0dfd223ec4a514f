"""An indexed, chunked, zstd-compressed MCAP file written with little Python per message.

The ``mcap`` library's ``Writer`` builds a ``Message`` dataclass and makes ~10 small writes to a
``BytesIO`` per message; here a message is one ``struct.pack`` of its 31-byte header and two
``bytearray`` appends, and the per-channel message index of a chunk is a flat list of (log time,
offset) packed once per chunk. Every other record (header, schemas, channels,
metadata, statistics, indexes, footer) is written by the ``mcap`` library's own record classes,
in the order its ``Writer`` writes them, so that a file written here is byte for byte the file
``mcap.writer.Writer(compression=ZSTD)`` writes for the same calls (a test checks it), readable by
the ``mcap`` tools and by :class:`replay.log.LogReader`.
"""

from __future__ import annotations

import struct
import zlib
from typing import Any, Protocol

import zstandard
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
# opcode, record length, channel id, sequence, log time, publish time (MCAP spec, "Message")
_pack_message = struct.Struct("<BQHIQQ").pack
_MESSAGE_FIXED = 2 + 4 + 8 + 8  # the record's length counts what follows opcode and length
_OP_MESSAGE = int(Opcode.MESSAGE)  # (an enum member's lookup costs ~10x a plain int's)
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
    on a binary stream; ``stream.write`` is called once a chunk (with its message indexes)."""

    def __init__(
        self,
        stream: Sink,
        *,
        chunk_size: int = 1024 * 1024,
        compression: str = "zstd",
        level: int = 3,
    ) -> None:
        if compression not in ("zstd", ""):
            raise ValueError(f"compression {compression!r}: zstd or '' (none)")
        self._stream = stream
        self._chunk_size = chunk_size
        self._compression = compression
        self._compressor = zstandard.ZstdCompressor(level=level) if compression else None
        self._offset = 0  # bytes written to the stream
        self._schemas: list[Schema] = []
        self._channels: list[Channel] = []
        self._counts: list[int] = [0]  # messages per channel id (id 0 unused)
        self._order: list[int] = []  # channel ids in the order of their first message
        self._chunk = bytearray()  # the records of the chunk being built
        # per channel id, its messages in the chunk being built: [t, offset, t, offset, ...]
        self._indexes: list[list[int]] = [[]]
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
        self._chunk += _record(schema)
        self._maybe_finish_chunk()
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
        self._counts.append(0)
        self._indexes.append([])
        self._chunk += _record(channel)
        self._maybe_finish_chunk()
        return channel.id

    def message(self, channel_id: int, log_time: int, publish_time: int, data: bytes) -> None:
        """One message; its sequence number is its count on the channel."""
        counts = self._counts
        sequence = counts[channel_id]
        counts[channel_id] = sequence + 1
        chunk = self._chunk
        self._indexes[channel_id] += (log_time, len(chunk))
        chunk += _pack_message(
            _OP_MESSAGE,
            _MESSAGE_FIXED + len(data),
            channel_id,
            sequence,
            log_time,
            publish_time,
        )
        chunk += data
        if len(chunk) > self._chunk_size:
            self._finish_chunk()

    @property
    def message_count(self) -> int:
        return sum(self._counts)

    def metadata(self, name: str, data: dict[str, str]) -> None:
        """A metadata record, written at once (outside chunks) and indexed in the summary."""
        record = _record(Metadata(name=name, metadata=data))
        self._metadata_indexes.append(
            MetadataIndex(offset=self._offset, length=len(record), name=name)
        )
        self._write(record)

    def _maybe_finish_chunk(self) -> None:
        if len(self._chunk) > self._chunk_size:
            self._finish_chunk()

    def _finish_chunk(self) -> None:
        # the chunk's channels in the order of their first message in it
        present = sorted((entries[1], c) for c, entries in enumerate(self._indexes) if entries)
        if not present:
            return  # (schemas and channels alone wait for the first message, as mcap's do)
        for _, c in present:
            if self._counts[c] == len(self._indexes[c]) // 2:  # its first chunk
                self._order.append(c)
        start = min(min(self._indexes[c][::2]) for _, c in present)
        end = max(0, max(max(self._indexes[c][::2]) for _, c in present))
        raw = bytes(self._chunk)
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
        for _, channel_id in present:
            entries = self._indexes[channel_id]
            n = len(entries)
            part = _INDEX_HEAD.pack(
                Opcode.MESSAGE_INDEX, 2 + 4 + 8 * n, channel_id, 8 * n
            ) + struct.pack(f"<{n}Q", *entries)
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
        self._chunk = bytearray()
        for _, c in present:
            self._indexes[c] = []

    def finish(self) -> None:
        """The last chunk, the data end, the summary (schemas, channels, statistics, chunk and
        metadata indexes, summary offsets), the footer and the closing magic."""
        self._finish_chunk()
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
                        channel_message_counts={c: self._counts[c] for c in self._order},
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
