"""The report's folder: ``replay report -o DIR`` replaces DIR whole, so it must be a folder the
report made (its :data:`MARKER` file inside), an empty one or a new one; never the logs it reads,
a folder holding them, the working folder or one of its parents, nor anything else.

The report is built in a fresh sibling folder and swapped in once complete: a failed build leaves
the earlier report as it was.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

MARKER = ".paper-replay-report"
MARKER_TEXT = "made by `replay report`, which replaces this folder whole on its next run\n"


class ReportFolderError(ValueError):
    """The folder given to ``replay report -o`` is not one it may replace (one line)."""


def _marked(folder: Path) -> bool:
    """The report's marker in ``folder``: a regular file (not a link to one) of its text."""
    marker = folder / MARKER
    try:
        return (
            not marker.is_symlink()
            and marker.is_file()
            and marker.read_text(encoding="utf-8", errors="replace")[:200] == MARKER_TEXT
        )
    except OSError:
        return False


def _ours(folder: Path) -> bool:
    """A report's folder: its marker only (a folder that merely looks like a report, e.g. a
    copy of one's pages or one written before the marker existed, is not replaced)."""
    return _marked(folder)


def check_folder(out: Path, logs: Path) -> None:
    """:class:`ReportFolderError` saying why the report may not replace ``out``, if it may
    not; nothing is touched."""
    try:
        target = out.resolve()
        read = logs.resolve()
        cwd = Path.cwd().resolve()
    except (OSError, RuntimeError) as exc:
        raise ReportFolderError(f"cannot use report folder {out}: {exc}") from None
    if target == cwd or target in cwd.parents:
        raise ReportFolderError(
            f"will not write the report to {out}: it is the working folder or one of its "
            "parents (the report replaces its folder whole; give a folder of its own, e.g. "
            "out/report)"
        )
    if target == read or target in read.parents:
        raise ReportFolderError(
            f"will not write the report to {out}: it holds the logs it reads ({logs}); give "
            "another -o"
        )
    if out.is_symlink() or (target.exists() and not target.is_dir()):
        what = "a symbolic link" if out.is_symlink() else "a file"
        raise ReportFolderError(f"will not write the report to {out}: it is {what}, not a folder")
    if target.is_dir() and any(target.iterdir()) and not _ours(target):
        raise ReportFolderError(
            f"will not replace {out}: a folder that is not empty and was not made by "
            f"`replay report` (no {MARKER} in it); give a new or empty folder"
        )


def staging(target: Path) -> Path:
    """A new empty folder beside ``target`` to build the report in (its parents made)."""
    target.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".part", dir=target.parent))
    (work / MARKER).write_text(MARKER_TEXT, encoding="utf-8")
    return work


def swap_in(work: Path, target: Path) -> None:
    """Replace ``target`` (a folder :func:`check_folder` allowed, or nothing) by ``work``. What
    is removed is only a report (checked again here: the folder may have changed during the
    build) moved into a folder made for it."""
    old = None
    if target.exists() or target.is_symlink():
        if (
            target.is_symlink()
            or not target.is_dir()
            or (any(target.iterdir()) and not _ours(target))
        ):
            raise ReportFolderError(
                f"will not replace {target}: it changed during the build and is no report now"
            )
        old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
        target.rename(old / "report")
    work.rename(target)
    target.chmod(0o755)  # (mkdtemp made it 0700)
    if old is not None:  # (made just above by mkdtemp, holding only the old report)
        shutil.rmtree(old)


def discard(work: Path) -> None:
    """Remove a staging folder of :func:`staging` (its marker inside) after a failed build;
    anything else at that path is left alone."""
    made = work.name.startswith(".") and work.name.endswith(".part")  # (staging's mkdtemp name)
    if made and not work.is_symlink() and _marked(work):
        shutil.rmtree(work, ignore_errors=True)
