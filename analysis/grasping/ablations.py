"""The grasping ablations: grasp rate and tracking error against the loop period of every task and
the vision chip, the gains re-designed for each period, one line per motion of the human hand
(sweeps/grasp_loops.yaml) and the thesis's verdict from that table (:func:`thesis`); the grasp
rate with each part removed alone (sweeps/grasp_components.yaml); the wrist force term K^af of
eq. 2 against the human's force and the object's drift in the hand during the hold
(sweeps/grasp_force.yaml)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402

from analysis.catching.ablations import wilson  # noqa: E402
from analysis.ablation_table import counts_by, grasped, mean_by, pct, rate_by  # noqa: E402
from analysis.ablation_plot import RATE_NOTE, plot_rates, shifts  # noqa: E402
from analysis.figure_files import save  # noqa: E402

PERIOD = "loop_period_ms"
MOTION = "motion"  # the human's RMS speed (m/s), with kicks of that speed (sweeps/grasp_loops.yaml)
SPEED = "plant.params.human_speed"
TRACKING = "m.tracking_error_rms"  # m: in-plane, grasp point to object centre, before the grasp
COMPONENT = "component"


def plot_loops(rows: list[dict], out: Path, stem: str) -> list[Path]:
    rows = [r for r in rows if r.get(MOTION)]  # (a pre-#38 table has none: nothing drawn)
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6))
    errors = mean_by(rows, PERIOD, MOTION, TRACKING)
    periods: set = set()
    curves = sorted(counts_by(rows, PERIOD, MOTION, grasped).items(), key=lambda kv: float(kv[0]))
    for i, ((motion, (xs, ks, ns)), dx) in enumerate(zip(curves, shifts(len(curves), 0.02))):
        # markers shrink line by line so that coinciding curves stay visible
        style = {
            "marker": "osD^v"[i % 5],
            "markersize": 9 - 2 * (i % 4),
            "lw": 2.4 - 0.6 * (i % 4),
        }
        label = f"object {float(motion):g} m/s RMS + kicks"
        plot_rates(ax, xs, ks, ns, "-", label, dx, log_x=True, **style)
        ex, ey = errors[motion]
        ax2.plot(ex, np.asarray(ey) * 1e3, label=label, **style)
        periods.update(xs)
    for a in (ax, ax2):
        a.axvline(1.0, color="0.5", lw=0.8, ls=":", label="paper: 1 ms" if a is ax else None)
        a.set_xscale("log")
        a.set_xticks(sorted(periods), [f"{x:g}" for x in sorted(periods)])
        a.minorticks_off()
        a.grid(True, alpha=0.3)
    ax.set_ylim(-0.05, 1.05)
    ax.set_ylabel(f"grasp rate k/n\n({RATE_NOTE})", fontsize=8)
    ax2.set_yscale("log")  # 1 mm to the lost target's 0.5 m; plain labels (no mathtext)
    ax2.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    ax2.yaxis.set_minor_formatter(NullFormatter())
    ax2.set_ylabel("RMS tracking error before\nthe grasp, mean [mm]", fontsize=8)
    ax2.set_xlabel("loop period of every task and the chip [ms] (gains re-designed)", fontsize=9)
    ax.legend(fontsize=7)
    ax.set_title("Grasping: grasp rate and tracking error vs loop period", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_loops(rows: list[dict]) -> str:
    said = thesis({"grasp_loops": rows})
    return f"The thesis {said['verdict']}. {said['numbers']}"


def _cells(rows: list[dict], x: str, line: str) -> dict[str, dict[float, tuple[int, int]]]:
    """{line: {x: (grasped k, runs n)}} of a rate table."""
    return {
        name: {xv: (k, n) for xv, k, n in zip(xs, ks, ns)}
        for name, (xs, ks, ns) in counts_by(rows, x, line, grasped).items()
    }


def _k_n(kn: tuple[int, int]) -> str:
    lo, hi = wilson(*kn)
    return f"{kn[0]}/{kn[1]} [{100 * lo:.0f}-{100 * hi:.0f} %]"


def _behind(a: tuple[int, int], b: tuple[int, int]) -> bool:
    """Rate a is below rate b: their Wilson 95 % intervals are disjoint (else a tie)."""
    return wilson(*a)[1] < wilson(*b)[0]


def thesis(tables) -> dict:
    """Namiki et al.'s thesis, "1 ms feedback in every loop makes the grasp of an irregularly
    moving object work, without prediction", from the stored grasp_loops table (``tables``: {sweep
    name: rows}, the rows themselves, or a table's path). Per motion level the grasp works at 1
    ms if at least half the runs grasp (k/n >= 1/2); a slower period loses grasps where its
    Wilson 95 % interval lies wholly below the 1 ms one (overlap: a tie). The thesis holds where
    the 1 ms grasp works and slowing the loops (gains re-designed, gain_rule.py) loses grasps;
    it does not hold where a slower loop ties, or where 1 ms itself fails. The numbers add the
    component ablation's (grasp_components) when ``tables`` has it."""
    rows = [r for r in _rows(tables, "grasp_loops") if r.get(MOTION)]  # (not a pre-#38 table)
    cells = _cells(rows, PERIOD, MOTION) if rows else {}
    if not cells:
        return {
            "verdict": "not run",
            "numbers": "run `replay ablate grasp_loops`",
            "figure": "grasp_loops",
        }
    parts: list[str] = []
    works: dict[str, bool] = {}
    loses: dict[str, float] = {}  # motion: the first period whose grasps fall below 1 ms's
    for motion in sorted(cells, key=float):
        c = cells[motion]
        fast = min(c)
        k, n = c[fast]
        works[motion] = n > 0 and 2 * k >= n
        lost = [x for x in sorted(c) if x > fast and _behind(c[x], c[fast])]
        if lost:
            loses[motion] = lost[0]
        ties = [x for x in sorted(c) if x > fast and x not in lost]
        parts.append(
            f"{float(motion):g} m/s with kicks: {fast:g} ms {_k_n(c[fast])}, "
            + ", ".join(f"{x:g} ms {_k_n(c[x])}" for x in sorted(c) if x > fast)
            + (
                f"; fewer grasps than at {fast:g} ms from {lost[0]:g} ms"
                if lost
                else f"; every period ties with {fast:g} ms"
            )
            + (f" (ties at {', '.join(f'{x:g}' for x in ties)} ms)" if lost and ties else "")
        )
    ok = [m for m in works if works[m]]
    needed = [m for m in ok if m in loses]
    fails = [m for m in works if not works[m]]
    if not ok:
        verdict = "does not hold: the 1 ms loops themselves grasp fewer than half the time"
    elif not needed:
        verdict = (
            f"does not hold: where 1 ms grasps ({_speeds(ok)}), loops of every period up to "
            f"{max(max(cells[m]) for m in ok):g} ms tie with it (gains re-designed per period)"
        )
    else:
        first = min(loses[m] for m in needed)
        second = min(x for m in needed for x in cells[m] if x > min(cells[m]))
        if first <= second and len(needed) == len(ok):
            verdict = (
                f"holds: at {_speeds(needed)} with kicks already a {first:g} ms loop grasps less"
            )
        else:
            tie = [x for m in needed for x in cells[m] if min(cells[m]) < x < first]
            verdict = (
                f"holds only when the object moves at {_speeds(needed)} with kicks and the loops "
                f"are slowed to {first:g} ms or more: those grasp less often than 1 ms"
                + (f", while loops of up to {max(tie):g} ms tie with it" if tie else "")
            )
            others = [m for m in ok if m not in needed]
            if others:
                top = max(max(cells[m]) for m in others)
                verdict += f" (at {_speeds(others)} every period up to {top:g} ms ties)"
        if fails:
            verdict += f"; at {_speeds(fails)} even 1 ms grasps fewer than half the time"
    numbers = "; ".join(parts) + "."
    parts_table = _rows(tables, "grasp_components") if isinstance(tables, dict) else []
    if parts_table:  # which parts the 1 ms grasp needs (sweeps/grasp_components.yaml)
        numbers += " " + summary_components(parts_table)
    return {"verdict": verdict, "numbers": numbers, "figure": "grasp_loops"}


def _speeds(motions: list[str]) -> str:
    return " and ".join(f"{float(m):g}" for m in motions) + " m/s RMS"


def _rows(tables, name: str) -> list[dict]:
    """The rows of sweep ``name`` from {name: rows}, a list of rows, or a stored table's path."""
    if isinstance(tables, dict):
        return list(tables.get(name, []))
    if isinstance(tables, (str, Path)):
        from replay.sweep.table import read_table

        return read_table(Path(tables))
    return list(tables)


def plot_components(rows: list[dict], out: Path, stem: str) -> list[Path]:
    counts = component_counts(rows)
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    names = list(counts)
    ys = np.arange(len(names))[::-1]
    for y, name in zip(ys, names):
        k, n = counts[name]
        lo, hi = wilson(k, n)
        rate = k / n if n else np.nan
        ax.errorbar(
            [rate],
            [y],
            xerr=[[rate - lo], [hi - rate]],
            fmt="o",
            capsize=3,
            color="C0" if name == FULL else "C1",
        )
        ax.text(1.04, y, f"{k}/{n}", va="center", fontsize=8)
    ax.set_yticks(ys, names, fontsize=8)
    ax.set_xlim(-0.05, 1.15)
    ax.set_xlabel(f"grasp rate k/n ({RATE_NOTE})", fontsize=8)
    ax.grid(True, axis="x", alpha=0.3)
    # (over the figure: the axes sit right of the long part names, a title over them ran out)
    fig.suptitle("Grasping: each part removed alone (0.4 m/s RMS + kicks, 1 ms)", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


FULL = "full system"


def component_counts(rows: list[dict]) -> dict[str, tuple[int, int]]:
    """{component: (grasped k, runs n)} in the sweep's order of first appearance."""
    out: dict[str, list[int]] = {}
    for r in rows:
        kn = out.setdefault(str(r.get(COMPONENT, "")), [0, 0])
        kn[0] += bool(grasped(r))
        kn[1] += 1
    return {name: (k, n) for name, (k, n) in out.items()}


def summary_components(rows: list[dict]) -> str:
    counts = component_counts(rows)
    full = counts.get(FULL)
    parts = []
    for name, kn in counts.items():
        if name == FULL or full is None:
            continue
        verdict = "needed" if _behind(kn, full) else "a tie (not shown needed)"
        parts.append(f"{name}: {_k_n(kn)}, {verdict}")
    head = f"Full system {_k_n(full)}" if full else "No full-system cell"
    return f"{head}; each part removed alone: " + "; ".join(parts) + "."


KAF = "tasks.arm.params.K_af"
FORCE = "m.hold_human_force_max"  # N: the human's largest force on the held object
HUMAN = "m.hold_human_offset_max"  # m: the held object's largest distance from the human's path
DRIFT = "m.hold_drift_max"  # m: its largest motion in the hand


def plot_force(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, axes = plt.subplots(3, 1, sharex=True, figsize=(6.4, 7.0))
    for col, ax, label, scale in (
        (FORCE, axes[0], "the human's largest force\non the held object [N]", 1.0),
        (HUMAN, axes[1], "held object from the\nhuman's path, max [mm]", 1e3),
        (DRIFT, axes[2], "object's drift in\nthe hand, max [mm]", 1e3),
    ):
        for i, (speed, (xs, ys)) in enumerate(sorted(mean_by(rows, KAF, SPEED, col).items())):
            ax.plot(xs, np.asarray(ys) * scale, marker="osD^v"[i % 5], label=f"human {speed} m/s")
        ax.set_ylabel(label, fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[1].axhline(20.0, color="0.5", ls=":", lw=0.8, label="success limit")
    axes[2].axhline(10.0, color="0.5", ls=":", lw=0.8)
    axes[0].legend(fontsize=8)
    axes[2].set_xlabel("eq. 2's K^af [rad/(s N m)]")
    axes[0].set_title("Grasping: the wrist force term during the hold", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_force(rows: list[dict]) -> str:
    parts = []
    force, human, drift = (mean_by(rows, KAF, SPEED, c) for c in (FORCE, HUMAN, DRIFT))
    rates = rate_by(rows, KAF, SPEED, grasped)
    for speed in sorted(force, key=float):
        xs, fs = force[speed]
        parts.append(
            f"at {float(speed):g} m/s, K^af "
            + ", ".join(
                f"{x:g}: human {f:.1f} N, {1e3 * h:.0f} mm off its path, drift {1e3 * d:.1f} mm"
                f" ({pct(r)} held with the human)"
                for x, f, h, d, r in zip(xs, fs, human[speed][1], drift[speed][1], rates[speed][1])
            )
        )
    return "The wrist force term during the hold (means over seeds): " + "; ".join(parts) + "."
