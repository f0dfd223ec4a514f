"""Drawing the ablations' rates: each point k/n with its Wilson 95 % interval as an error bar
and n in the legend (a rate from one throw is no evidence: the bar says so); log axes with
plain tick labels."""

from __future__ import annotations


import numpy as np
from matplotlib.ticker import FuncFormatter, NullFormatter


def n_said(ns: list[int]) -> str:
    """'n = 3' or 'n = 1-3': the runs behind each point of a line."""
    lo, hi = min(ns, default=0), max(ns, default=0)
    return f"n = {lo}" if lo == hi else f"n = {lo}-{hi}"


def plot_rates(ax, xs, ks, ns, fmt: str, label: str, shift: float = 0.0, log_x=False, **style):
    """Rates k/n at ``xs`` with Wilson 95 % error bars, ``n`` in the legend entry; ``shift``
    moves the points sideways (a fraction of a decade on a log axis, else of x units) so that
    coinciding lines stay apart."""
    from analysis.catching.ablations import wilson

    xs = np.asarray(xs, float)
    xs = xs * 10**shift if log_x else xs + shift
    ys = np.array([k / n if n else np.nan for k, n in zip(ks, ns)])
    bounds = np.array([wilson(k, n) for k, n in zip(ks, ns)]).reshape(-1, 2)
    err = np.vstack([ys - bounds[:, 0], bounds[:, 1] - ys]).clip(min=0.0)
    label = f"{label} ({n_said(ns)})" if label else n_said(ns)
    return ax.errorbar(xs, ys, yerr=err, fmt=fmt, capsize=3, elinewidth=0.8, label=label, **style)


def shifts(m: int, step: float) -> list[float]:
    """``m`` sideways offsets ``step`` apart, centred on zero."""
    return [(i - (m - 1) / 2.0) * step for i in range(m)]


def plain_log_ticks(ax) -> None:
    """Tick labels of a log x axis as plain numbers (the figures turn mathtext off, so
    matplotlib's '10^{2}' labels would show as their source)."""
    ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax.xaxis.set_minor_formatter(NullFormatter())


RATE_NOTE = "error bars: Wilson 95 % interval of k/n"
