"""Plots of the main signals (uPlot in the GUI panel) with a cursor at the current time.

Every run's signal is resampled onto one shared time grid (at most ``GRID_POINTS`` points), so
several runs share one chart. The cursor is one more series, on its own fixed 0..1 scale: off
the chart everywhere except three samples inserted at the current time, which draw a vertical
line (uPlot takes NaN as a value, not a gap, so the cursor uses out-of-range values instead).
"""

from __future__ import annotations

import numpy as np
import viser

from replay.viewer.data import RunData, resample
from replay.viewer.scenes import PlotSpec

GRID_POINTS = 500
PALETTE = [
    "#1f77b4",
    "#d62728",
    "#2ca02c",
    "#9467bd",
    "#ff7f0e",
    "#8c564b",
    "#e377c2",
    "#17becf",
    "#bcbd22",
    "#7f7f7f",
]
_OFF = -10.0  # cursor value off the chart (its scale is fixed to 0..1)


class Plot:
    def __init__(self, gui, spec: PlotSpec, runs: list[RunData], grid: np.ndarray) -> None:
        self.grid = grid
        self.ys: list[np.ndarray] = []
        series: list[dict[str, object]] = [{"label": "t (s)"}]
        many = len(runs) > 1
        for k, run in enumerate(runs):
            for s_i, s in enumerate(spec.series):
                got = s.signal(run)
                if got is None or len(got[0]) == 0:
                    continue
                t, y = got
                self.ys.append(resample(t, y, grid))
                label = f"{s.label} ({run.label})" if many else s.label
                cfg = {
                    "label": label,
                    "stroke": PALETTE[(s_i if len(spec.series) > 1 else k) % len(PALETTE)],
                    "width": 1.5,
                    "scale": "y",
                    "points": {"show": False},
                }
                if k > 0 and len(spec.series) > 1:
                    cfg["dash"] = [6, 4]
                series.append(cfg)
        self.empty = not self.ys
        series.append(
            {
                "label": "now",
                "stroke": "#343a40",
                "width": 1.5,
                "scale": "cursor",
                "points": {"show": False},
            }
        )
        self.handle = None
        if self.empty:
            return
        self.handle = gui.add_uplot(
            self._data(float(grid[0])),
            tuple(series),
            title=spec.title,
            scales={
                "x": {"time": False, "auto": True},
                "y": {"auto": True},
                "cursor": {"auto": False, "range": [0.0, 1.0]},
            },
            axes=({}, {"scale": "y", "size": 48}),
            legend={"show": True, "live": False},
            cursor={"show": False},
            aspect=1.6,
        )

    def _data(self, t: float) -> tuple[np.ndarray, ...]:
        x = self.grid
        j = int(np.searchsorted(x, t))
        xs = np.insert(x, j, [t, t, t])
        out = [xs]
        for y in self.ys:
            v = float(np.interp(t, x, y))
            out.append(np.insert(y, j, [v, v, v]))
        cur = np.full(len(xs), _OFF)
        cur[j + 1] = 1.0 - _OFF
        out.append(cur)
        return tuple(out)

    def set_cursor(self, t: float) -> None:
        if self.handle is not None:
            self.handle.data = self._data(t)


class PlotPanel:
    """All plots of the shown runs, in the current GUI container."""

    def __init__(
        self,
        server: viser.ViserServer,
        specs: list[PlotSpec],
        runs: list[RunData],
        t_range: tuple[float, float],
    ) -> None:
        t0, t1 = t_range
        n = GRID_POINTS if t1 > t0 else 2
        grid = np.linspace(t0, t1 if t1 > t0 else t0 + 1e-3, n)
        self.plots = [Plot(server.gui, s, runs, grid) for s in specs]
        self.plots = [p for p in self.plots if not p.empty]

    def set_cursor(self, t: float) -> None:
        for p in self.plots:
            p.set_cursor(t)
