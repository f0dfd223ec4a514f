"""Writing a run's MCAP log: JSON messages with JSON schemas, stamped with simulated time.

Crash safety: the file is written under ``NAME.part`` and renamed to ``NAME`` on close; chunks are
small and flushed, so a run killed mid-way leaves a ``.part`` file readable up to its last chunk
(``LogReader`` reads it). Same messages in the same order give the same bytes.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import orjson
from mcap.writer import CompressionType, Writer

from replay import __version__
from replay.log.errors import LogError, NonFiniteValueError
from replay.messages import TOPICS, json_schema, to_dict

PART_SUFFIX = ".part"
_ENCODER = json.JSONEncoder(allow_nan=False, separators=(",", ":"))   # built once: dumps() with
                                                                       # options builds one a call
_ORJSON = orjson.OPT_NON_STR_KEYS          # keys as the standard encoder writes them


def encode(topic: str, payload: Any) -> bytes:
    """A payload (dataclass or dict) as compact JSON bytes; the same payload gives the same bytes.

    orjson (~10x the standard encoder's speed, dataclasses without a dict copy) writes NaN and
    infinity as ``null``, so a message holding ``null`` is checked again by the standard encoder,
    which refuses non-finite numbers (:class:`NonFiniteValueError`); so is a payload holding a
    type only the standard encoder takes (e.g. ``numpy.float64``), which it then encodes.
    """
    try:
        data = orjson.dumps(payload, option=_ORJSON)
    except TypeError:
        data = None
    if data is None or b"null" in data:
        body = to_dict(payload)
        try:
            checked = _ENCODER.encode(body).encode()
        except ValueError:
            raise NonFiniteValueError(topic, body) from None
        data = checked if data is None else data
    return data


def seconds_to_ns(t: float) -> int:
    return int(round(t * 1e9))


class _FlushedFile:
    """A file whose every write reaches the OS at once, so a killed run keeps its last chunk."""

    def __init__(self, f) -> None:
        self._f = f

    def write(self, data) -> int:
        n = self._f.write(data)
        self._f.flush()
        return n

    def tell(self) -> int:
        return self._f.tell()

    def close(self) -> None:
        self._f.close()


class LogWriter:
    """``with LogWriter(path) as log: log.write("/events", Event(...), t_ns)``."""

    def __init__(self, path: str | os.PathLike, *, chunk_size: int = 256 * 1024,
                 compression: str = "zstd") -> None:
        self.path = Path(path)
        self.part_path = self.path.with_name(self.path.name + PART_SUFFIX)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            self._file = _FlushedFile(open(self.part_path, "wb"))
        except OSError as exc:
            raise LogError(f"cannot write log {self.part_path}: {exc.strerror}") from exc
        comp = {"zstd": CompressionType.ZSTD, "lz4": CompressionType.LZ4,
                "none": CompressionType.NONE}[compression]
        self._writer = Writer(self._file, chunk_size=chunk_size, compression=comp)
        self._writer.start(profile="", library=f"paper-replay {__version__}")
        self._channels: dict[str, int] = {}
        self._sequence: dict[str, int] = {}
        self.count = 0
        self.closed = False

    def _channel(self, topic: str, payload: Any) -> int:
        if topic not in self._channels:
            cls = TOPICS.get(topic) or (None if isinstance(payload, dict) else type(payload))
            schema = json_schema(cls) if cls is not None else {"title": topic, "type": "object"}
            schema_id = self._writer.register_schema(
                name=schema["title"], encoding="jsonschema",
                data=json.dumps(schema, separators=(",", ":")).encode())
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="json", schema_id=schema_id)
            self._sequence[topic] = 0
        return self._channels[topic]

    def write(self, topic: str, payload: Any, t_ns: int) -> None:
        """Write one message; ``t_ns`` (simulated time) is both log and publish time."""
        data = encode(topic, payload)
        channel = self._channel(topic, payload)
        self._writer.add_message(channel_id=channel, log_time=t_ns, publish_time=t_ns,
                                 data=data, sequence=self._sequence[topic])
        self._sequence[topic] += 1
        self.count += 1

    def metadata(self, name: str, data: dict[str, str]) -> None:
        self._writer.add_metadata(name, {k: str(v) for k, v in data.items()})

    def close(self) -> Path:
        """Finish the file (summary, index) and give it its final name."""
        if not self.closed:
            self._writer.finish()
            self._file.close()
            os.replace(self.part_path, self.path)
            self.closed = True
        return self.path

    def __enter__(self) -> "LogWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close()
