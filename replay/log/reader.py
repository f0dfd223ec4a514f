"""Reading a run's MCAP log back as (topic, simulated time, decoded JSON dict).

A finished log is read through its index. A log whose summary is missing (a run killed mid-way,
or a ``.part`` file) is read record by record up to the last complete chunk, and says so
(``truncated``).
"""

from __future__ import annotations

import json
import os
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Iterable, Iterator

from mcap.exceptions import McapError
from mcap.reader import make_reader
from mcap.records import Message
from mcap.stream_reader import StreamReader

from replay.log.errors import LogError, NotALogError
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO

MAGIC = b"\x89MCAP0\r\n"


@dataclass(frozen=True)
class LogMessage:
    topic: str
    t_ns: int
    data: dict

    @property
    def t(self) -> float:
        return self.t_ns * 1e-9


class LogReader:
    def __init__(self, path: str | os.PathLike) -> None:
        self.path = Path(path)
        if not self.path.is_file():
            raise LogError(f"{self.path}: no such log file")
        with open(self.path, "rb") as f:
            head = f.read(len(MAGIC))
        if head != MAGIC:
            raise NotALogError(f"{self.path}: not an MCAP log (bad magic bytes)")
        self.truncated = False
        self._summary = None
        try:
            with open(self.path, "rb") as f:
                self._summary = make_reader(f).get_summary()
        except (McapError, ValueError, EOFError, OSError, KeyError):
            self._summary = None
        if self._summary is None:
            self.truncated = True

    # -- messages -------------------------------------------------------------------------
    def messages(self, topics: Iterable[str] | str | None = None) -> Iterator[LogMessage]:
        """Messages in log-time order (file order for a truncated log), optionally by topic."""
        wanted = None if topics is None else ({topics} if isinstance(topics, str) else set(topics))
        if not self.truncated:
            with open(self.path, "rb") as f:
                for _, channel, msg in make_reader(f).iter_messages(topics=wanted):
                    yield LogMessage(channel.topic, msg.log_time, json.loads(msg.data))
            return
        yield from self._stream(wanted)

    def _stream(self, wanted) -> Iterator[LogMessage]:
        channels: dict[int, str] = {}
        from mcap.records import Channel
        with open(self.path, "rb") as f:
            records = StreamReader(f).records
            while True:
                try:
                    record = next(records)
                except StopIteration:
                    return
                except (McapError, ValueError, EOFError, KeyError, Exception):  # noqa: BLE001
                    return  # the torn tail of a killed run: stop at the last whole record
                if isinstance(record, Channel):
                    channels[record.id] = record.topic
                elif isinstance(record, Message):
                    topic = channels.get(record.channel_id)
                    if topic is not None and (wanted is None or topic in wanted):
                        yield LogMessage(topic, record.log_time, json.loads(record.data))

    def series(self, topic: str) -> list[dict]:
        """All payloads of one topic, in order."""
        return [m.data for m in self.messages(topic)]

    # -- summary --------------------------------------------------------------------------
    def topic_counts(self) -> dict[str, int]:
        if self._summary is not None and self._summary.statistics is not None:
            stats = self._summary.statistics.channel_message_counts
            return {self._summary.channels[cid].topic: n for cid, n in sorted(stats.items())}
        return dict(Counter(m.topic for m in self.messages()))

    def time_range(self) -> tuple[float, float]:
        if self._summary is not None and self._summary.statistics is not None:
            s = self._summary.statistics
            return s.message_start_time * 1e-9, s.message_end_time * 1e-9
        times = [m.t_ns for m in self.messages()]
        return (min(times) * 1e-9, max(times) * 1e-9) if times else (0.0, 0.0)

    def metadata(self) -> dict[str, dict[str, str]]:
        out: dict[str, dict[str, str]] = {}
        if self.truncated:
            return out
        with open(self.path, "rb") as f:
            for record in make_reader(f).iter_metadata():
                out[record.name] = dict(record.metadata)
        return out

    def scenario(self) -> dict:
        """The ``/scenario`` message (name, paper, yaml, seed, version)."""
        for m in self.messages(TOPIC_SCENARIO):
            return m.data
        raise LogError(f"{self.path}: no /scenario message")

    def events(self) -> list[dict]:
        return self.series(TOPIC_EVENTS)
