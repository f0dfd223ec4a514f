"""The plot of any sweep (``DIR/summary.png``/``.svg``, drawn by ``replay sweep`` from its
``summary.csv``): each cell's success rate with its Wilson 95 % interval; one numeric varied
parameter is the x axis, else the cells are named along it."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from analysis.ablation_plot import RATE_NOTE, plot_rates  # noqa: E402
from analysis.figure_files import save  # noqa: E402
from replay.sweep.results import COLUMNS  # noqa: E402
from replay.sweep.table import as_float, read_table  # noqa: E402

STEM = "summary"
LABEL_CHARS = 40  # a cell's name along the x axis at most this long (the grid's values are data)
MAX_CELLS = 60  # cells drawn at most (a bigger sweep: its summary.csv says the rest)


def plot_summary(summary: Path, out: Path) -> list[Path]:
    """``out/summary.png`` and ``.svg`` from ``summary`` (nothing when no cell has a run)."""
    cells = [c for c in read_table(summary) if int(c.get("runs") or 0) > 0][:MAX_CELLS]
    if not cells:
        return []
    axes = [k for k in cells[0] if k not in COLUMNS]
    ks = [int(c["successes"]) for c in cells]
    ns = [int(c["runs"]) for c in cells]
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    values = [as_float(c[axes[0]]) for c in cells] if len(axes) == 1 else []
    if values and all(v == v for v in values):  # (one numeric axis: no NaN among its values)
        plot_rates(ax, values, ks, ns, "o-", "")
        ax.set_xlabel(_clip(axes[0]))
    else:
        plot_rates(ax, list(range(len(cells))), ks, ns, "o", "")
        names = [_clip(", ".join(f"{a}={c[a]}" for a in axes) or "all") for c in cells]
        ax.set_xticks(range(len(cells)), names, rotation=60, ha="right", fontsize=7)
    ax.set_ylabel(f"success rate k/n\n({RATE_NOTE})", fontsize=8)
    ax.set_ylim(-0.05, 1.05)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return save(fig, out, STEM)


def _clip(text: str) -> str:
    return text if len(text) <= LABEL_CHARS else text[: LABEL_CHARS - 1] + "…"
