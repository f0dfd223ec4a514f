"""Rewrite stored files that name a moved analysis module (issue #40: a paper is a unit).

A sweep table (``data/**/*.csv``, its ``version`` column: ``CODE|module:function``) and a sweep
file (``sweeps/*.yaml``: ``metrics:``, ``plot:``, ``summary:``, ``thesis:``) name functions as
``analysis.<module>:<function>``. This rewrites every old module name of ``analysis.MOVED`` to
its new one, in place, and says which files it changed. The sweep loader follows the same table,
so a file not rewritten still loads.

    .venv/bin/python tools/migrate_analysis_names.py [FILE_OR_FOLDER ...]   # default: data sweeps
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from analysis import MOVED  # noqa: E402

# an old name followed by ``:`` (a function reference), never a prefix of a longer module name
_OLD = re.compile(
    "(" + "|".join(re.escape(m) for m in sorted(MOVED, key=len, reverse=True)) + r")(?=:)"
)


def migrated(text: str) -> str:
    """``text`` with every ``analysis.<old>:`` renamed to ``analysis.<new>:``."""
    return _OLD.sub(lambda m: MOVED[m.group(1)], text)


def _files(args: list[str]) -> list[Path]:
    found: list[Path] = []
    for arg in args:
        path = Path(arg)
        if path.is_dir():
            found += sorted(p for p in path.rglob("*") if p.suffix in (".csv", ".yaml"))
        else:
            found.append(path)
    return found


def main(args: list[str]) -> int:
    for path in _files(args or [str(ROOT / "data"), str(ROOT / "sweeps")]):
        text = path.read_text(encoding="utf-8")
        new = migrated(text)
        if new != text:
            path.write_text(new, encoding="utf-8")
            print(f"migrated {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
