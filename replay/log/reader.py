"""Reading a run's MCAP log back as (topic, simulated time, decoded JSON dict), saying what it read.

A finished log is read through its index. A log whose summary is missing (a run killed mid-way,
a ``.part`` file, a file cut short) is read record by record up to its last whole record and is
``truncated``. A log whose bytes are wrong (a chunk whose CRC does not match, a record that does
not parse, a message that is not a JSON object) is ``damaged``: what can be read is read, and
:attr:`LogReader.problems` says what was not. Nothing a log's bytes hold raises anything but
:class:`LogError`.
"""

from __future__ import annotations

import json
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Iterable, Iterator

from mcap.reader import make_reader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader

from replay.log.chunks import MAGIC
from replay.log.errors import LogError, NotALogError
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO

_RECORD_LIMIT = 1 << 30  # no record of ours is near 1 GiB: a bigger length is damage


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


def _decode(data: bytes) -> dict | None:
    try:
        value = json.loads(data)
    except (ValueError, UnicodeDecodeError, RecursionError):
        return None
    return value if isinstance(value, dict) else None


class LogReader:
    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise LogError(f"{self.path}: no such log file")
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
        self.truncated = False
        self.damaged = False
        self.problems: list[str] = []
        self._bad_messages: Counter = Counter()
        self._checked = False
        self._summary = None
        try:
            with open(self.path, "rb") as f:
                self._summary = make_reader(f).get_summary()
        except Exception:  # noqa: BLE001 - mcap raises many kinds on bad bytes
            self._summary = None
        if self._summary is None:
            self.truncated = True
            if tail == MAGIC and self.size > 2 * len(MAGIC):
                self._damage("its summary (index, statistics) cannot be read")
            else:
                self.problems.append(
                    "truncated: the file ends mid-run (no summary): read up "
                    "to its last whole record"
                )

    def _damage(self, what: str) -> None:
        self.damaged = True
        note = f"damaged: {what}"
        if note not in self.problems:
            self.problems.append(note)

    @property
    def status(self) -> str:
        """``complete``, ``truncated`` or ``damaged``."""
        return "damaged" if self.damaged else "truncated" if self.truncated else "complete"

    def check(self) -> "LogReader":
        """Read every record once with CRCs checked (a few ms per MB), so that ``damaged`` and
        ``problems`` are known before the log is used; a damaged log is then read record by
        record (the index may point into the damage)."""
        if self._checked:
            return self
        self._checked = True
        n = 0
        try:
            with open(self.path, "rb") as f:
                for _ in StreamReader(
                    f, validate_crcs=True, record_size_limit=_RECORD_LIMIT
                ).records:
                    n += 1
        except Exception as exc:  # noqa: BLE001
            if not self.truncated or self._summary is not None:
                self._damage(
                    f"a record after {n} whole ones does not read "
                    f"({type(exc).__name__}); what follows it is missing"
                )
            self._summary = None
            self.truncated = True
        return self

    # -- messages -------------------------------------------------------------------------
    def messages(self, topics: Iterable[str] | str | None = None) -> Iterator[LogMessage]:
        """Messages in log-time order (file order for a truncated log), optionally by topic.
        Only channels of JSON messages are read (others, e.g. protobuf, are for other tools);
        messages on them that are not JSON objects are skipped (and counted in ``problems``)."""
        wanted = None if topics is None else ({topics} if isinstance(topics, str) else set(topics))
        if self._summary is not None:
            done = 0
            try:
                with open(self.path, "rb") as f:
                    for _, channel, msg in make_reader(f).iter_messages(topics=wanted):
                        if channel.message_encoding != "json":
                            continue  # e.g. Foxglove's protobuf channels: not JSON payloads
                        item = self._message(channel.topic, msg.log_time, msg.data)
                        if item is not None:
                            done += 1
                            yield item
                return
            except Exception as exc:  # noqa: BLE001
                self._damage(
                    f"the index points at bad bytes ({type(exc).__name__}); "
                    "read record by record instead"
                )
                self._summary = None
                self.truncated = True
                skip = done
        else:
            skip = 0
        for i, item in enumerate(self._stream(wanted)):
            if i >= skip:
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

    def _records(self) -> Iterator[Any]:
        """The file's records in order, CRCs checked, ending quietly at a torn or damaged tail."""
        with open(self.path, "rb") as f:
            records = StreamReader(f, validate_crcs=True, record_size_limit=_RECORD_LIMIT).records
            while True:
                try:
                    yield next(records)
                except StopIteration:
                    return
                except Exception:  # noqa: BLE001 - the torn or damaged tail: stop there
                    return

    def _stream(self, wanted) -> Iterator[LogMessage]:
        channels: dict[int, str] = {}  # the JSON channels' topics
        for record in self._records():
            if isinstance(record, Channel):
                if record.message_encoding == "json":
                    channels[record.id] = record.topic
            elif isinstance(record, Message):
                topic = channels.get(record.channel_id)
                if topic is not None and (wanted is None or topic in wanted):
                    item = self._message(topic, record.log_time, record.data)
                    if item is not None:
                        yield item

    def raw(self, topics: Iterable[str] | str | None = None) -> Iterator[RawMessage]:
        """The messages of the channels that are not JSON, undecoded, in log-time order (file
        order for a truncated log), optionally by topic."""
        wanted = None if topics is None else ({topics} if isinstance(topics, str) else set(topics))
        if self._summary is not None:
            try:
                with open(self.path, "rb") as f:
                    for schema, channel, msg in make_reader(f).iter_messages(topics=wanted):
                        if channel.message_encoding != "json":
                            name = schema.name if schema is not None else ""
                            yield RawMessage(
                                channel.topic,
                                msg.log_time,
                                name,
                                channel.message_encoding,
                                msg.data,
                            )
                return
            except Exception as exc:  # noqa: BLE001
                self._damage(f"the index points at bad bytes ({type(exc).__name__})")
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

    def series(self, topic: str) -> list[dict]:
        """All payloads of one topic, in order."""
        return [m.data for m in self.messages(topic)]

    # -- summary --------------------------------------------------------------------------
    def topic_counts(self) -> dict[str, int]:
        if self._summary is not None and self._summary.statistics is not None:
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
            with open(self.path, "rb") as f:
                for record in make_reader(f).iter_metadata():
                    out[record.name] = dict(record.metadata)
        except Exception:  # noqa: BLE001
            self._damage("its metadata cannot be read")
        return out

    def scenario(self) -> dict:
        """The ``/scenario`` message (name, paper, yaml, seed, version)."""
        for m in self.messages(TOPIC_SCENARIO):
            return m.data
        raise LogError(f"{self.path}: no /scenario message")

    def events(self) -> list[dict]:
        return [e for e in self.series(TOPIC_EVENTS) if isinstance(e.get("kind"), str)]

    def outcome(self) -> dict | None:
        """The run's final ``outcome`` event (None when the log does not reach it)."""
        for e in reversed(self.events()):
            if e["kind"] == "outcome":
                return e
        return None

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
