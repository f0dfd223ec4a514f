"""Writing a run's MCAP log: JSON messages with JSON schemas, stamped with simulated time.

Crash safety:

- the file is written under a name of its own, ``NAME.PID.part`` (PID: the writing process),
  and renamed to ``NAME`` only when it is closed as a finished run, so an old log at ``NAME``
  stays untouched until a new one is complete; a run closed as failed or interrupted is renamed
  ``STEM.failed.mcap`` / ``STEM.interrupted.mcap`` instead, and a run killed mid-way leaves its
  ``.part``, readable up to its last chunk (``LogReader`` reads it);
- one writer per output: a ``.part`` is locked (``flock``) while its run lives, and a second run
  onto the same ``NAME`` is refused before it starts, naming the first one's process; a finished
  log replaces ``NAME`` only if no other log got there after this run started (else it is kept as
  ``STEM.conflict-PID.mcap`` and :class:`OutputConflictError` says so);
- a record is written whole or not at all: Ctrl-C (SIGINT) arriving while a message or the
  summary is being written is held until that write is done, then raised;
- a log never overwrites a file that is not an MCAP log (a scenario, say), an empty file, a
  folder, nor anything that is not a regular file (a device, a FIFO, a socket).

- a failed write (a full disk, an I/O error) raises :class:`LogWriteError` from the call that
  made it (the MCAP writer, foxglove-sdk's, would only log it: ``_Sink`` keeps the ``OSError``
  and every call looks), and the run's ``.part`` is then left to the caller.

Same messages in the same order give the same bytes. The file's records are foxglove-sdk's
(:mod:`replay.log.chunks`): each channel's messages are numbered 1, 2, ...; a schema and a
channel are written with the channel's first message.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import glob
import json
import logging
import math
import os
import signal
import stat
import tempfile
import threading
from pathlib import Path
from typing import Any

import orjson

try:
    import fcntl
except ImportError:  # (Windows: no flock; one writer per output is then up to the user)
    fcntl = None  # type: ignore[assignment]

import foxglove

from replay.log.chunks import MAGIC, mcap_writer
from replay.log.errors import LogError, NonFiniteValueError
from replay.messages import TOPICS, json_schema, to_dict

PART_SUFFIX = ".part"
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


def _what(mode: int) -> str | None:
    """What a file that is neither a regular file nor a folder is, or None."""
    for test, name in (
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return name
    return None if stat.S_ISREG(mode) or stat.S_ISDIR(mode) else "not a regular file"


def check_output(path: Path, *, kind: str = "log", magic: bytes | None = MAGIC) -> None:
    """Raise :class:`LogError` when ``path`` cannot take a log (or another ``kind`` of output):
    a folder, anything but a regular file (a device, a FIFO, a socket: checked without opening
    it, which would block on a FIFO), a symbolic link (dangling or not: an output is never
    written through one), an existing file that does not start with ``magic`` or is empty, a
    parent that is not a folder, cannot be made or takes no files. The output itself is then
    written beside ``path`` and renamed onto it (:func:`write_output`, ``LogWriter``), which
    never follows a link planted after this check."""
    link = os.path.islink(path)
    try:
        st = os.stat(path)
    except (FileNotFoundError, NotADirectoryError):
        st = None  # (a parent that is a file: said below)
    except OSError as exc:
        if not link:  # (a link's loop: said below)
            raise LogError(f"cannot write {kind} {path}: {exc.strerror}") from None
        st = None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise LogError(f"cannot write {kind} {path}: it is a folder (give a file name)")
    if st is not None and _what(st.st_mode):
        raise LogError(
            f"will not write {kind} {path}: it is {_what(st.st_mode)}, not a regular file"
        )
    if link:
        raise LogError(
            f"will not write {kind} {path} through a symbolic link (to {os.readlink(path)}); "
            "remove the link or give another path"
        )
    if st is not None and magic is not None:
        what = "an MCAP log" if magic == MAGIC else f"an earlier {kind} (a file starting {magic!r})"
        if st.st_size == 0:
            raise LogError(f"will not overwrite {path}: it is an empty file, not {what}")
        try:
            with open(path, "rb") as f:
                head = f.read(len(magic))
        except OSError as exc:
            raise LogError(f"cannot write {kind} {path}: {exc.strerror}") from None
        if head != magic:
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


def write_output(path: Path, write, *, mode: int = 0o644) -> None:
    """``write(tmp)`` makes the output in a new file of its own beside ``path`` (``tmp``, a
    path), which then replaces ``path`` whole: never a write through a link or into a file
    this command did not make (a hard link, one planted after :func:`check_output`); nothing
    left behind when ``write`` raises."""
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    os.close(fd)
    try:
        write(Path(tmp))
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def _identity(path: Path) -> tuple[int, int, int, int] | None:
    """What is at ``path`` (device, inode, size, mtime), None when nothing: a log that another
    run put there changes it."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino, st.st_size, st.st_mtime_ns


@contextlib.contextmanager
def _folder_lock(folder: Path):
    """The folder ``flock``-ed for a moment, so that looking for other writers and making a
    ``.part``, or checking the target and replacing it, is one step among runs (no-op where
    ``fcntl`` is missing)."""
    if fcntl is None:
        yield
        return
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:
        yield
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)  # (releases the lock)


def _locked(path: Path) -> bool:
    """Whether another live process holds ``path`` (a ``.part``) locked."""
    if fcntl is None:
        return False
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_SH | fcntl.LOCK_NB)
    except OSError:
        return True
    finally:
        os.close(fd)
    return False


def part_paths(path: Path) -> list[Path]:
    """The ``.part`` files of runs onto ``path`` (live or killed), oldest first."""
    found = path.parent.glob(f"{glob.escape(path.name)}.*{PART_SUFFIX}")
    return sorted((p for p in found if p.is_file()), key=lambda p: p.stat().st_mtime_ns)


def part_pid(part: Path, path: Path) -> str:
    """The process that made ``part`` (``NAME.PID.part`` or ``NAME.PID-N.part``) onto ``path``."""
    return part.name[len(path.name) + 1 : -len(PART_SUFFIX)].split("-")[0]


def live_writers(path: Path) -> list[Path]:
    """The ``.part`` files of runs still writing ``path`` (locked by a live process)."""
    return [p for p in part_paths(path) if _locked(p)]


class LogWriteError(LogError):
    """Writing or finishing a log failed (a full disk, an I/O error): a system fault, not bad
    input; ``errno`` says which."""

    def __init__(self, message: str, errno: int | None = None) -> None:
        super().__init__(message)
        self.errno = errno


def own_part(path: Path) -> Path | None:
    """The newest ``.part`` of this process onto ``path`` (what a failed run leaves)."""
    mine = [p for p in part_paths(path) if part_pid(p, path) == str(os.getpid())]
    return mine[-1] if mine else None


class OutputConflictError(LogError):
    """Another run finished a log at the same path while this one ran: this one kept aside."""


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
        self.part_path, self._file, self._found = self._open_part(self.path)
        self._sink = _Sink(self._file)
        self._held = _HeldSigint()
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

    @staticmethod
    def _open_part(path: Path) -> tuple[Path, _FlushedFile, tuple | None]:
        """This run's own ``NAME.PID.part``, made and locked while no other live run writes
        ``path`` (else :class:`LogError` naming it), and what was at ``path`` then."""
        with _folder_lock(path.parent):
            others = live_writers(path)
            if others:
                pid = part_pid(others[0], path)
                raise LogError(
                    f"will not write log {path}: another run (process {pid}) is writing it "
                    f"({others[0].name}); wait for it or give another -o"
                )
            found = _identity(path)
            for n in range(1000):
                tag = f"{os.getpid()}" + (f"-{n}" if n else "")
                part = path.with_name(f"{path.name}.{tag}{PART_SUFFIX}")
                try:
                    fd = os.open(part, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
                except FileExistsError:
                    continue  # a killed run's .part of a recycled pid: kept
                except OSError as exc:
                    raise LogWriteError(
                        f"cannot write log {part}: {exc.strerror}", exc.errno
                    ) from None
                break
            else:
                raise LogError(f"cannot write log {path}: 1000 .part files of this pid")
            if fcntl is not None:
                fcntl.flock(fd, fcntl.LOCK_EX)  # (made under the folder's lock: free)
        return part, _FlushedFile(os.fdopen(fd, "wb")), found

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
        """Finish the file (summary, index) and give it its final name: ``path`` for a
        finished run (replacing an old log only now), ``STEM.STATUS.mcap`` for a run that
        ended with ``status`` ("failed", "interrupted"). Returns where the log is."""
        if not self.closed:
            final = failed_path(self.path, status) if status else self.path
            conflict = None
            with self._held:
                try:
                    try:
                        self._mcap.close()
                    except RuntimeError as exc:  # (a write of _Sink's failed, or the SDK's own)
                        raise self._sink.error or OSError(None, str(exc)) from None
                    os.fsync(self._file.fileno())
                    with _folder_lock(final.parent):
                        if final == self.path and _identity(final) != self._found:
                            conflict = final  # another log got there after this run started
                            final = failed_path(self.path, f"conflict-{os.getpid()}")
                        os.replace(self.part_path, final)
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
