"""Plots of the catching ablations (sweeps/catch_*.yaml), each drawn from its sweep table."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from analysis.ablation_table import caught, rate_by  # noqa: E402
from analysis.figure_files import save  # noqa: E402


def _rate_axes(ax, xlabel: str, log_x: bool = False) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel("catch rate")
    ax.set_ylim(-0.05, 1.05)
    if log_x:
        ax.set_xscale("log")
    ax.grid(True, alpha=0.3)


def plot_vision(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for lat, (xs, ys) in sorted(rate_by(rows, "sensors.stereo.rate", "sensors.stereo.latency",
                                        caught).items(), key=lambda kv: float(kv[0])):
        ax.plot(xs, ys, "o-", label=f"latency {float(lat) * 1e3:g} ms")
    _rate_axes(ax, "stereo frame rate [Hz]", log_x=True)
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping: catch rate vs camera rate and latency", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_throw_speed(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    (xs, ys), = rate_by(rows, "throw_speed", None, caught).values()
    ax.plot(xs, ys, "o-", color="tab:blue")
    ax.axvspan(8.0, 10.0, color="tab:green", alpha=0.1, label="optimised for 8-10 m/s")
    _rate_axes(ax, "throw speed [m/s]")
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping: catch vs throw speed (1 kHz vision)", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_arm_limits(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for scale, (xs, ys) in sorted(rate_by(rows, "joint_speed_limit", "torque_scale",
                                          caught).items(), key=lambda kv: float(kv[0])):
        ax.plot(xs, ys, "o-", label=f"torque limits x{scale}")
    _rate_axes(ax, "enforced joint speed limit [rad/s]", log_x=True)
    ax.legend(fontsize=8)
    ax.set_title("What the arm needs: catch vs joint speed and torque limits", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_direct_vs_predictive(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    styles = {"catch_optimised": ("tab:blue", "direct mapping"),
              "catch_predictive": ("tab:orange", "predict-then-intercept")}
    for (method, kick), sub in sorted(_split(rows, "scenario", "kick").items()):
        (xs, ys), = rate_by(sub, "camera", None, caught).values()
        color, label = styles.get(method, ("0.4", method))
        ax.plot(xs, ys, "o-" if kick == "none" else "s--", color=color,
                label=f"{label}, {'no kick' if kick == 'none' else 'mid-flight kick'}")
    _rate_axes(ax, "stereo frame rate [Hz] (latency one frame)", log_x=True)
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping vs predictor: catch rate vs camera rate", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def _split(rows, *cols):
    out: dict = {}
    for r in rows:
        out.setdefault(tuple(r.get(c, "") for c in cols), []).append(r)
    return out
