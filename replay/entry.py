"""The ``replay`` executable: Ctrl-C at any moment exits 130 quietly, even while Python is still
importing the command line (numpy, PyBullet, ... take a while); a command line that cannot load
(an address-space limit, ``ulimit -v``, too low for the libraries) is one ``error:`` line, exit 1."""

import os
import signal
import sys


def _while_importing(signum, frame) -> None:
    sys.stderr.write("interrupted\n")
    sys.stderr.flush()
    os._exit(130)  # nothing is written yet: nothing to keep


def _address_space_limit() -> int | None:
    """The soft RLIMIT_AS in bytes, None when there is none."""
    try:
        import resource
    except ImportError:  # (Windows)
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_AS)
    return None if soft == resource.RLIM_INFINITY else soft


def _caused_by(exc: BaseException, kind: type[BaseException]) -> bool:
    """Whether ``exc`` is or came of a ``kind`` (through its causes and contexts)."""
    seen: BaseException | None = exc
    while seen is not None:
        if isinstance(seen, kind):
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def _by_ctrl_c(exc: BaseException) -> bool:
    """Whether ``exc`` came of a Ctrl-C: a C extension whose initialisation the KeyboardInterrupt
    broke raises ImportError from it (pybind11: "initialization failed")."""
    return _caused_by(exc, KeyboardInterrupt)


def _cannot_load(exc: BaseException, limit: int | None) -> None:
    if _by_ctrl_c(exc):
        _while_importing(signal.SIGINT, None)
    text = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
    why = f"{type(exc).__name__}: {text}"
    if limit is not None:
        why += (
            f"; the address-space limit (ulimit -v) is {limit >> 20} MB, too little for "
            "NumPy, OpenCV and PyBullet: raise it"
        )
    sys.stderr.write(f"error: paper-replay cannot load: {why}\n")
    sys.stderr.flush()
    os._exit(1)


def main() -> None:
    signal.signal(signal.SIGINT, _while_importing)
    from replay.top_level import guard

    guard()  # plants and analysis: the installed ones (replay/top_level.py)
    limit = _address_space_limit()
    if limit is not None:
        # each OpenBLAS thread reserves its buffers at import: under a limit (ulimit -v) one
        # thread, else the import fails (500 MB on 2 cores) or crashes in C (400 MB)
        os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    try:
        from replay.cli import main as cli
    except (ImportError, MemoryError, OSError) as exc:
        _cannot_load(exc, limit)
    except RuntimeError as exc:  # a Rust extension (foxglove-sdk) out of memory at import
        # raises RuntimeError from the MemoryError ("error occurred while initializing class")
        if not _caused_by(exc, MemoryError):
            raise
        _cannot_load(exc, limit)

    signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        cli()
    except (ImportError, MemoryError) as exc:  # a plug-in's libraries, loaded by the command
        _cannot_load(exc, limit)


if __name__ == "__main__":
    main()
