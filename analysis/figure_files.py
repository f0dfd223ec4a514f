"""Saving a figure as PNG and SVG so that the same log gives the same files, under a file name
that stays one harmless component of the output folder whatever the log names itself."""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
# text on a figure is plain: a run's name from a log ("a$\\frac{$b") is never parsed as mathtext
matplotlib.rcParams["text.parse_math"] = False
import matplotlib.pyplot as plt  # noqa: E402

from replay.log.output import check_output, write_output  # noqa: E402

# what an earlier figure starts with: the only file a figure overwrites
MAGIC = {".png": b"\x89PNG\r\n\x1a\n", ".svg": b"<?xml"}
STEM_LENGTH = 120  # characters of a figure's file stem (a scenario name is at most 100)
_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]")  # what a scenario name may hold (NAME_PATTERN)


def file_stem(text: str) -> str:
    """``text`` as one path component: only ``[A-Za-z0-9_.-]`` (no ``/``, ``\\``, control or
    NUL characters), no leading dot or dash, at most :data:`STEM_LENGTH` characters. A text
    that is already such a name is kept; any other gets a short hash of itself, so two logs
    whose names differ never share a file."""
    text = str(text)
    stem = _UNSAFE.sub("_", text).lstrip(".-")[:STEM_LENGTH]
    if stem == text and stem:
        return stem
    digest = hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()[:10]
    return f"{stem[: STEM_LENGTH - 11]}-{digest}" if stem else f"run-{digest}"


class FigureFile(type(Path())):  # type: ignore[misc]
    """A figure's file: a path that also says which runs it shows (their keys, analysis/runs.py),
    so the report captions each figure with its own runs. A figures plug-in may return bare
    paths too (the report then matches the file name to a run)."""

    runs: tuple[str, ...] = ()


def figure_file(path: Path, runs) -> FigureFile:
    f = FigureFile(path)
    f.runs = tuple(runs)
    return f


def runs_of(path: Path, keys) -> tuple[str, ...]:
    """The runs a figure file shows: its own record (:class:`FigureFile`), else (a plug-in's
    bare path) the run whose file stem begins its name, the longest such."""
    if isinstance(path, FigureFile):
        return tuple(path.runs)
    match = [k for k in keys if Path(path).stem.startswith(file_stem(k))]
    return (max(match, key=len),) if match else ()


def save(fig, out: Path, stem: str, runs=()) -> list[Path]:
    """``out/STEM.png`` and ``out/STEM.svg`` (``stem`` made safe by :func:`file_stem`), as
    :class:`FigureFile` paths showing ``runs``; the SVG has no date and fixed element ids
    (matplotlib salts them randomly otherwise). A file there that is not an earlier PNG or SVG
    is refused (``replay.log.LogError``), not overwritten, and so is a symbolic link."""
    out.mkdir(parents=True, exist_ok=True)
    stem = file_stem(stem)
    paths: list[Path] = [figure_file(out / f"{stem}.{x}", runs) for x in ("png", "svg")]
    for path in paths:
        check_output(path, kind="figure", magic=MAGIC[path.suffix])
    # each written beside its name and renamed onto it: never through a link planted there
    write_output(paths[0], lambda tmp: fig.savefig(tmp, format="png", dpi=150))
    with plt.rc_context({"svg.hashsalt": "paper-replay"}):
        write_output(paths[1], lambda tmp: fig.savefig(tmp, format="svg", metadata={"Date": None}))
    plt.close(fig)
    return paths
