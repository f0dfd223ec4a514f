"""Writing a run's MCAP log: JSON messages with JSON schemas, stamped with simulated time.

Where and how the file is written (``NAME.PID.part``, locks, renames, held Ctrl-C, never over
a file that is not a log) is :mod:`replay.log.output`'s. A failed write (a full disk, an I/O
error) raises :class:`LogWriteError` from the call that made it (the MCAP writer, foxglove-sdk's,
would only log it: ``_Sink`` keeps the ``OSError`` and every call looks), and the run's ``.part``
is then left to the caller.

Same messages in the same order give the same bytes. The file's records are foxglove-sdk's
(:mod:`replay.log.chunks`): each channel's messages are numbered 1, 2, ...; a schema and a
channel are written with the channel's first message.
"""

from __future__ import annotations

import dataclasses
import functools
import json
import logging
import math
import os
from pathlib import Path
from typing import Any

import orjson

import foxglove

from replay.log.chunks import mcap_writer
from replay.log.errors import LogError, LogWriteError, NonFiniteValueError
from replay.log.output import HeldSigint, OutputConflictError, check_output, open_part, place
from replay.messages import TOPICS, json_schema, to_dict

_ENCODER = json.JSONEncoder(allow_nan=False, separators=(",", ":"))  # built once: dumps() with
# options builds one a call
_ORJSON = orjson.OPT_NON_STR_KEYS  # int keys as the standard encoder writes them
_dumps = orjson.dumps


def encode(topic: str, payload: Any) -> bytes:
    """A payload (dataclass or dict) as compact JSON bytes; the same payload gives the same bytes.

    orjson (~10x the standard encoder's speed, dataclasses without a dict copy) writes NaN and
    infinity as ``null``, so a message holding ``null`` has its numbers checked
    (:class:`NonFiniteValueError` names the field); a payload holding a type only the standard
    encoder takes (e.g. ``numpy.float64``) is encoded by it, which refuses non-finite numbers.
    """
    try:
        data = _dumps(payload)
    except TypeError:
        try:
            data = _dumps(payload, option=_ORJSON)  # (slower than without: only when needed)
        except TypeError:
            body = to_dict(payload)
            try:
                return _ENCODER.encode(body).encode()
            except ValueError:
                raise NonFiniteValueError(topic, body) from None
    if b"null" in data and not _finite(payload):
        raise NonFiniteValueError(topic, to_dict(payload))
    return data


_LEAVES = frozenset({str, int, bool, type(None)})


def _finite(value: Any) -> bool:
    """No NaN or infinity anywhere in a payload (what orjson serialises: dataclasses, dicts,
    lists, tuples, scalars)."""
    tp = type(value)
    if tp is float:
        return value - value == 0.0  # NaN - NaN and inf - inf are NaN
    if tp in _LEAVES:
        return True
    if tp is dict:
        items = value.values()
    elif tp is list or tp is tuple:
        items = value
    elif dataclasses.is_dataclass(value):
        items = to_dict(value).values()
    elif isinstance(value, float):
        return math.isfinite(value)
    elif isinstance(value, (list, tuple)):  # subclasses, which orjson serialises too
        items = value
    elif isinstance(value, dict):
        items = value.values()
    else:
        return True
    for v in items:
        tv = type(v)
        if tv is float:
            if v - v != 0.0:
                return False
        elif tv not in _LEAVES and not _finite(v):
            return False
    return True


@functools.cache  # once a process (a payload class's type hints cost ~1 ms a topic a run)
def _schema_record(cls: type) -> tuple[str, bytes]:
    """(title, JSON schema bytes) of a payload dataclass."""
    schema = json_schema(cls)
    return schema["title"], json.dumps(schema, separators=(",", ":")).encode()


def _topic_schema(topic: str) -> tuple[str, bytes]:
    """(title, JSON schema bytes) of a topic of plain dicts."""
    return topic, json.dumps({"title": topic, "type": "object"}, separators=(",", ":")).encode()


def seconds_to_ns(t: float) -> int:
    return int(round(t * 1e9))


class _FlushedFile:
    """A file whose writes reach the OS at each seek, so a killed run keeps its last chunk: the
    log's writer seeks back to a chunk's header when the chunk is done, and forward again after
    filling in its lengths, so every finished chunk is in the file then (the message indexes
    after it follow with the next chunk). Flushing every write instead (~2,700 a simulated
    second of a catch run) cost 7-10 % of its CPU."""

    def __init__(self, f) -> None:
        self._f = f

    def write(self, data) -> int:
        return self._f.write(data)

    def seek(self, offset: int, whence: int = 0) -> int:
        self._f.flush()
        return self._f.seek(offset, whence)

    def flush(self) -> None:
        self._f.flush()

    def tell(self) -> int:
        return self._f.tell()

    def fileno(self) -> int:
        return self._f.fileno()

    def close(self) -> None:
        self._f.close()


class _Sink:
    """What the SDK's writer writes to: the file, keeping the first ``OSError`` of a write.
    The SDK reports a failed write of a file-like sink only as a logged line (and refuses every
    write after it), so :class:`LogWriter` looks at ``error`` after each call and raises it."""

    def __init__(self, f: _FlushedFile) -> None:
        self.file = f
        self.error: OSError | None = None
        self.pos = f.tell()  # where the next write goes: the SDK asks after nearly every write
        # (seek(0, SEEK_CUR), ~1650 a catch run), answered from here without a system call

    def _keep(self, exc: OSError) -> None:
        if self.error is None:
            self.error = exc

    def write(self, data) -> int:
        try:
            self.file.write(data)  # (a buffered file's write takes it all or raises)
        except OSError as exc:
            self._keep(exc)
            raise
        n = len(data)
        self.pos += n
        return n

    def seek(self, offset: int, whence: int = 0) -> int:
        if whence == os.SEEK_CUR and offset == 0:
            return self.pos
        try:
            self.pos = self.file.seek(offset, whence)
        except OSError as exc:
            self._keep(exc)
            raise
        return self.pos

    def flush(self) -> None:
        try:
            self.file.flush()
        except OSError as exc:
            self._keep(exc)
            raise


class _FailedWriteLine(logging.Filter):
    """Drops foxglove-sdk's own warning about a failed write ("error logging message: ..."):
    :class:`LogWriter` raises that error itself, as one clean line."""

    def filter(self, record: logging.LogRecord) -> bool:
        return not record.getMessage().startswith("error logging message")


logging.getLogger("foxglove.log_sink_set").addFilter(_FailedWriteLine())


class LogWriter:
    """``with LogWriter(path) as log: log.write("/events", Event(...), t_ns)``.

    JSON channels (with a JSON schema from the payload's dataclass) are made on a topic's first
    :meth:`write`. Channels of any other encoding (e.g. Foxglove's protobuf schemas):
    ``schema = log.register_schema(name, "protobuf", descriptor_bytes)``, ``channel =
    log.register_channel(topic, "protobuf", schema)``, then ``log.write_raw(channel, data,
    t_ns)`` with the message's encoded bytes, under the same safe-write guarantees.
    """

    def __init__(
        self, path: str | os.PathLike, *, chunk_size: int = 256 * 1024, compression: str = "zstd"
    ) -> None:
        if compression not in ("zstd", "none"):
            raise LogError(f"log compression {compression!r}: zstd or none")
        self.path = Path(path)
        check_output(self.path)
        self.part_path, part, self._found = open_part(self.path)
        self._file = _FlushedFile(part)
        self._sink = _Sink(self._file)
        self._held = HeldSigint()
        self._held.install()
        self._context = foxglove.Context()  # (this log's channels only)
        with self._held:
            try:
                self._mcap = mcap_writer(
                    self._sink,
                    self._context,
                    chunk_size=chunk_size,
                    compression="" if compression == "none" else "zstd",
                )
            except RuntimeError as exc:
                raise self.write_error(exc) from None
        if self._sink.error is not None:
            raise self.write_error()
        self._json_channels: dict[str, int] = {}  # topic -> channel id
        self._topics: set[str] = set()  # every channel's topic
        self._schemas: list[foxglove.Schema | None] = [None]  # by schema id (0: none)
        self._log: list = [None]  # by channel id: its channel's ``log``
        self._count = 0
        self.closed = False

    @property
    def count(self) -> int:
        """Messages written so far."""
        return self._count

    def register_schema(self, name: str, encoding: str, data: bytes) -> int:
        """A schema (``encoding``: ``jsonschema``, ``protobuf`` (a FileDescriptorSet), ...) for
        channels to name; returns its id (> 0). It is written with the first message of a
        channel naming it, once however many do."""
        self._schemas.append(foxglove.Schema(name=name, encoding=encoding, data=bytes(data)))
        return len(self._schemas) - 1

    def register_channel(
        self,
        topic: str,
        message_encoding: str,
        schema_id: int = 0,
        metadata: dict[str, str] | None = None,
    ) -> int:
        """A channel on ``topic`` whose messages are ``message_encoding`` (``json``,
        ``protobuf``, ...) bytes of schema ``schema_id`` (0: none); returns its id for
        :meth:`write_raw`. A topic has one channel; it is written with its first message."""
        if topic in self._topics:
            raise LogError(f"log {self.path}: topic {topic} already has a channel")
        # The Rust channel itself (BaseChannel, what foxglove.Channel wraps for a context): the
        # wrapper keeps every channel it makes in a module-level dict for good (~48 KB a log of
        # 40 channels never freed: a sweep's worker writing thousands of logs), and its log()
        # checks for a str, a dict or a list each message (~0.4 of its ~0.9 us).
        channel = self._context._create_channel(
            topic,
            message_encoding=message_encoding,
            schema=self._schemas[schema_id],
            metadata=dict(metadata or {}),
        )
        self._topics.add(topic)
        self._log.append(channel.log)
        return len(self._log) - 1

    def _json_channel(self, topic: str, payload: Any) -> int:
        cls = TOPICS.get(topic) or (None if isinstance(payload, dict) else type(payload))
        title, data = _schema_record(cls) if cls is not None else _topic_schema(topic)
        schema_id = self.register_schema(title, "jsonschema", data)
        channel = self._json_channels[topic] = self.register_channel(topic, "json", schema_id)
        return channel

    def write(self, topic: str, payload: Any, t_ns: int) -> None:
        """Write one message; ``t_ns`` (simulated time) is both log and publish time. A payload
        with a non-finite number is refused (:class:`NonFiniteValueError`) before anything is
        written."""
        data = encode(topic, payload)
        channel = self._json_channels.get(topic) or self._json_channel(topic, payload)
        self.write_raw(channel, data, t_ns)

    def write_all(self, messages: dict[str, Any], t_ns: int) -> None:
        """:meth:`write` of each (topic, payload) of ``messages`` in its order, a list payload
        being its items' messages (a plant's state, a controller's telemetry)."""
        write = self.write
        for topic, payload in messages.items():
            if isinstance(payload, list):
                for item in payload:
                    write(topic, item, t_ns)
            else:
                write(topic, payload, t_ns)

    def write_raw(self, channel_id: int, data: bytes, t_ns: int) -> None:
        """Write one message's encoded bytes on a channel of :meth:`register_channel` (sequence
        numbers 1, 2, ... on each channel): whole, a SIGINT arriving meanwhile (a finished chunk
        being written) raised after it."""
        held = self._held  # (its __enter__ / __exit__ inlined: this runs for every message)
        held.depth += 1
        try:
            self._log[channel_id](data, t_ns)
            if not self._count:  # the SDK writes the magic and header with the first message:
                self._sink.flush()  # in the file from then on, a killed run's .part a log
        except OSError:
            pass  # (kept by the sink: raised below)
        finally:
            held.depth -= 1
        if self._sink.error is not None:
            raise self.write_error()
        self._count += 1
        if held.pending and not held.depth:
            held.pending = False
            raise KeyboardInterrupt

    def write_error(self, exc: Exception | None = None) -> LogError:
        """The LogError of a failed write (after which the run stops: Ctrl-C is Python's
        again): the file's own ``OSError`` when there was one, else what the SDK said."""
        self._held.uninstall()
        error = self._sink.error
        if error is not None:
            return LogWriteError(
                f"cannot write log {self.part_path}: {error.strerror}", error.errno
            )
        return LogWriteError(f"cannot write log {self.part_path}: {exc}")

    def metadata(self, name: str, data: dict[str, str]) -> None:
        with self._held:
            try:
                self._mcap.write_metadata(name, {k: str(v) for k, v in data.items()})
            except RuntimeError as exc:
                raise self.write_error(exc) from None
        if self._sink.error is not None:
            raise self.write_error()

    def close(self, status: str = "") -> Path:
        """Finish the file (summary, index) and give it its final name (:func:`place`): ``path``
        for a finished run (replacing an old log only now), ``STEM.STATUS.mcap`` for a run that
        ended with ``status`` ("failed", "interrupted"). Returns where the log is."""
        if not self.closed:
            with self._held:
                try:
                    try:
                        self._mcap.close()
                    except RuntimeError as exc:  # (a write of _Sink's failed, or the SDK's own)
                        raise self._sink.error or OSError(None, str(exc)) from None
                    os.fsync(self._file.fileno())
                    final, conflict = place(self.part_path, self.path, self._found, status)
                    self._file.close()  # (the .part's lock held until it has its name)
                except OSError as exc:
                    raise LogWriteError(
                        f"cannot finish log {self.part_path}: {exc.strerror}", exc.errno
                    ) from None
                finally:
                    self._held.uninstall()
                self.closed = True
                self.path = final
            if conflict is not None:
                raise OutputConflictError(
                    f"another run wrote {conflict} while this one ran: not replaced; this "
                    f"run's finished log is kept as {final}"
                )
        return self.path

    def __enter__(self) -> "LogWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close(
            "" if exc[0] is None else "interrupted" if exc[0] is KeyboardInterrupt else "failed"
        )
