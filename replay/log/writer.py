"""Writing a run's MCAP log: JSON messages with JSON schemas, stamped with simulated time.

Crash safety:

- the file is written under ``NAME.part`` and renamed to ``NAME`` only when it is closed as a
  finished run, so an old log at ``NAME`` stays untouched until a new one is complete; a run
  closed as failed or interrupted is renamed ``STEM.failed.mcap`` / ``STEM.interrupted.mcap``
  instead, and a run killed mid-way leaves ``NAME.part``, readable up to its last chunk
  (``LogReader`` reads it);
- a record is written whole or not at all: Ctrl-C (SIGINT) arriving while a message or the
  summary is being written is held until that write is done, then raised;
- a log never overwrites a file that is not an MCAP log (a scenario, say) nor a folder.

Same messages in the same order give the same bytes.
"""

from __future__ import annotations

import json
import os
import signal
import tempfile
import threading
from pathlib import Path
from typing import Any

import orjson
from mcap.writer import CompressionType, Writer

from replay import __version__
from replay.log.errors import LogError, NonFiniteValueError
from replay.messages import TOPICS, json_schema, to_dict

PART_SUFFIX = ".part"
MAGIC = b"\x89MCAP0\r\n"
_ENCODER = json.JSONEncoder(allow_nan=False, separators=(",", ":"))  # built once: dumps() with
# options builds one a call
_ORJSON = orjson.OPT_NON_STR_KEYS  # keys as the standard encoder writes them


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

    def fileno(self) -> int:
        return self._f.fileno()

    def close(self) -> None:
        self._f.close()


class _HeldSigint:
    """While ``depth > 0`` (a record is being written) a SIGINT is held, then raised as
    ``KeyboardInterrupt`` when the write is done. Installed only from the main thread and only
    over Python's default handler (a host program's own handler is left alone)."""

    def __init__(self) -> None:
        self.depth = 0
        self.pending = False
        self.installed = False

    def _handler(self, signum, frame) -> None:
        if self.depth:
            self.pending = True
        else:
            raise KeyboardInterrupt

    def install(self) -> None:
        if (
            threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) is signal.default_int_handler
        ):
            signal.signal(signal.SIGINT, self._handler)
            self.installed = True

    def uninstall(self) -> None:
        if self.installed:
            signal.signal(signal.SIGINT, signal.default_int_handler)
            self.installed = False

    def __enter__(self) -> None:
        self.depth += 1

    def __exit__(self, *exc) -> None:
        self.depth -= 1
        if self.pending and not self.depth:
            self.pending = False
            if exc[0] is None:
                raise KeyboardInterrupt


def failed_path(path: Path, status: str) -> Path:
    """Where a log closed as ``status`` (failed, interrupted) is kept: ``STEM.STATUS.mcap``."""
    return path.with_name(f"{path.stem}.{status}{path.suffix or '.mcap'}")


def check_output(path: Path, *, kind: str = "log", magic: bytes | None = MAGIC) -> None:
    """Raise :class:`LogError` when ``path`` cannot take a log (or another ``kind`` of output):
    a folder, an existing file that does not start with ``magic``, a parent that is not a
    folder, cannot be made or takes no files."""
    if path.is_dir():
        raise LogError(f"cannot write {kind} {path}: it is a folder (give a file name)")
    if path.exists() and magic is not None:
        try:
            with open(path, "rb") as f:
                head = f.read(len(magic))
        except OSError as exc:
            raise LogError(f"cannot write {kind} {path}: {exc.strerror}") from None
        if head != magic and path.stat().st_size > 0:
            what = "an MCAP log" if magic == MAGIC else f"an earlier {kind} (JSON)"
            raise LogError(f"will not overwrite {path}: it is not {what}")
    parent = path.parent
    for p in (parent, *parent.parents):
        if p.exists():
            if not p.is_dir():
                raise LogError(f"cannot write {kind} {path}: {p} is a file, not a folder")
            break
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise LogError(
            f"cannot write {kind} {path}: cannot make folder {parent} ({exc.strerror})"
        ) from None
    try:
        tempfile.TemporaryFile(dir=parent).close()  # can a file be made there at all?
    except OSError as exc:
        raise LogError(
            f"cannot write {kind} {path}: folder {parent} takes no files ({exc.strerror})"
        ) from None


class LogWriter:
    """``with LogWriter(path) as log: log.write("/events", Event(...), t_ns)``."""

    def __init__(
        self, path: str | os.PathLike, *, chunk_size: int = 256 * 1024, compression: str = "zstd"
    ) -> None:
        self.path = Path(path)
        self.part_path = self.path.with_name(self.path.name + PART_SUFFIX)
        check_output(self.path)
        try:
            self._file = _FlushedFile(open(self.part_path, "wb"))
        except OSError as exc:
            raise LogError(f"cannot write log {self.part_path}: {exc.strerror}") from exc
        self._held = _HeldSigint()
        self._held.install()
        comp = {
            "zstd": CompressionType.ZSTD,
            "lz4": CompressionType.LZ4,
            "none": CompressionType.NONE,
        }[compression]
        self._writer = Writer(self._file, chunk_size=chunk_size, compression=comp)
        self._writer.start(profile="", library=f"paper-replay {__version__}")
        self._channels: dict[str, int] = {}
        self._sequence: dict[str, int] = {}
        self._schemas: dict[tuple[str, str], int] = {}  # (name, encoding) -> id, for raw channels
        self.count = 0
        self.closed = False

    def _channel(self, topic: str, payload: Any) -> int:
        if topic not in self._channels:
            cls = TOPICS.get(topic) or (None if isinstance(payload, dict) else type(payload))
            schema = json_schema(cls) if cls is not None else {"title": topic, "type": "object"}
            schema_id = self._writer.register_schema(
                name=schema["title"],
                encoding="jsonschema",
                data=json.dumps(schema, separators=(",", ":")).encode(),
            )
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding="json", schema_id=schema_id
            )
            self._sequence[topic] = 0
        return self._channels[topic]

    def write(self, topic: str, payload: Any, t_ns: int) -> None:
        """Write one message; ``t_ns`` (simulated time) is both log and publish time."""
        data = encode(topic, payload)
        with self._held:
            try:
                channel = self._channel(topic, payload)
                self._writer.add_message(
                    channel_id=channel,
                    log_time=t_ns,
                    publish_time=t_ns,
                    data=data,
                    sequence=self._sequence[topic],
                )
            except OSError as exc:
                raise LogError(f"cannot write log {self.part_path}: {exc.strerror}") from None
            self._sequence[topic] += 1
            self.count += 1

    def register_channel(
        self,
        topic: str,
        *,
        schema_name: str,
        schema_encoding: str,
        schema_data: bytes,
        message_encoding: str,
    ) -> None:
        """Declare a channel whose messages are not our JSON payloads (e.g. Foxglove's
        protobuf schemas); then :meth:`write_raw` writes its messages. A schema is stored
        once however many channels use it. Registering a topic twice is a no-op."""
        if topic in self._channels:
            return
        with self._held:
            key = (schema_name, schema_encoding)
            if key not in self._schemas:
                self._schemas[key] = self._writer.register_schema(
                    name=schema_name, encoding=schema_encoding, data=schema_data
                )
            self._channels[topic] = self._writer.register_channel(
                topic=topic, message_encoding=message_encoding, schema_id=self._schemas[key]
            )
            self._sequence[topic] = 0

    def write_raw(self, topic: str, data: bytes, t_ns: int) -> None:
        """Write one already-encoded message on a channel of :meth:`register_channel`."""
        with self._held:
            try:
                self._writer.add_message(
                    channel_id=self._channels[topic],
                    log_time=t_ns,
                    publish_time=t_ns,
                    data=data,
                    sequence=self._sequence[topic],
                )
            except OSError as exc:
                raise LogError(f"cannot write log {self.part_path}: {exc.strerror}") from None
            self._sequence[topic] += 1
            self.count += 1

    def metadata(self, name: str, data: dict[str, str]) -> None:
        with self._held:
            self._writer.add_metadata(name, {k: str(v) for k, v in data.items()})

    def close(self, status: str = "") -> Path:
        """Finish the file (summary, index) and give it its final name: ``path`` for a
        finished run (replacing an old log only now), ``STEM.STATUS.mcap`` for a run that
        ended with ``status`` ("failed", "interrupted"). Returns where the log is."""
        if not self.closed:
            final = failed_path(self.path, status) if status else self.path
            with self._held:
                try:
                    self._writer.finish()
                    os.fsync(self._file.fileno())
                    self._file.close()
                    os.replace(self.part_path, final)
                except OSError as exc:
                    raise LogError(f"cannot finish log {self.part_path}: {exc.strerror}") from None
                finally:
                    self._held.uninstall()
                self.closed = True
                self.path = final
        return self.path

    def __enter__(self) -> "LogWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close(
            "" if exc[0] is None else "interrupted" if exc[0] is KeyboardInterrupt else "failed"
        )
