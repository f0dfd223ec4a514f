"""The grasping ablations: grasp rate and tracking error against the loop period of every task and
the vision chip, one line per speed of the human hand (sweeps/grasp_loops.yaml); the wrist force
term K^af of eq. 2 against the human's force and the object's drift in the hand during the hold
(sweeps/grasp_force.yaml)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.ablation_table import grasped, mean_by, overall, pct, rate_by  # noqa: E402
from analysis.ablation_plot import RATE_NOTE, plot_rates, shifts  # noqa: E402
from analysis.ablation_table import counts_by  # noqa: E402
from analysis.figure_files import save  # noqa: E402

PERIOD = "loop_period_ms"
SPEED = "plant.params.human_speed"
TRACKING = "m.tracking_error_rms"  # m: in-plane, grasp point to object centre, before the grasp


def plot_loops(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6))
    errors = mean_by(rows, PERIOD, SPEED, TRACKING)
    periods: set = set()
    curves = sorted(counts_by(rows, PERIOD, SPEED, grasped).items(), key=lambda kv: float(kv[0]))
    for i, ((speed, (xs, ks, ns)), dx) in enumerate(zip(curves, shifts(len(curves), 0.02))):
        # markers shrink line by line so that coinciding curves stay visible
        style = {
            "marker": "osD^v"[i % 5],
            "markersize": 9 - 2 * (i % 4),
            "lw": 2.4 - 0.6 * (i % 4),
        }
        label = f"object {float(speed):g} m/s RMS"
        plot_rates(ax, xs, ks, ns, "-", label, dx, log_x=True, **style)
        ex, ey = errors[speed]
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
    ax2.set_ylabel("RMS tracking error\nbefore the grasp [mm]", fontsize=8)
    ax2.set_xlabel("loop period of every task and the vision chip [ms]")
    ax.legend(fontsize=8)
    ax.set_title("Grasping: grasp rate and tracking error vs loop period", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_loops(rows: list[dict]) -> str:
    rates = rate_by(rows, PERIOD, SPEED, grasped)
    errors = mean_by(rows, PERIOD, SPEED, TRACKING)
    parts = []
    for speed in sorted(rates, key=float):
        xs, ys = rates[speed]
        _, es = errors[speed]
        ok = ", ".join(f"{x:g}" + ("" if y == 1 else f" ({pct(y)})") for x, y in zip(xs, ys) if y)
        err = ", ".join("n/a" if np.isnan(e) else f"{e * 1e3:.0f}" for e in es)
        parts.append(
            f"at {float(speed):g} m/s grasped with {ok or 'no'} ms loops, "
            f"RMS tracking error {err} mm at {', '.join(f'{x:g}' for x in xs)} ms"
        )
    return (
        f"Grasp rate against loop period ({overall(rows, grasped, 'grasped')}): "
        + "; ".join(parts)
        + "."
    )


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
