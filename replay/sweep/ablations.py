"""The named ablations: sweep files under sweeps/, their tables and their plots.

``replay ablate NAME`` runs ``sweeps/NAME.yaml`` into ``out/ablations/NAME/`` (table.csv, logs/)
and draws the plot from that table; ``--store`` also keeps the table as ``data/ablations/NAME.csv``,
the precomputed table the report plots when no fresh one exists (so ``make run`` need not rerun
hundreds of variants).
"""

from __future__ import annotations

import csv
from pathlib import Path

from replay.resources import data_path, sweep_dir
from replay.sweep.spec import SweepFile, SweepSpecError, load_sweep_file
from replay.sweep.table import column_name, read_table
from replay.sweep.worker import load_function

SWEEP_DIR = sweep_dir()
STORED_DIR = data_path("ablations")
OUT_DIR = Path("out/ablations")


def names() -> list[str]:
    return sorted(p.stem for p in SWEEP_DIR.glob("*.yaml"))


def load(name: str) -> SweepFile:
    path = Path(name)
    if not (path.suffix == ".yaml" and path.is_file()):
        path = SWEEP_DIR / f"{name}.yaml"
    if not path.is_file():
        raise SweepSpecError(f"unknown ablation {name!r} (known: {', '.join(names())})")
    return load_sweep_file(path)


def table_path(name: str, out_dir: Path = OUT_DIR) -> tuple[Path | None, str]:
    """The freshest table of an ablation: this machine's run, else the stored one."""
    fresh = out_dir / name / "table.csv"
    if fresh.is_file() and read_table(fresh):
        return fresh, "run here"
    stored = STORED_DIR / f"{name}.csv"
    if stored.is_file():
        return stored, "stored"
    return None, "not run"


def store(name: str, table: Path) -> Path:
    """Keep a finished table as data/ablations/NAME.csv (log paths blanked: they are local)."""
    rows = read_table(table)
    dest = STORED_DIR / f"{name}.csv"
    dest.parent.mkdir(parents=True, exist_ok=True)
    with table.open(newline="", encoding="utf-8") as f:
        head = next(csv.reader(f))  # (as written: with its units)
    with dest.open("w", newline="", encoding="utf-8") as f:
        csv.writer(f).writerow(head)
        w = csv.DictWriter(f, fieldnames=[column_name(h) for h in head])
        for r in rows:
            w.writerow({**r, "log": ""})
    return dest


def plot(sf: SweepFile, table: Path, out: Path) -> list[Path]:
    rows = read_table(table)
    return load_function(sf.plot)(rows, out, f"ablation_{sf.name}")
