"""The code a run ran: the package version and its git commit. From a checkout (an editable
install) the commit is read from git live; from a wheel, from ``replay/_build_info.py``, which
setup.py writes into the build when a wheel is built from a checkout (never into the checkout).
A wheel built from sources without git (a copied tree) says ``unknown``. Plain Python: setup.py
loads this file by its path."""

from __future__ import annotations

import functools
import hashlib
import subprocess
from pathlib import Path

HOME = Path(__file__).resolve().parent.parent  # the checkout, or site-packages


def _git(*args: str, timeout: float = 10) -> subprocess.CompletedProcess | None:
    try:
        return subprocess.run(["git", *args], capture_output=True, timeout=timeout, cwd=HOME)
    except (OSError, subprocess.SubprocessError):
        return None


def _built() -> tuple[str, str] | None:
    """(commit, diff digest) the build recorded, or None when not built (a checkout)."""
    try:
        from replay import _build_info  # type: ignore[attr-defined]
    except ImportError:
        return None
    return str(_build_info.COMMIT), str(_build_info.DIFF)


def git_state(root: Path = HOME, *, diff: bool = True) -> tuple[str, str]:
    """(12-digit commit, 8-digit digest of uncommitted changes or "") of the checkout whose top
    is ``root``, read from git; ("", "") when ``root`` is none (no git, or a folder inside some
    other repository, e.g. a venv in a user's project). setup.py records this in a wheel."""
    top = _git("-C", str(root), "rev-parse", "--show-toplevel")
    if top is None or top.returncode != 0 or Path(top.stdout.decode().strip()) != root.resolve():
        return "", ""
    commit = _git("-C", str(root), "rev-parse", "--short=12", "HEAD")
    if commit is None or commit.returncode != 0:
        return "", ""
    if not diff:
        return commit.stdout.decode().strip(), ""
    changes = _git("-C", str(root), "diff", "HEAD", "--", ".", ":(exclude)*.csv", timeout=30)
    digest = ""
    if changes is not None and changes.returncode == 0 and changes.stdout:
        digest = hashlib.sha256(changes.stdout).hexdigest()[:8]
    return commit.stdout.decode().strip(), digest


@functools.cache  # once a process: the code a process runs is the code it loaded
def commit() -> str:
    """The 12-digit git commit of this code, or "" when unknown."""
    built = _built()
    return built[0] if built is not None else git_state(diff=False)[0]


def code_version() -> str:
    """Package version, git commit and a digest of uncommitted changes (so an edit re-runs a
    sweep's variants): ``0.1.0+1a2b3c4d5e6f.0badf00d``; ``0.1.0+unknown`` without a commit."""
    from replay import __version__  # (here: setup.py loads this file alone, replay unimported)

    sha, digest = _built() or git_state()
    return f"{__version__}+{sha or 'unknown'}" + (f".{digest}" if digest else "")
