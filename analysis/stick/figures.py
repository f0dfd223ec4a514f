"""Higashimori et al. 2007, Fig. 7: translational and rotational velocity of the stick vs time
during the capture, collision instants marked — drawn from a run's log."""

from __future__ import annotations

import copy

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.figure_files import save  # noqa: E402
from analysis import line_labels  # noqa: E402
from analysis import runs as run_labels  # noqa: E402
from analysis.needs import has, skip  # noqa: E402
from analysis.series import arrays, events  # noqa: E402
from plants.airtable.params import Params  # noqa: E402
from replay.log import LogReader  # noqa: E402
from replay.messages import TOPIC_STICK_STATE  # noqa: E402
from replay.scenario import ScenarioError, params_from_data  # noqa: E402


# what each figure reads (the contract a stick-capture controller fulfils: README)
TOPICS = {"Fig. 7": (TOPIC_STICK_STATE,), "friction overlay": (TOPIC_STICK_STATE,)}
MAX_VARIANTS = 6  # runs in one variants overlay


def fig7(log: LogReader, title: str = ""):
    s = arrays(log, TOPIC_STICK_STATE, ["vx", "vy", "omega"])
    speed = np.hypot(s["vx"], s["vy"])
    fig, (ax_v, ax_w) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.2))
    ax_v.plot(s["t"], speed, color="tab:blue", lw=1.4, label="simulated (Pymunk)")
    ax_w.plot(s["t"], s["omega"], color="tab:red", lw=1.4, label="simulated (Pymunk)")
    marks = []
    collisions, more = line_labels.first(events(log, "collision"))
    captures, more_captures = line_labels.first(events(log, "capture"))
    for e in collisions:
        for ax in (ax_v, ax_w):
            ax.axvline(e["t"], color="0.4", lw=0.8, ls="--")
        marks.append((e["t"], f"#{e['data'].get('index', '')}"))
    for e in captures:
        for ax in (ax_v, ax_w):
            ax.axvline(e["t"], color="tab:green", lw=1.0)
    ax_v.set_ylabel("translational speed |v| [m/s]")
    ax_w.set_ylabel("angular velocity ω [rad/s]")
    ax_w.set_xlabel("time [s]")
    ax_w.axhline(0.0, color="0.7", lw=0.6)
    for ax in (ax_v, ax_w):
        ax.grid(alpha=0.3)
    ax_v.set_title(title or "Translational and rotational velocities (cf. Fig. 7)", fontsize=10)
    fig.text(
        0.01,
        0.005,
        "dashed: fingertip-stick collisions #index (from /events); green: capture"
        + (f" ({line_labels.MORE})" if more or more_captures else ""),
        fontsize=7,
        color="0.35",
        va="bottom",
    )
    fig.tight_layout()
    line_labels.place(ax_v, marks)  # (close collisions' labels stagger down)
    ax_v.legend(fontsize=8, loc="best")
    return fig


def friction_overlay(logs: dict[str, LogReader], labels: dict[str, str] | None = None, title=""):
    """The same strategy run under different friction: the curves should coincide (Sec. II-C).
    With ``labels`` (run key -> legend entry), any runs overlaid under ``title``."""
    fig, (ax_v, ax_w) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.2))
    for name, log in sorted(logs.items()):
        mu = _mu(log)
        s = arrays(log, TOPIC_STICK_STATE, ["vx", "vy", "omega"])
        label = f"{name} (μ = {mu:g})" if mu is not None else name
        label = labels[name] if labels is not None else label
        ax_v.plot(s["t"], np.hypot(s["vx"], s["vy"]), lw=1.2, label=label)
        ax_w.plot(s["t"], s["omega"], lw=1.2, label=label)
    ax_v.set_ylabel("|v| [m/s]")
    ax_w.set_ylabel("ω [rad/s]")
    ax_w.set_xlabel("time [s]")
    ax_v.set_title(title or "Friction independence: the same plan under different μ", fontsize=10)
    ax_v.legend(fontsize=7)
    for ax in (ax_v, ax_w):
        ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def _params(log: LogReader) -> Params:
    """The air table's typed params, rebuilt from the log's resolved scenario by the loader."""
    sc = copy.deepcopy(log.scenario_config())
    return params_from_data(Params, sc["plant"].get("params"), "plant.params")


def _mu(log: LogReader):
    try:
        return float(_params(log).stick.friction)
    except (KeyError, TypeError, ValueError, ScenarioError):
        return None


def make_figures(logs: dict[str, LogReader], out: Path) -> list[Path]:
    """Fig. 7 for every stick run, and the friction overlay for runs of the same strategy."""
    paths: list[Path] = []
    logs = {n: log for n, log in logs.items() if has({n: log}, TOPICS["Fig. 7"], "stick Fig. 7")}
    for name, log in sorted(logs.items()):
        paths += save(
            fig7(log, f"{run_labels.titled(name, log)}: velocities vs time (cf. Fig. 7)"),
            out,
            f"{name}_fig7",
            [name],
        )
    by_strategy: dict[str, dict[str, LogReader]] = {}
    for name, log in logs.items():
        sc = copy.deepcopy(log.scenario_config())
        if _params(log).stick.collision_width == 0.0:
            by_strategy.setdefault(sc["controller"]["type"], {})[name] = log
    for strategy, group in sorted(by_strategy.items()):
        if len({_mu(log) for log in group.values()}) > 1:
            paths += save(friction_overlay(group), out, f"{strategy}_friction", sorted(group))
    return paths + _variant_figures(logs, out)


def _variant_figures(logs: dict[str, LogReader], out: Path) -> list[Path]:
    """Fig. 7's velocities of every run of one experiment overlaid, each labelled by what
    differs (analysis/runs.py), when some run of it differs from its shipped scenario."""
    groups: dict[str, dict[str, LogReader]] = {}
    for name, log in logs.items():
        groups.setdefault(run_labels.describe(log, name).experiment, {})[name] = log
    paths: list[Path] = []
    for experiment, group in sorted(groups.items()):
        labels = {n: run_labels.describe(log, n).label for n, log in group.items()}
        if not experiment or len(group) < 2 or not any(labels.values()):
            continue
        keys = sorted(group, key=lambda n: (bool(labels[n]), n))
        for n in keys[MAX_VARIANTS:]:
            skip(f"{n}: not in {experiment}'s variants overlay (at most {MAX_VARIANTS} runs)")
        shown = {n: group[n] for n in keys[:MAX_VARIANTS]}
        legend = {n: run_labels.titled(n, log) for n, log in shown.items()}  # name (label)
        legend.update({n: f"{n} (as shipped)" for n in shown if not labels[n]})
        title = f"{experiment} and its variants: velocities vs time (cf. Fig. 7)"
        fig = friction_overlay(shown, legend, title)
        paths += save(fig, out, f"{experiment}_variants", sorted(shown))
    return paths
