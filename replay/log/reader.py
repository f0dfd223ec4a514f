"""Reading a run's MCAP log back as (topic, simulated time, decoded JSON dict), saying what it read.

A finished log is read through its index. A log whose summary is missing (a run killed mid-way,
a ``.part`` file, a file cut short) is read record by record up to its last whole record and is
``truncated``. A log whose bytes are wrong (a chunk whose CRC does not match, a record that does
not parse, a message that is not a JSON object, bytes after its end) is ``damaged``: what can be
read is read, and :attr:`LogReader.problems` says what was not and where. A damaged chunk of an
indexed log costs its own messages only: the others are read through the index (the summary
holds every channel). Zeros or garbage after the last whole record (a file extended, a disk
block) are found by walking the records' headers, in time proportional to the real content.
Nothing a log's bytes hold raises anything but :class:`LogError`.

A reader loads at most ``message_bytes`` (:mod:`replay.limits`) at once: a chunk whose stated
uncompressed size is over it, or a record the file holds whole that is, is refused
(:class:`LogLimitError`, one line) before anything is read or decompressed, and a chunk is
decompressed no further than its stated size (a zstd frame may claim any size of its own).
What it decodes and keeps of one topic (:meth:`LogReader.series`, the events) is at most
``series_bytes`` as stored, and the ``/scenario`` message's fields are typed and clipped
(:meth:`LogReader.scenario`): a log's tiny compressed bytes cannot make it keep gigabytes.
"""

from __future__ import annotations

import hashlib
import heapq
import io
import json
import os
import struct
from collections import Counter
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Iterator

import orjson
import yaml
from mcap.data_stream import ReadDataStream
from mcap.exceptions import RecordLengthLimitExceeded
from mcap.reader import make_reader
from mcap.records import Channel, Chunk, Message, Schema
from mcap.stream_reader import StreamReader

from replay.limits import LimitError, check, limit
from replay.log.chunks import MAGIC
from replay.log.errors import LogError, LogLimitError, NotALogError
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO

_loads = orjson.loads
# every digit as "0", "." as itself, every other byte as " ": a whole number of 20 digits is
# then a plain substring, " " and 20 "0"s (a fraction's digits follow a ".": orjson reads those
# as the standard decoder does, and small floats are written with many of them)
_DIGITS_ONLY = bytes(0x30 if 0x30 <= i <= 0x39 else i if i == 0x2E else 0x20 for i in range(256))
_TWENTY_DIGITS = b" " + b"0" * 20
_RECORD_LIMIT = 1 << 30  # no record of ours is near 1 GiB: a bigger length is damage
_OPCODES = range(0x01, 0x10)  # MCAP's record opcodes (0x00 is none: zeros are not records)
_HEAD = struct.Struct("<BQ")  # a record's opcode and length
# A chunk being written: foxglove-sdk's writer (the Rust mcap crate) puts a chunk's header down
# with every length all ones, and writes its data and the real lengths when the chunk is done;
# a run killed meanwhile ends on this header, a record cut short, not garbage.
_CHUNK_OPCODE, _LENGTH_PENDING = 0x06, (1 << 64) - 1
_SCHEMA_OPCODE, _CHANNEL_OPCODE, _MESSAGE_OPCODE = 0x03, 0x04, 0x05
_MESSAGE = struct.Struct("<HIQQ")  # a message's channel id, sequence, log and publish times
_RECORD_HEAD = 1024  # bytes of a record besides its payload (a message's or chunk's header)
# bytes of chunks (uncompressed) a reader keeps parsed, so that reading topic after topic
# decompresses each chunk once: a grasp run's log is ~21 MB, make run's longest ~47 MB
CACHED_CHUNK_BYTES = 128 * 1024 * 1024


def content_end(f, size: int) -> tuple[int, bool]:
    """Where the records of an MCAP file end, and whether a record cut short is what ends them
    (else zeros, garbage or nothing follow): past its last record whose header is an MCAP opcode
    and whose length fits in the file (and the closing magic, if it follows). Walks the
    records' 9-byte headers only, seeking over their bodies."""
    pos = len(MAGIC)
    while pos + _HEAD.size <= size:
        f.seek(pos)
        head = f.read(_HEAD.size)
        opcode, length = _HEAD.unpack(head)
        if opcode not in _OPCODES:
            if head[: len(MAGIC)] == MAGIC[: len(head)] and pos + len(MAGIC) <= size:
                return pos + len(MAGIC), False
            return pos, False
        if length > min(_RECORD_LIMIT, size - pos - _HEAD.size):
            pending = opcode == _CHUNK_OPCODE and length == _LENGTH_PENDING
            return pos, length <= _RECORD_LIMIT or pending
        pos += _HEAD.size + length
    return pos, pos < size


class _Bounded:
    """The first ``end`` bytes of a binary file, seekable (what the ``mcap`` reader is given
    when zeros or garbage follow the records)."""

    def __init__(self, f, end: int) -> None:
        self._f = f
        self._end = end
        self._pos = 0

    def readable(self) -> bool:
        return True

    def seekable(self) -> bool:
        return True

    def tell(self) -> int:
        return self._pos

    def seek(self, offset: int, whence: int = io.SEEK_SET) -> int:
        base = {io.SEEK_SET: 0, io.SEEK_CUR: self._pos, io.SEEK_END: self._end}[whence]
        self._pos = max(0, base + offset)
        return self._pos

    def read(self, n: int | None = -1) -> bytes:
        n = self._end - self._pos if n is None or n < 0 else min(n, self._end - self._pos)
        if n <= 0:
            return b""
        self._f.seek(self._pos)
        data = self._f.read(n)
        self._pos += len(data)
        return data

    def close(self) -> None:
        self._f.close()

    def __enter__(self) -> "_Bounded":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


@dataclass(frozen=True)
class LogMessage:
    topic: str
    t_ns: int
    data: dict

    @property
    def t(self) -> float:
        return self.t_ns * 1e-9


@dataclass(frozen=True)
class RawMessage:
    """A message as stored, for the channels that are not JSON (Foxglove's protobuf topics,
    the URDF's CDR string: ``replay.foxglove.schemas`` decodes them)."""

    topic: str
    t_ns: int
    schema: str  # the schema's name, e.g. foxglove.FrameTransforms
    encoding: str  # the channel's message encoding: protobuf, cdr
    data: bytes

    @property
    def t(self) -> float:
        return self.t_ns * 1e-9


TEXT_CHARS = 200  # a log's scenario name, paper or version: at most this long (clipped)
DESCRIPTION_CHARS = 2000
_TEXTS = {  # the /scenario message's text fields, and how long each may be (None: any)
    "name": TEXT_CHARS,
    "paper": TEXT_CHARS,
    "yaml": None,  # (within scenario_bytes: its reader checks that)
    "version": TEXT_CHARS,
    "description": DESCRIPTION_CHARS,  # (the stored scenario's)
}


def clip(text: str, chars: int) -> str:
    """``text`` if at most ``chars`` characters long, else its start, "…" and a short hash of
    the whole, ``chars`` long at most: two long names that start alike stay two names."""
    if len(text) <= chars:
        return text
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:10]
    return f"{text[: chars - 40]}…{digest}"


def _fields(data: dict) -> dict:
    """A ``/scenario`` message's fields of their types (as :meth:`LogReader.scenario` says)."""
    out: dict[str, Any] = {}
    for key, chars in _TEXTS.items():
        value = data.get(key)
        if isinstance(value, str):
            out[key] = value if chars is None else clip(value, chars)
    seed = data.get("seed")
    if type(seed) is int and 0 <= seed <= 2**63 - 1:
        out["seed"] = seed
    return out


def _decode(data: bytes) -> dict | None:
    """A message's JSON object (None if it is not one). orjson first (~4x the standard
    decoder's speed: a sweep's metrics decode thousands of messages a variant); what it refuses
    (a lone surrogate, ``NaN``, UTF-16 text, deep nesting) or reads otherwise (a whole number
    past 64 bits, which it makes a float: any run of 20 digits is left to the other) is read by
    the standard decoder, so every message reads as ``json.loads`` reads it."""
    try:
        if _TWENTY_DIGITS in data.translate(_DIGITS_ONLY):  # (~0.3 us: no regex scan)
            raise ValueError
        value = _loads(data)
    except ValueError:  # (orjson.JSONDecodeError is one)
        try:
            value = json.loads(data)
        except (ValueError, UnicodeDecodeError, RecursionError):
            return None
    return value if isinstance(value, dict) else None


def _chunk_body(data: bytes) -> list:
    """The schemas, channels and messages of a chunk's data. Messages are parsed here, in one
    ``struct`` call each (``mcap``'s reader makes ~5 calls a field: most of the time of 10**6
    events read); schemas and channels by ``mcap``."""
    out: list[Any] = []
    pos, end = 0, len(data)
    while pos < end:
        if end - pos < _HEAD.size:
            raise ValueError("a record cut short in its chunk")
        opcode, length = _HEAD.unpack_from(data, pos)
        body, after = pos + _HEAD.size, pos + _HEAD.size + length
        if after > end:
            raise ValueError("a record runs past its chunk's end")
        if opcode == _MESSAGE_OPCODE:
            if length < _MESSAGE.size:
                raise ValueError("a message record shorter than its header")
            channel_id, sequence, log_time, publish_time = _MESSAGE.unpack_from(data, body)
            out.append(
                Message(
                    channel_id=channel_id,
                    sequence=sequence,
                    log_time=log_time,
                    publish_time=publish_time,
                    data=data[body + _MESSAGE.size : after],
                )
            )
        elif opcode in (_SCHEMA_OPCODE, _CHANNEL_OPCODE):
            stream = ReadDataStream(io.BytesIO(data[body:after]))
            out.append(Schema.read(stream) if opcode == _SCHEMA_OPCODE else Channel.read(stream))
        pos = after
    return out


def _decompress(compression: str, data: bytes, size: int) -> bytes:
    """A chunk's data decompressed, at most ``size + 1`` bytes of it (one more than stated
    says the chunk holds more than it states)."""
    if compression == "":
        return data[: size + 1]
    if compression == "zstd":
        import zstandard

        parts, got = [], 0
        with zstandard.ZstdDecompressor().stream_reader(data) as r:
            while got <= size:
                part = r.read(size + 1 - got)
                if not part:
                    break
                parts.append(part)
                got += len(part)
        return b"".join(parts)
    if compression == "lz4":
        import lz4.frame

        return lz4.frame.LZ4FrameDecompressor().decompress(data, max_length=size + 1)
    raise ValueError(f"unknown compression {compression[:20]!r}")


class LogMessages:
    """What a log's messages are read as, from a file (:class:`LogReader`) or from a run's
    memory (:class:`replay.log.memory.MemoryReader`): the one interface analysis and the
    sweeps' metrics read. A subclass gives ``_json`` (topic, log time, stored bytes in log-time
    order) and sets :meth:`_start_reading`'s state."""

    path: Path

    def _start_reading(self) -> None:
        self.truncated = False
        self.damaged = False
        self.problems: list[str] = []
        self._bad_messages: Counter = Counter()
        self._scenario: dict | None = None
        self._config: dict = {}
        self._events: list[dict] | None = None

    def _json(self, wanted) -> Iterator[tuple[str, int, bytes]]:
        raise NotImplementedError

    @staticmethod
    def _limit(name: str) -> int:
        """:func:`replay.limits.limit`, raising :class:`LogLimitError` (a bad variable)."""
        try:
            return limit(name)
        except LimitError as exc:
            raise LogLimitError(str(exc)) from None

    @staticmethod
    def _check(name: str, size: int, what: str) -> None:
        """:func:`replay.limits.check`, raising :class:`LogLimitError`."""
        try:
            check(name, size, what)
        except LimitError as exc:
            raise LogLimitError(str(exc)) from None

    def _damage(self, what: str) -> None:
        self.damaged = True
        note = f"damaged: {what}"
        if note not in self.problems:
            self.problems.append(note)

    def messages(self, topics: Iterable[str] | str | None = None) -> Iterator[LogMessage]:
        """Messages in log-time order (file order for a truncated log), optionally by topic.
        Only channels of JSON messages are read (others, e.g. protobuf, are for other tools);
        messages on them that are not JSON objects are skipped (and counted in ``problems``)."""
        wanted = None if topics is None else ({topics} if isinstance(topics, str) else set(topics))
        for topic, t_ns, data in self._json(wanted):
            item = self._message(topic, t_ns, data)
            if item is not None:
                yield item

    def _message(self, topic: str, t_ns: int, data: bytes) -> LogMessage | None:
        value = _decode(data)
        if value is None:
            self._bad_messages[topic] += 1
            n = self._bad_messages[topic]
            self.problems = [p for p in self.problems if not p.startswith(f"damaged: {topic}: ")]
            self._damage(f"{topic}: {n} message(s) not a JSON object (skipped)")
            return None
        return LogMessage(topic, t_ns, value)

    def series(self, topic: str) -> list[dict]:
        """All payloads of one topic, in order: at most ``series_bytes`` of them as stored,
        counted as they are read, before each is decoded (:class:`LogLimitError` past it)."""
        cap, out, stored = self._limit("series_bytes"), [], 0
        for name, t_ns, data in self._json({topic}):
            stored += len(data)
            if stored > cap:
                what = f"{self.path}: its {topic} topic (as stored, read so far)"
                self._check("series_bytes", stored, what)
            item = self._message(name, t_ns, data)
            if item is not None:
                out.append(item.data)
        return out

    def scenario(self) -> dict:
        """The ``/scenario`` message's fields, bounded and typed (the one place analysis,
        report, figures and ``info`` get them): ``name``, ``paper``, ``version`` text of at most
        :data:`TEXT_CHARS` characters and ``description`` (the stored scenario's) of
        :data:`DESCRIPTION_CHARS`, longer ones :func:`clip`-ped; ``seed`` an integer from 0 to
        2^63 - 1; ``yaml`` checked as :meth:`scenario_config` says (a :class:`LogError` if it
        is not, or if there is no message). A field that is not of its type (a seed that is
        text, a name that is a list) is left out, as one the message lacks: ``.get`` says None."""
        if self._scenario is None:
            for m in self.messages(TOPIC_SCENARIO):
                self._config = self._stored_config(m.data.get("yaml", ""))
                self._scenario = _fields({**m.data, "description": self._config.get("description")})
                break
            else:
                raise LogError(f"{self.path}: no /scenario message")
        return dict(self._scenario)

    def scenario_config(self) -> dict:
        """The stored scenario YAML as data: within the ``scenario_bytes`` limit, YAML as a
        scenario file must be (nesting, size, tags), a mapping whose plug-in sections (plant,
        controller, each sensor and task) and their ``params`` are mappings."""
        self.scenario()
        return self._config

    def _stored_config(self, text) -> dict:
        from replay.scenario.yamlio import ScenarioError, compose

        where = f"{self.path}: its stored scenario"
        if not isinstance(text, str):
            raise LogError(f"{where} is not text ({type(text).__name__})")
        try:
            check("scenario_bytes", len(text), where)  # (characters: before encoding them)
            check("scenario_bytes", len(text.encode("utf-8", "surrogatepass")), where)
            node = compose(text, f"{self.path}:/scenario")
            config = {} if node is None else yaml.SafeLoader("").construct_document(node)
        except (LimitError, ScenarioError) as exc:
            raise LogError(
                str(exc) if str(exc).startswith(str(self.path)) else f"{where}: {exc}"
            ) from None
        except (yaml.YAMLError, RecursionError, ValueError, TypeError) as exc:
            raise LogError(f"{where} does not read ({type(exc).__name__})") from None
        if not isinstance(config, dict):
            raise LogError(f"{where} is not a mapping of sections ({type(config).__name__})")
        sections = [("plant", config.get("plant")), ("controller", config.get("controller"))]
        for group in ("sensors", "tasks"):
            members = config.get(group)
            if members is not None and not isinstance(members, dict):
                raise LogError(f"{where}: {group} is not a mapping ({type(members).__name__})")
            sections += [(f"{group}.{k}", v) for k, v in (members or {}).items()]
        for name, section in sections:
            if section is None:
                continue
            if not isinstance(section, dict):
                raise LogError(f"{where}: {name} is not a mapping ({type(section).__name__})")
            params = section.get("params")
            if params is not None and not isinstance(params, dict):
                raise LogError(f"{where}: {name}.params is not a mapping ({type(params).__name__})")
        return config

    def events(self) -> list[dict]:
        """The ``/events`` payloads that have a kind, read once (a log does not change; the
        claims of one paper ask for them many times)."""
        if self._events is None:
            self._events = [e for e in self.series(TOPIC_EVENTS) if isinstance(e.get("kind"), str)]
        return list(self._events)

    def outcome(self) -> dict | None:
        """The run's final ``outcome`` event (None when the log does not reach it)."""
        for e in reversed(self.events()):
            if e["kind"] == "outcome":
                return e
        return None


class LogReader(LogMessages):
    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            what = "not a file" if self.path.exists() else "no such log file"
            raise LogError(f"{self.path}: {what}")
        try:
            with open(self.path, "rb") as f:
                head = f.read(len(MAGIC))
                f.seek(0, os.SEEK_END)
                self.size = f.tell()
                f.seek(max(0, self.size - len(MAGIC)))
                tail = f.read(len(MAGIC))
        except OSError as exc:
            raise LogError(f"{self.path}: cannot read ({exc.strerror})") from None
        if head != MAGIC:
            raise NotALogError(f"{self.path}: not an MCAP log (bad magic bytes)")
        self._start_reading()
        self._bad_chunks: dict[int, str] = {}  # chunk offset -> why it does not read
        # chunk offset -> channel id -> [(place in the chunk, message)]: each chunk read once
        # (a grasp log is ~30 topics in 80 chunks, its analysis reads each topic), up to
        # CACHED_CHUNK_BYTES of them uncompressed; past that a chunk is read again when asked
        self._chunk_messages: dict[int, dict[int, list[tuple[int, Message]]]] = {}
        self._cached_bytes = 0
        self._checked = False
        self._end = self.size  # where the records end (before zeros or garbage)
        self._summary = self._read_summary() if tail == MAGIC else None
        if self._summary is None:
            self._find_end()
        for c in self._summary.chunk_indexes if self._summary is not None else ():
            self._check_size(
                c.uncompressed_size, f"the chunk at byte {c.chunk_start_offset}, uncompressed,"
            )
        if self._summary is None:
            self.truncated = True
            if tail == MAGIC and self.size > 2 * len(MAGIC):
                self._damage("its summary (index, statistics) cannot be read")
            else:
                self.problems.append(
                    "truncated: the file ends mid-run (no summary): read up "
                    "to its last whole record"
                )

    def _open(self):
        """The file, cut at the end of its records."""
        f = open(self.path, "rb")
        return f if self._end == self.size else _Bounded(f, self._end)

    def _read_summary(self):
        try:
            with self._open() as f:
                return make_reader(f).get_summary()
        except Exception:  # noqa: BLE001 - mcap raises many kinds on bad bytes
            return None

    def _find_end(self) -> None:
        """Zeros or garbage after the last record: cut off (and said), the summary looked for
        before them."""
        try:
            with open(self.path, "rb") as f:
                end, torn = content_end(f, self.size)
                f.seek(end)
                sample = f.read(4096)
        except OSError:
            return
        if end >= self.size or torn:
            return  # (a record cut short: a truncated log, said as such)
        self._end = end
        what = "zeros" if not sample.strip(b"\0") else "not MCAP records"
        self._damage(f"its last {self.size - end} bytes (from byte {end} on) are {what}: ignored")
        self._summary = self._read_summary()

    def _check_size(self, size: int, what: str) -> None:
        """LogLimitError if ``size`` bytes (of ``what``) are over ``message_bytes``."""
        self._check("message_bytes", size, f"{self.path}: {what}")

    def _record_cap(self) -> int:
        """The longest record a reader loads: ``message_bytes`` and a header."""
        return self._limit("message_bytes") + _RECORD_HEAD

    def _walk(self, f, *, validate: bool, chunks: bool = True) -> Iterator[Any]:
        """The records of ``f`` in file order, each chunk's broken up (``chunks``) or as it is;
        raises what a bad record raises, and :class:`LogLimitError` for a record over
        ``message_bytes`` that the file holds whole (a longer one is a torn tail)."""
        records = StreamReader(
            f, emit_chunks=True, validate_crcs=validate, record_size_limit=self._record_cap()
        ).records
        while True:
            try:
                record = next(records)
            except StopIteration:
                return
            except RecordLengthLimitExceeded:
                pos = f.tell()  # (just past the record's header)
                f.seek(pos - _HEAD.size)
                _, length = _HEAD.unpack(f.read(_HEAD.size))
                if length <= self._end - pos:
                    self._check_size(length, f"the record at byte {pos - _HEAD.size}")
                raise
            if chunks and isinstance(record, Chunk):
                yield from self._chunk_records(record)
            else:
                yield record

    def _chunk_records(self, chunk: Chunk) -> list:
        """A chunk's records (schemas, channels, messages): its stated size checked against
        ``message_bytes`` before it is decompressed, no further than that size, CRC checked."""
        size = chunk.uncompressed_size
        self._check_size(size, "a chunk, uncompressed,")
        data = _decompress(chunk.compression, chunk.data, size)
        if len(data) != size:
            raise ValueError(f"the chunk decompresses to {'more' if len(data) > size else 'less'}")
        if chunk.uncompressed_crc and zlib.crc32(data) != chunk.uncompressed_crc:
            raise ValueError("the chunk's CRC does not match")
        return _chunk_body(data)

    @property
    def status(self) -> str:
        """``complete``, ``truncated`` or ``damaged``."""
        return "damaged" if self.damaged else "truncated" if self.truncated else "complete"

    def check(self) -> "LogReader":
        """Read every record once with CRCs checked (a few ms per MB), so that ``damaged`` and
        ``problems`` are known before the log is used: an indexed log chunk by chunk through its
        index (a damaged chunk is then skipped, the rest read), another record by record."""
        if self._checked:
            return self
        self._checked = True
        if self._summary is not None:
            self._check_chunks()
            self._check_records()
            return self
        n = 0
        try:
            with self._open() as f:
                for _ in self._walk(f, validate=True):
                    n += 1
        except LogLimitError:
            raise
        except Exception as exc:  # noqa: BLE001
            if not self.truncated or self._summary is not None:
                self._damage(
                    f"a record after {n} whole ones does not read "
                    f"({type(exc).__name__}); what follows it is missing"
                )
            self._summary = None
            self.truncated = True
        return self

    def _chunk_indexes(self) -> list:
        assert self._summary is not None
        return sorted(self._summary.chunk_indexes, key=lambda c: c.chunk_start_offset)

    def _read_chunk(self, f, index) -> list:
        """The records of the chunk an index entry points at, its CRC checked."""
        f.seek(index.chunk_start_offset)
        opcode, length = _HEAD.unpack(f.read(_HEAD.size).ljust(_HEAD.size, b"\0"))
        if opcode != _CHUNK_OPCODE:
            raise ValueError("the index points at a record that is not a chunk")
        if self._record_cap() < length <= self._end - f.tell():
            self._check_size(length, f"the chunk record at byte {index.chunk_start_offset}")
        return self._chunk_records(Chunk.read(ReadDataStream(f)))

    def _check_chunks(self) -> None:
        indexes = self._chunk_indexes()
        try:
            with self._open() as f:
                for i, c in enumerate(indexes):
                    try:
                        self._read_chunk(f, c)
                    except LogLimitError:
                        raise
                    except Exception as exc:  # noqa: BLE001 - any damage of its bytes
                        self._bad_chunk(i, len(indexes), c, exc)
        except OSError as exc:
            self._damage(f"cannot be read ({exc.strerror})")

    def _check_records(self) -> None:
        """The records outside the chunks (header, metadata, summary), parsed once."""
        n = 0
        try:
            with self._open() as f:
                for _ in self._walk(f, validate=False, chunks=False):
                    n += 1
        except LogLimitError:
            raise
        except Exception as exc:  # noqa: BLE001
            if not self._bad_chunks:
                self._damage(
                    f"a record after {n} whole ones does not read ({type(exc).__name__}); "
                    "the chunks are read through the index"
                )

    def _bad_chunk(self, i: int, n: int, c, exc: BaseException) -> None:
        self._bad_chunks[c.chunk_start_offset] = type(exc).__name__
        end = c.chunk_start_offset + c.chunk_length
        self._damage(
            f"chunk {i + 1} of {n} (bytes {c.chunk_start_offset}-{end}, t = "
            f"{c.message_start_time * 1e-9:.4f}-{c.message_end_time * 1e-9:.4f} s) does not "
            f"read ({type(exc).__name__}): its messages are missing, the other chunks are read"
        )

    def _messages_of(self, f, index) -> dict[int, list[tuple[int, Message]]]:
        """The messages of the chunk an index entry points at, by channel (those the summary
        names), each with its place in the chunk: read once and kept while the kept chunks
        stay under CACHED_CHUNK_BYTES uncompressed."""
        kept = self._chunk_messages.get(index.chunk_start_offset)
        if kept is not None:
            return kept
        channels = self._summary.channels if self._summary is not None else {}
        by_channel: dict[int, list[tuple[int, Message]]] = {}
        for i, record in enumerate(self._read_chunk(f, index)):
            if isinstance(record, Message) and record.channel_id in channels:
                by_channel.setdefault(record.channel_id, []).append((i, record))
        if self._cached_bytes + index.uncompressed_size <= CACHED_CHUNK_BYTES:
            self._cached_bytes += index.uncompressed_size
            self._chunk_messages[index.chunk_start_offset] = by_channel
        return by_channel

    def _indexed(self, wanted) -> Iterator[tuple[Any, Channel, Message]]:
        """(schema, channel, message) through the index, in log-time order (ties in file
        order), chunk by chunk: a message is handed on once no chunk still to be read can
        start before it. A chunk that does not read is skipped and said."""
        assert self._summary is not None
        channels, schemas = self._summary.channels, self._summary.schemas
        indexes = self._chunk_indexes()
        number = {c.chunk_start_offset: i for i, c in enumerate(indexes)}

        def wanted_in(c) -> bool:
            ids = c.message_index_offsets
            return (
                wanted is None
                or not ids
                or any(i not in channels or channels[i].topic in wanted for i in ids)
            )

        todo = sorted(
            (c for c in indexes if c.chunk_start_offset not in self._bad_chunks and wanted_in(c)),
            key=lambda c: (c.message_start_time, c.chunk_start_offset),
        )
        heap: list[tuple[int, int, int, Channel, Message]] = []  # (C tuples: fast to compare)
        with self._open() as f:
            for c in todo:
                while heap and heap[0][0] < c.message_start_time:
                    _, _, _, channel, msg = heapq.heappop(heap)
                    yield schemas.get(channel.schema_id), channel, msg
                try:
                    by_channel = self._messages_of(f, c)
                except LogLimitError:
                    raise
                except Exception as exc:  # noqa: BLE001 - any damage of its bytes
                    self._bad_chunk(number[c.chunk_start_offset], len(indexes), c, exc)
                    continue
                for channel_id, messages in by_channel.items():
                    channel = channels[channel_id]
                    if wanted is None or channel.topic in wanted:
                        for i, record in messages:
                            item = (record.log_time, c.chunk_start_offset, i, channel, record)
                            heapq.heappush(heap, item)
        while heap:
            _, _, _, channel, msg = heapq.heappop(heap)
            yield schemas.get(channel.schema_id), channel, msg

    # -- messages -------------------------------------------------------------------------

    def _json(self, wanted) -> Iterator[tuple[str, int, bytes]]:
        """(topic, log time, stored bytes) of the JSON channels' messages, in the order
        :meth:`messages` says, undecoded."""
        if self._summary is None or not self._summary.chunk_indexes:
            yield from self._stream(wanted)
            return
        for _, channel, msg in self._indexed(wanted):
            if channel.message_encoding == "json":  # (not e.g. Foxglove's protobuf channels)
                yield channel.topic, msg.log_time, msg.data

    def _records(self) -> Iterator[Any]:
        """The file's records in order, CRCs checked, ending quietly at a torn or damaged tail."""
        with self._open() as f:
            records = self._walk(f, validate=True)
            while True:
                try:
                    yield next(records)
                except StopIteration:
                    return
                except LogLimitError:
                    raise
                except Exception:  # noqa: BLE001 - the torn or damaged tail: stop there
                    return

    def _stream(self, wanted) -> Iterator[tuple[str, int, bytes]]:
        channels: dict[int, str] = {}  # the JSON channels' topics
        for record in self._records():
            if isinstance(record, Channel):
                if record.message_encoding == "json":
                    channels[record.id] = record.topic
            elif isinstance(record, Message):
                topic = channels.get(record.channel_id)
                if topic is not None and (wanted is None or topic in wanted):
                    yield topic, record.log_time, record.data

    def raw(self, topics: Iterable[str] | str | None = None) -> Iterator[RawMessage]:
        """The messages of the channels that are not JSON, undecoded, in log-time order (file
        order for a truncated log), optionally by topic."""
        wanted = None if topics is None else ({topics} if isinstance(topics, str) else set(topics))
        if self._summary is not None and self._summary.chunk_indexes:
            for schema, channel, msg in self._indexed(wanted):
                if channel.message_encoding != "json":
                    name = schema.name if schema is not None else ""
                    yield RawMessage(
                        channel.topic, msg.log_time, name, channel.message_encoding, msg.data
                    )
            return
        yield from self._stream_raw(wanted)

    def _stream_raw(self, wanted) -> Iterator[RawMessage]:
        schemas: dict[int, str] = {}
        channels: dict[
            int, tuple[str, str, int]
        ] = {}  # the other channels: topic, encoding, schema
        for record in self._records():
            if isinstance(record, Schema):
                schemas[record.id] = record.name
            elif isinstance(record, Channel):
                if record.message_encoding != "json":
                    channels[record.id] = (
                        record.topic,
                        record.message_encoding,
                        record.schema_id,
                    )
            elif isinstance(record, Message) and record.channel_id in channels:
                topic, encoding, schema_id = channels[record.channel_id]
                if wanted is None or topic in wanted:
                    yield RawMessage(
                        topic,
                        record.log_time,
                        schemas.get(schema_id, ""),
                        encoding,
                        record.data,
                    )

    # -- summary --------------------------------------------------------------------------
    def topic_counts(self) -> dict[str, int]:
        """Messages per topic: the statistics' counts, or what was read where chunks are lost."""
        if (
            self._summary is not None
            and self._summary.statistics is not None
            and not self._bad_chunks
        ):
            stats = self._summary.statistics.channel_message_counts
            channels = self._summary.channels
            return {
                channels[cid].topic if cid in channels else f"(channel {cid})": n
                for cid, n in sorted(stats.items())
            }
        return dict(Counter(m.topic for m in self.messages()))

    def time_range(self) -> tuple[float, float]:
        if self._summary is not None and self._summary.statistics is not None:
            s = self._summary.statistics
            return s.message_start_time * 1e-9, s.message_end_time * 1e-9
        times = [m.t_ns for m in self.messages()]
        return (min(times) * 1e-9, max(times) * 1e-9) if times else (0.0, 0.0)

    def metadata(self) -> dict[str, dict[str, str]]:
        out: dict[str, dict[str, str]] = {}
        if self._summary is None:
            return out
        try:
            with self._open() as f:
                for record in make_reader(f).iter_metadata():
                    out[record.name] = dict(record.metadata)
        except Exception:  # noqa: BLE001
            self._damage("its metadata cannot be read")
        return out

    def describe_problems(self) -> list[str]:
        """What a reader of this log must be told: damage, truncation and what is missing."""
        notes = list(self.problems)
        if self.truncated or self.damaged:
            try:
                t_end = self.time_range()[1]
                ended = self.outcome() is not None
            except LogError:
                t_end, ended = 0.0, False
            if not ended:
                notes.append(
                    f"the run's end is missing: no outcome event; the log stops at "
                    f"t = {t_end:.4f} s"
                )
        return notes
