"""Where a log (or another output) is written, and how, so that nothing is lost or clobbered.

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
"""

from __future__ import annotations

import contextlib
import glob
import os
import signal
import stat
import tempfile
import threading
from pathlib import Path
from typing import BinaryIO

try:
    import fcntl
except ImportError:  # (Windows: no flock; one writer per output is then up to the user)
    fcntl = None  # type: ignore[assignment]

from replay.log.chunks import MAGIC
from replay.log.errors import LogError, LogWriteError

PART_SUFFIX = ".part"


class HeldSigint:
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


def own_part(path: Path) -> Path | None:
    """The newest ``.part`` of this process onto ``path`` (what a failed run leaves)."""
    mine = [p for p in part_paths(path) if part_pid(p, path) == str(os.getpid())]
    return mine[-1] if mine else None


class OutputConflictError(LogError):
    """Another run finished a log at the same path while this one ran: this one kept aside."""


def open_part(path: Path) -> tuple[Path, BinaryIO, tuple | None]:
    """This run's own ``NAME.PID.part`` (its path and open file), made and locked while no
    other live run writes ``path`` (else :class:`LogError` naming it), and what was at ``path``
    then (for :func:`place`)."""
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
                raise LogWriteError(f"cannot write log {part}: {exc.strerror}", exc.errno) from None
            break
        else:
            raise LogError(f"cannot write log {path}: 1000 .part files of this pid")
        if fcntl is not None:
            fcntl.flock(fd, fcntl.LOCK_EX)  # (made under the folder's lock: free)
    return part, os.fdopen(fd, "wb"), found


def place(part: Path, path: Path, found: tuple | None, status: str) -> tuple[Path, Path | None]:
    """Rename a finished ``part`` (fsync-ed) to its final name: ``path``, or ``STEM.STATUS.mcap``
    for a run that ended with ``status``; a finished log is kept as ``STEM.conflict-PID.mcap``
    when another log got to ``path`` after ``found`` was seen. Returns (where it is, the path
    it did not replace or None)."""
    final = failed_path(path, status) if status else path
    with _folder_lock(final.parent):
        if final == path and _identity(final) != found:
            conflict = final  # another log got there after this run started
            return _replace(part, failed_path(path, f"conflict-{os.getpid()}")), conflict
        return _replace(part, final), None


def _replace(part: Path, final: Path) -> Path:
    os.replace(part, final)
    return final
