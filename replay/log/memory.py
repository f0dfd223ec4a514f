"""A run's messages kept in memory instead of a log (``Runner.run(None, keep=True)``), and read
back through the same interface as a log file (:class:`replay.log.reader.LogMessages`).

A sweep that keeps no logs but has a ``metrics:`` function runs its variants this way: each
message is encoded as the log writer encodes it (:class:`~replay.log.unwritten.UnwrittenLog`) and
its bytes are kept, so the metrics read the very bytes a log would hold, decoded as a
:class:`~replay.log.LogReader` decodes them: the same numbers with a log or without one. What a
log holds besides (its Foxglove topics: 3-D frames, camera images; its metadata records) is not
made; its metadata records (provenance, scenario) are kept."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any, Iterator

import yaml

from replay.log.reader import LogMessages, RawMessage
from replay.log.unwritten import UnwrittenLog
from replay.log.writer import encode


_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class KeptLog(UnwrittenLog):
    """What the runner writes to when it keeps its messages in memory: each one checked and
    encoded as a log's, its bytes kept."""

    def __init__(self) -> None:
        super().__init__()
        self.kept: list[tuple[str, int, bytes]] = []  # (topic, log time ns, stored bytes)
        self.records: dict[str, dict[str, str]] = {}  # the metadata records a log would hold

    def write(self, topic: str, payload: Any, t_ns: int) -> None:
        self.kept.append((topic, t_ns, encode(topic, payload)))
        self.count += 1

    def metadata(self, name: str, data: dict[str, str]) -> None:
        self.records[name] = dict(data)

    def reader(self, name: str = "<memory>") -> "MemoryReader":
        return MemoryReader(self.kept, self.records, name)


class MemoryReader(LogMessages):
    """The kept messages read as a log's (``series``, ``events``, ``outcome``, ``scenario``,
    ``scenario_config``, ``topic_counts``, ``messages``...), in log-time order with ties in
    written order, as :class:`~replay.log.LogReader` reads a log's."""

    def __init__(
        self,
        kept: list[tuple[str, int, bytes]],
        records: dict[str, dict[str, str]] | None = None,
        name: str = "<memory>",
    ) -> None:
        self.path = Path(name)
        self._start_reading()
        self._records = dict(records or {})
        self._kept = sorted(kept, key=lambda m: m[1])  # (stable: ties keep their order)

    def _json(self, wanted) -> Iterator[tuple[str, int, bytes]]:
        if wanted is None:
            yield from self._kept
            return
        for m in self._kept:
            if m[0] in wanted:
                yield m

    def _stored_config(self, text) -> dict:
        """The run's own resolved scenario as data: the text the runner wrote (a scenario that
        loaded, so within every bound a log's is checked against), read by libyaml where PyYAML
        has it (~10x the pure-Python parser a log's text is checked with; the same data)."""
        return yaml.load(text, Loader=_LOADER)

    @property
    def status(self) -> str:
        return "complete"

    def check(self) -> "MemoryReader":
        return self

    def describe_problems(self) -> list[str]:
        return list(self.problems)

    def topic_counts(self) -> dict[str, int]:
        return dict(Counter(m[0] for m in self._kept))

    def time_range(self) -> tuple[float, float]:
        if not self._kept:
            return 0.0, 0.0
        return self._kept[0][1] * 1e-9, self._kept[-1][1] * 1e-9

    def metadata(self) -> dict[str, dict[str, str]]:
        return {name: dict(data) for name, data in self._records.items()}

    def raw(self, topics=None) -> Iterator[RawMessage]:
        return iter(())  # (no Foxglove topics are made without a log)
