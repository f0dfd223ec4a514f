"""Saving a figure as PNG and SVG so that the same log gives the same files."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def save(fig, out: Path, stem: str) -> list[Path]:
    """``out/stem.png`` and ``out/stem.svg``; the SVG has no date and fixed element ids
    (matplotlib salts them randomly otherwise)."""
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / f"{stem}.png", out / f"{stem}.svg"]
    fig.savefig(paths[0], dpi=150)
    with plt.rc_context({"svg.hashsalt": "paper-replay"}):
        fig.savefig(paths[1], metadata={"Date": None})
    plt.close(fig)
    return paths
