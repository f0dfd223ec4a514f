"""What the command line says and where: results on stdout; errors, warnings, notes and progress
on stderr, each message one line with one prefix (``error:``, ``warning:``, ``note:``).

Progress bars are tqdm's (rate and ETA), drawn only when stderr is a terminal and not ``--quiet``,
and redrawn at most every :data:`REDRAW` seconds of wall time, so a fast run pays one clock read
per runner callback and nothing more.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import sys
import time
import warnings
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any, NoReturn

import click

from replay.scenario.yamlio import one_line

if TYPE_CHECKING:
    from replay.log import LogReader

REDRAW = 0.1  # s of wall time between redraws of a bar

# what a character becomes on a terminal whose encoding lacks it (latin-1, ASCII): the units and
# symbols the papers' tables and the summaries print, else "?"
FALLBACK = {
    "…": "...",
    "ω": "w",
    "θ": "theta",
    "α": "alpha",
    "β": "beta",
    "γ": "gamma",
    "δ": "delta",
    "Δ": "D",
    "μ": "u",
    "π": "pi",
    "σ": "sigma",
    "τ": "tau",
    "φ": "phi",
    "ψ": "psi",
    "λ": "lambda",
    "ε": "eps",
    "ρ": "rho",
    "η": "eta",
    "ζ": "zeta",
    "ν": "nu",
    "κ": "kappa",
    "χ": "chi",
    "Ω": "Ohm",
    "°": " deg",
    "±": "+/-",
    "×": "x",
    "·": ".",
    "−": "-",
    "–": "-",
    "—": "--",
    "≤": "<=",
    "≥": ">=",
    "≈": "~",
    "≠": "!=",
    "→": "->",
    "←": "<-",
    "²": "^2",
    "³": "^3",
    "½": "1/2",
    "√": "sqrt",
    "✓": "ok",
    "✗": "x",
    "‘": "'",
    "’": "'",
    "“": '"',
    "”": '"',
}
_ERRORS = "replay-fallback"


def _fallback(exc: UnicodeError) -> tuple[str, int]:
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    text = exc.object[exc.start : exc.end]
    out = "".join(FALLBACK.get(ch, "?") for ch in text)
    try:
        out.encode(exc.encoding)
    except (UnicodeEncodeError, LookupError):
        out = "?" * len(text)
    return out, exc.end


codecs.register_error(_ERRORS, _fallback)


def printable_streams() -> None:
    """stdout and stderr print in any terminal encoding: a character it cannot encode becomes
    its :data:`FALLBACK` (ω -> w, … -> ...) or ``?``, instead of a UnicodeEncodeError."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is None or getattr(stream, "errors", None) in (_ERRORS, "surrogateescape"):
            continue
        try:
            reconfigure(errors=_ERRORS)
        except (ValueError, OSError):  # (a stream that cannot be reconfigured: left alone)
            pass


def fail(message: str, code: int = 2) -> NoReturn:
    """A user error (bad input, a file that cannot be written): one line, exit ``code``."""
    click.echo(f"error: {one_line(message)}", err=True)
    sys.exit(code)


def say(text: str) -> None:
    """A result on stdout, each of its lines with control characters escaped (``one_line``): a
    name or path read from a log never moves the cursor, clears the screen or sets a title."""
    click.echo("\n".join(one_line(line) for line in str(text).split("\n")))


def warn(message: str) -> None:
    click.echo(f"warning: {one_line(message)}", err=True)


def note(message: str) -> None:
    click.echo(f"note: {one_line(message)}", err=True)


@contextlib.contextmanager
def quoted_warnings():
    """Python warnings raised meanwhile (matplotlib's "Glyph 27 (\\x1b) missing" for a title
    quoting a log's name) said once each by :func:`warn`, their control characters escaped."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        yield  # (an error raised: only its own line is said)
    for text in dict.fromkeys(f"{w.category.__name__}: {w.message}" for w in caught):
        warn(text)


def bars_on(quiet: bool = False, stream: IO | None = None) -> bool:
    """Whether to draw progress: a terminal on stderr and no ``--quiet``."""
    stream = sys.stderr if stream is None else stream
    return not quiet and bool(getattr(stream, "isatty", lambda: False)())


def bar(total: float, desc: str, *, unit: str, enabled: bool, stream: IO | None = None, **kw: Any):
    """A tqdm bar on stderr (disabled: a no-op bar), cleared when closed."""
    from tqdm import tqdm

    options: dict[str, Any] = {
        "file": sys.stderr if stream is None else stream,
        "disable": not enabled,
        "leave": False,
        "dynamic_ncols": True,
        "mininterval": REDRAW,
    }
    return tqdm(total=total, desc=desc, unit=unit, **{**options, **kw})


class RunProgress:
    """The runner's ``progress(t, duration)`` hook as a bar of simulated seconds with the ETA and
    the real-time factor (simulated s per wall s). Off unless ``enabled``; redrawn at
    most every :data:`REDRAW` s of wall time."""

    # tqdm's own rate would read "13.9s/s" for 13.9 wall s per simulated s (it inverts rates
    # below 1): the real-time factor is written out instead
    FORMAT = "{desc}: {percentage:3.0f}%|{bar}| t = {n:.3f}/{total:.3f} s [{elapsed}<{remaining}{postfix}]"

    def __init__(self, label: str, enabled: bool, stream: IO | None = None) -> None:
        self.label = label
        self.enabled = enabled
        self.stream = stream
        self._bar: Any = None
        self._next = 0.0
        self._start = (0.0, 0.0)  # (t, wall clock) at the first call
        self.redraws = 0

    def __call__(self, t: float, duration: float) -> None:
        if not self.enabled:
            return
        now = time.monotonic()
        if now < self._next:
            return
        self._next = now + REDRAW
        if self._bar is None:
            self._bar = bar(
                duration,
                self.label,
                unit="s",
                enabled=True,
                stream=self.stream,
                bar_format=self.FORMAT,
                mininterval=0,  # throttled here, on wall time
                miniters=0,  # every call redraws (tqdm's dynamic miniters assume whole items)
                smoothing=0,  # the run's mean real-time factor, so a steady ETA
                initial=min(t, duration),  # the rate counts from here
            )
            self._start = (t, now)
        else:
            t0, wall0 = self._start
            self._bar.set_postfix_str(f"{(t - t0) / (now - wall0):.3g}x real time", refresh=False)
            self._bar.update(min(t, duration) - self._bar.n)
        self.redraws += 1

    def done(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


# -- files the commands read and write, their failures one line ------------------------------
def read_log(path: str | Path) -> LogReader:
    """A checked :class:`~replay.log.LogReader` of ``path``, or the one-line error."""
    from replay.log import LogError, LogReader

    try:
        return LogReader(path).check()
    except LogError as exc:
        fail(str(exc))


def write_text(path: Path, text: str, *, kind: str, magic: bytes) -> None:
    """Write ``text`` to ``path`` (mode 0644, whole: :func:`replay.log.output.write_output`);
    never over a scenario, a log or a file that is not an earlier output of this ``kind`` (one
    that starts with ``magic``)."""
    from replay.log import LogError
    from replay.log.output import check_output, write_output

    if path.suffix in (".yaml", ".yml", ".mcap"):
        fail(f"will not write the {kind} over {path} (a scenario or a log): give another -o")
    try:
        check_output(path, kind=kind, magic=magic)
        write_output(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
    except LogError as exc:
        fail(str(exc))
    except OSError as exc:
        fail(f"cannot write {path}: {exc.strerror or exc}", code=exit_code(exc))


def exit_code(exc: OSError) -> int:
    """Exit code of a failed write: 1 for the disk (full, I/O error), 2 for the place given."""
    return 1 if exc.errno in (errno.ENOSPC, errno.EDQUOT, errno.EIO) else 2
