"""One sweep per folder: ``DIR/sweep.lock``, ``flock``-ed while a sweep uses ``DIR``.

The lock is held by an open file, so it dies with the sweep whatever kills it (no stale lock to
clear by hand), and the sweep's forked workers share it: a rerun is refused as long as any
process of the old sweep still runs, so it never races a survivor for the same logs and rows.
The file says who holds it (process, command, start time) for the refusal's one line. A sweep
that ends removes it (its workers stopped first); one killed leaves it, unlocked, for the next.
A sweep that locked a file another one removed meanwhile (opened before that one's end) sees
that its name is no longer that file, and opens the name again.
"""

from __future__ import annotations

import contextlib
import os
import stat
import sys
import time
from pathlib import Path

try:
    import fcntl
except ImportError:  # (Windows: no flock; one sweep per folder is then up to the user)
    fcntl = None  # type: ignore[assignment]

LOCK = "sweep.lock"
_ATTEMPTS = 8  # opens of the lock's name, each file removed by the sweep that held it


class SweepOutputError(Exception):
    """The sweep's folder cannot be used (in use by another sweep, not writable); ``code`` is
    the exit code (2: the folder given is unusable, 1: a system fault such as a full disk)."""

    def __init__(self, message: str, code: int = 2) -> None:
        super().__init__(message)
        self.code = code


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:
        return True
    return True


class FolderLock:
    """``with FolderLock(out_dir): ...``: the folder is this sweep's, or SweepOutputError."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.path = folder / LOCK
        self._fd: int | None = None

    def __enter__(self) -> "FolderLock":
        for _ in range(_ATTEMPTS):
            fd = self._lock()
            if self._named(fd):
                break
            os.close(fd)  # (the file was removed by the sweep that held it: open the name again)
        else:
            raise SweepOutputError(f"sweep folder {self.folder}: its {LOCK} keeps being replaced")
        try:
            os.ftruncate(fd, 0)
            text = f"{os.getpid()}\n{time.time():.0f}\n{' '.join(sys.argv)}\n"
            os.write(fd, text.encode("utf-8", "replace"))
        except OSError:
            pass  # (who holds it is a courtesy; the lock is what counts)
        self._fd = fd
        return self

    def _named(self, fd: int) -> bool:
        """``fd`` is still the file at the lock's name."""
        try:
            st = os.stat(self.path, follow_symlinks=False)
        except OSError:
            return False
        mine = os.fstat(fd)
        return (st.st_dev, st.st_ino) == (mine.st_dev, mine.st_ino)

    def _lock(self) -> int:
        """The lock file opened and locked (SweepOutputError if it cannot be, or is held)."""
        # never through a link: a folder shipped with sweep.lock -> a file of yours would have
        # it truncated (O_NOFOLLOW: ELOOP); nor a FIFO, a device or a hard link's other name
        flags = os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_NONBLOCK", 0)
        try:
            fd = os.open(self.path, flags, 0o644)
        except OSError as exc:
            if os.path.islink(self.path):
                raise SweepOutputError(
                    f"will not use sweep folder {self.folder}: its {LOCK} is a symbolic link "
                    f"(to {os.readlink(self.path)}); remove it"
                ) from None
            raise SweepOutputError(
                f"cannot use sweep folder {self.folder}: {exc.strerror or exc}"
            ) from None
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_nlink != 1:
            os.close(fd)
            what = "has other names (hard links)" if stat.S_ISREG(st.st_mode) else "is no file"
            raise SweepOutputError(
                f"will not use sweep folder {self.folder}: its {LOCK} {what}; remove it"
            )
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError:
                holder = self._holder(fd)
                os.close(fd)
                raise SweepOutputError(
                    f"sweep folder {self.folder} is in use by {holder}; wait for it to end or "
                    "give another -o"
                ) from None
        return fd

    @staticmethod
    def _holder(fd: int) -> str:
        try:
            text = os.pread(fd, 4096, 0).decode("utf-8", "replace").splitlines()
            pid = int(text[0])
            since = time.strftime("%H:%M:%S", time.localtime(float(text[1])))
            command = text[2] if len(text) > 2 else ""
        except (OSError, ValueError, IndexError):
            return "another sweep"
        who = f"sweep process {pid} ({command}, since {since})"
        if not _alive(pid):  # its workers outlived it: they hold the lock until they end
            who += ", dead, whose workers still run"
        return who

    def __exit__(self, *exc) -> None:
        if self._fd is not None:
            if self._named(self._fd):  # (removed while held: a sweep that opens it next
                with contextlib.suppress(OSError):  # sees the name is no longer its file)
                    os.unlink(self.path)
            os.close(self._fd)  # (the lock goes when the workers, which share it, are gone)
            self._fd = None
