"""The stick-capture ablations (sweeps/stick_*.yaml): a metrics function the sweep runs on each
log, and the plots drawn from the tables."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.ablation_table import captured, counts_by, rate_by  # noqa: E402
from analysis.ablation_plot import (  # noqa: E402
    RATE_NOTE,
    plain_log_ticks,
    plot_rates,
    shifts,
)
from analysis.figure_files import save  # noqa: E402
from replay.sweep.table import as_float  # noqa: E402


def first_collision(log) -> dict:
    """The stick's velocity after the first collision, measured and as the method planned it."""
    for e in log.events():
        if e["kind"] == "collision" and e["data"].get("index") == 1:
            d = e["data"]
            planned = d.get("planned") or {}
            out = {
                "speed_after": math.hypot(*d["v_after"]),
                "omega_after": d["omega_after"],
                "t": e["t"],
            }
            if planned.get("v_after") is not None:
                out["planned_speed_after"] = math.hypot(*planned["v_after"])
                out["planned_omega_after"] = planned["omega_after"]
            return out
    return {}


def plot_friction(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax_v, ax_w) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.2))
    widths = sorted({as_float(r["plant.params.stick.collision_width"]) for r in rows})
    for w in widths:
        sub = sorted(
            (r for r in rows if as_float(r["plant.params.stick.collision_width"]) == w),
            key=lambda r: as_float(r["plant.params.stick.friction"]),
        )
        mu = [as_float(r["plant.params.stick.friction"]) for r in sub]
        ax_v.plot(
            mu, [as_float(r.get("x.speed_after")) for r in sub], "o-", label=f"W = {w * 1e3:g} mm"
        )
        ax_w.plot(
            mu, [as_float(r.get("x.omega_after")) for r in sub], "o-", label=f"W = {w * 1e3:g} mm"
        )
    plan_v = [as_float(r.get("x.planned_speed_after")) for r in rows]
    plan_w = [as_float(r.get("x.planned_omega_after")) for r in rows]
    if rows and not np.all(np.isnan(plan_v)):
        ax_v.axhline(float(np.nanmean(plan_v)), color="k", lw=0.8, ls="--", label="planned")
        ax_w.axhline(float(np.nanmean(plan_w)), color="k", lw=0.8, ls="--", label="planned")
    ax_v.set_ylabel("|v| after collision 1 [m/s]")
    ax_w.set_ylabel("ω after collision 1 [rad/s]")
    ax_w.set_xlabel("friction coefficient μ")
    for ax in (ax_v, ax_w):
        ax.grid(True, alpha=0.3)
    ax_v.legend(fontsize=8)
    ax_v.set_title("3-step strategy: first collision vs μ and width W", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_vision(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    curves = sorted(
        counts_by(rows, "camera", "sensors.camera.params.noise_sigma", captured).items(),
        key=lambda kv: float(kv[0]),
    )
    for (noise, (xs, ks, ns)), dx in zip(curves, shifts(len(curves), 0.02)):
        label = f"pixel noise σ = {float(noise):g} grey levels"
        plot_rates(ax, xs, ks, ns, "o-", label, dx, log_x=True)
    ax.axvline(300, color="0.5", lw=0.8, ls=":", label="paper: 300 fps")
    ax.set_xscale("log")
    plain_log_ticks(ax)
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel("camera frame rate [Hz] (latency one frame)")
    ax.set_ylabel(f"capture rate k/n\n({RATE_NOTE})", fontsize=8)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("3-step strategy: capture rate vs vision rate and noise", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_friction(rows: list[dict]) -> str:
    from analysis.ablation_table import failures

    parts = []
    for w in sorted({as_float(r["plant.params.stick.collision_width"]) for r in rows}):
        sub = [r for r in rows if as_float(r["plant.params.stick.collision_width"]) == w]
        v = np.array([as_float(r.get("x.speed_after")) for r in sub])
        om = np.array([as_float(r.get("x.omega_after")) for r in sub])
        if np.all(np.isnan(v)):
            parts.append(f"W = {w * 1e3:g} mm: no first collision")
            continue
        parts.append(
            f"W = {w * 1e3:g} mm: |v| {np.nanmin(v):.3f}-{np.nanmax(v):.3f} m/s, "
            f"ω {np.nanmin(om):.2f} to {np.nanmax(om):.2f} rad/s"
        )
    plan = [as_float(r.get("x.planned_omega_after")) for r in rows]
    text = "Over μ = 0-1 after collision 1: " + "; ".join(parts)
    if rows and not np.all(np.isnan(plan)):
        text += f" (planned ω {np.nanmean(plan):.2f} rad/s, |v| ~0)"
    bad = failures(rows)
    return text + (f"; {len(bad)} variants failed to run" if bad else "") + "."


def summary_vision(rows: list[dict]) -> str:
    from analysis.ablation_table import overall, pct

    curves = rate_by(rows, "camera", "sensors.camera.params.noise_sigma", captured)
    parts = []
    for noise in sorted(curves, key=float):
        xs, ys = curves[noise]
        parts.append(
            f"σ = {float(noise):g}: "
            + ", ".join(f"{pct(y)} at {x:g} fps" for x, y in zip(xs[::-1], ys[::-1]))
        )
    return f"Capture rate ({overall(rows, captured, 'captured')}): " + "; ".join(parts) + "."
