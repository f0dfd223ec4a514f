"""Plots of the catching ablations (sweeps/catch_*.yaml), each drawn from its sweep table."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import numpy as np  # noqa: E402

from analysis.ablation_table import (
    caught,
    mean_by,
    overall,
    pct,
    rate_at,  # noqa: E402
    rate_by,
    counts_by,
)
from analysis.ablation_plot import (  # noqa: E402
    RATE_NOTE,
    plain_log_ticks,
    plot_rates,
    shifts,
)
from analysis.figure_files import save  # noqa: E402


def catch_metrics(log) -> dict:
    """How near each run came to a catch, also when it missed: the closest approach of the ball's
    centre to the hand's catch point l(q) (``/effector/state``, the controller's model of where
    the ball should sit on the palm), and the ball's speed relative to the hand at its first
    contact with the palm or fingers."""
    from analysis.series import arrays, events
    from replay.messages import TOPIC_EFFECTOR_STATE, TOPIC_OBJECT_STATE

    ball = arrays(log, TOPIC_OBJECT_STATE, ["position"])
    hand = (
        arrays(log, TOPIC_EFFECTOR_STATE, ["position"])
        if log.topic_counts().get(TOPIC_EFFECTOR_STATE)
        else {"t": np.zeros(0)}
    )
    out: dict = {}
    if len(ball["t"]) and len(hand["t"]) and hand["position"].ndim == 2:
        # the ball's state at the hand's stamps (both are logged at the control rate)
        idx = np.clip(np.searchsorted(ball["t"], hand["t"]), 0, len(ball["t"]) - 1)
        d = np.linalg.norm(ball["position"][idx] - hand["position"], axis=1)
        k = int(np.argmin(d))
        out.update(min_distance=float(d[k]), t_min_distance=float(hand["t"][k]))
    for e in events(log, "contact"):
        if set(e["data"].get("parts", [])) - {"arm"}:
            out.update(
                contact_speed=e["data"]["speed"],
                contact_t=e["t"],
                contact_parts="+".join(e["data"]["parts"]),
            )
            break
    return out


def _rate_axes(ax, xlabel: str, log_x: bool = False) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"catch rate k/n\n({RATE_NOTE})", fontsize=8)
    ax.set_ylim(-0.05, 1.05)
    if log_x:
        ax.set_xscale("log")
        plain_log_ticks(ax)
    ax.grid(True, alpha=0.3)


def _near_axes(ax, xlabel: str, log_x: bool = True) -> None:
    ax.set_xlabel(xlabel)
    ax.set_ylabel("ball speed rel. to hand\nat first hand contact [m/s]", fontsize=8)
    if log_x:
        ax.set_xscale("log")
        plain_log_ticks(ax)
    ax.grid(True, alpha=0.3)


def plot_vision(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6))
    x, line = "sensors.stereo.rate", "sensors.stereo.latency"
    speeds = mean_by(rows, x, line, "x.contact_speed")
    curves = sorted(counts_by(rows, x, line, caught).items(), key=lambda kv: float(kv[0]))
    for (lat, (xs, ks, ns)), dx in zip(curves, shifts(len(curves), 0.02)):
        plot_rates(ax, xs, ks, ns, "o-", f"latency {float(lat) * 1e3:g} ms", dx, log_x=True)
        ax2.plot(*speeds[lat], "o-")
    _rate_axes(ax, "", log_x=True)
    _near_axes(ax2, "stereo frame rate [Hz]")
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping: catch rate vs camera rate and latency", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_throw_speed(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6))
    ((xs, ks, ns),) = counts_by(rows, "throw_speed", None, caught).values()
    plot_rates(ax, xs, ks, ns, "o-", "catch rate", color="tab:blue")
    ax2.plot(*mean_by(rows, "throw_speed", None, "x.contact_speed")[""], "o-", color="tab:blue")
    for a in (ax, ax2):
        a.axvspan(
            8.0,
            10.0,
            color="tab:green",
            alpha=0.1,
            label="optimised for 8-10 m/s" if a is ax else None,
        )
    _rate_axes(ax, "")
    _near_axes(ax2, "throw speed [m/s]", log_x=False)
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping: catch vs throw speed (1 kHz vision)", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_arm_limits(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 5.6))
    x, line = "joint_speed_limit", "torque_scale"
    speeds = mean_by(rows, x, line, "x.contact_speed")
    curves = sorted(counts_by(rows, x, line, caught).items(), key=lambda kv: float(kv[0]))
    for (scale, (xs, ks, ns)), dx in zip(curves, shifts(len(curves), 0.02)):
        plot_rates(ax, xs, ks, ns, "o-", f"torque limits x{scale}", dx, log_x=True)
        ax2.plot(*speeds[scale], "o-")
    _rate_axes(ax, "", log_x=True)
    _near_axes(ax2, "enforced joint speed limit [rad/s]")
    ax.legend(fontsize=8)
    ax.set_title("What the arm needs: catch vs joint speed and torque limits", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def plot_direct_vs_predictive(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax2) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0))
    styles = {
        "catch_optimised": ("tab:blue", "direct mapping"),
        "predictive_catch": ("tab:orange", "predict-then-intercept"),
    }
    groups = sorted(_split(rows, "scenario", "kick").items())
    for ((method, kick), sub), dx in zip(groups, shifts(len(groups), 0.02)):
        ((xs, ks, ns),) = counts_by(sub, "camera", None, caught).values()
        color, label = styles.get(method, ("0.4", method))
        style = "o-" if kick == "none" else "s--"
        plot_rates(
            ax,
            xs,
            ks,
            ns,
            style,
            f"{label}, {'no kick' if kick == 'none' else 'mid-flight kick'}",
            dx,
            log_x=True,
            color=color,
        )
        ax2.plot(*mean_by(sub, "camera", None, "x.contact_speed")[""], style, color=color)
    _rate_axes(ax, "", log_x=True)
    _near_axes(ax2, "stereo frame rate [Hz] (latency one frame)")
    ax.legend(fontsize=8)
    ax.set_title("Direct mapping vs predictor: catch rate vs camera rate", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def _split(rows, *cols):
    out: dict = {}
    for r in rows:
        out.setdefault(tuple(r.get(c, "") for c in cols), []).append(r)
    return out


# -- one sentence per plot (the report's text), computed from the same table -------------------


def summary_vision(rows: list[dict]) -> str:
    curves = rate_by(rows, "sensors.stereo.rate", "sensors.stereo.latency", caught)
    parts = []
    for lat in sorted(curves, key=float):
        xs, ys = curves[lat]
        parts.append(
            f"latency {float(lat) * 1e3:g} ms: {pct(ys[-1])} at {xs[-1]:g} Hz, "
            f"{pct(ys[0])} at {xs[0]:.0f} Hz"
        )
    return f"Direct mapping ({overall(rows, caught, 'caught')}): " + "; ".join(parts) + "."


def summary_throw_speed(rows: list[dict]) -> str:
    ((xs, ys),) = rate_by(rows, "throw_speed", None, caught).values()
    yes = [f"{x:g}" for x, y in zip(xs, ys) if y > 0]
    sx, sv = mean_by(rows, "throw_speed", None, "x.contact_speed")[""]
    near = ""
    if sv and not np.all(np.isnan(sv)):
        near = (
            f"; the ball met the hand at {sv[0]:.1f} m/s relative to it at {sx[0]:g} m/s "
            f"and {sv[-1]:.1f} m/s at {sx[-1]:g} m/s"
        )
    return (
        f"Caught at {', '.join(yes) or 'no'} m/s of {', '.join(f'{x:g}' for x in xs)} m/s "
        f"({overall(rows, caught, 'caught')}){near}."
    )


def summary_arm_limits(rows: list[dict]) -> str:
    curves = rate_by(rows, "joint_speed_limit", "torque_scale", caught)
    parts = []
    for scale in sorted(curves, key=float):
        xs, ys = curves[scale]
        yes = [f"{x:g}" for x, y in zip(xs, ys) if y > 0]
        parts.append(
            f"torque x{scale}: "
            + (
                f"caught at {', '.join(yes)} rad/s"
                if yes
                else f"no catch from {xs[0]:g} to {xs[-1]:g} rad/s"
            )
        )
    return (
        f"With the speed limit enforced ({overall(rows, caught, 'caught')}): "
        + "; ".join(parts)
        + "."
    )


def summary_direct_vs_predictive(rows: list[dict]) -> str:
    split = _split(rows, "scenario", "kick")
    rates = {k: rate_by(v, "camera", None, caught)[""] for k, v in split.items()}
    xs = sorted({x for v in rates.values() for x in v[0]})
    if not xs:
        return "Not run."

    def at(method, kick, x):
        return rate_at({"": rates.get((method, kick), ([], []))}, "", x)

    hi, lo = xs[-1], xs[0]
    d = [at("catch_optimised", k, x) for k in ("none", "kick") for x in (hi, lo)]
    p = [at("predictive_catch", k, x) for k in ("none", "kick") for x in (hi, lo)]
    text = (
        f"At {hi:g} Hz the direct mapping caught {pct(d[0])} (kick: {pct(d[2])}) and the "
        f"predictor {pct(p[0])} (kick: {pct(p[2])}); at {lo:g} Hz direct {pct(d[1])} "
        f"(kick: {pct(d[3])}), predictor {pct(p[1])} (kick: {pct(p[3])}). "
    )
    speeds = {k: mean_by(v, "camera", None, "x.contact_speed")[""] for k, v in split.items()}
    sd = rate_at({"": speeds.get(("catch_optimised", "none"), ([], []))}, "", hi)
    sp = rate_at({"": speeds.get(("predictive_catch", "none"), ([], []))}, "", hi)
    if not (np.isnan(sd) or np.isnan(sp)):
        text += (
            f"At first hand contact the ball moved at {sd:.1f} m/s relative to the hand "
            f"with the direct mapping and {sp:.1f} m/s with the predictor ({hi:g} Hz, no "
            "kick). "
        )
    per_cell = min(len(v) for v in _split(rows, "scenario", "kick", "camera").values())
    if per_cell < 20:  # a rate from a throw or two is no evidence either way
        return text + (
            f"With {per_cell} throw{'s' if per_cell > 1 else ''} a cell this sweep supports no "
            "conclusion; the shared throw set (python -m analysis.ablation_catch, "
            "data/ablations/catch_shared_throws.md: 20 throws a cell, Wilson intervals) does."
        )
    fast_gap = np.nanmean([d[0] - p[0], d[2] - p[2]])
    slow_gap = np.nanmean([d[1] - p[1], d[3] - p[3]])
    if np.isnan(fast_gap) or (max(np.nanmax(d), np.nanmax(p)) == 0):
        text += "Neither method caught in this sweep, so it cannot test the claim."
    elif fast_gap > 0 and fast_gap > slow_gap:
        text += "The direct mapping's advantage grows with the camera rate, as the paper argues."
    elif fast_gap > 0:
        text += "The direct mapping is ahead, but not more so with fast vision."
    else:
        text += "The direct mapping is not ahead of the predictor here: the claim is not borne out."
    return text


# -- the shared throw set (issue #21): every controller on the same throws ---------------------

SHARED_CONTROLLERS = {
    "initial": "catch_initial",
    "optimised": "catch_optimised",
    "extension (clamp-aware)": "catch_optimised_clamped",
    "predictor": "predictive_catch",
}
KICK = [[0.18, 0.0, 0.02, 0.0]]  # t (s), impulse (N*s): +y, 0.8 m/s on the 25 g ball (assumed)
SHARED_CELLS: dict[str, dict] = {
    # name: (throw-set arguments, scenario overrides); the base cell is the robustness test's
    "base (8-10 m/s, 1 kHz)": {"throws": {}, "set": {}},
    "arrival spread +-0.1 m": {"throws": {"spread": 0.1}, "set": {}},
    "10-11 m/s": {"throws": {"speeds": (10.0, 11.0)}, "set": {}},
    "camera 250 Hz": {
        "throws": {},
        "set": {"sensors.stereo.rate": 250, "sensors.stereo.latency": 0.004},
    },
    "camera 100 Hz": {
        "throws": {},
        "set": {"sensors.stereo.rate": 100, "sensors.stereo.latency": 0.01},
    },
    "latency 5 ms (1 kHz)": {"throws": {}, "set": {"sensors.stereo.latency": 0.005}},
    "mid-flight kick": {"throws": {}, "set": {"plant.params.object_impulses": KICK}},
}


def wilson(k: int, n: int, z: float = 1.959964) -> tuple[float, float]:
    """The Wilson score 95 % interval of a rate k/n (Wilson 1927)."""
    if n == 0:
        return 0.0, 1.0
    p = k / n
    den = 1.0 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return float(max(0.0, mid - half)), float(min(1.0, mid + half))


def rate_cell(k: int, n: int, why) -> str:
    """A table cell of a rate: ``k/n [Wilson 95 % interval]`` and the failures' reasons (``why``:
    a Counter of them), most common first."""
    lo, hi = wilson(k, n)
    fails = "; ".join(f"{v}× {x}" for x, v in why.most_common())
    return f"{k}/{n} [{100 * lo:.0f}–{100 * hi:.0f} %]" + (f" ({fails})" if fails else "")


def run_shared(n: int = 20, seed: int = 20030914, cells=None, controllers=None, out=None, extra=()):
    """Every controller on every cell's n seeded throws (the same throws for all): one row per
    run with the plant's outcome (success, reason). ``out``: a CSV path to write; ``extra``:
    ``--set`` strings applied to every run after the cell's."""
    import csv
    import json
    import tempfile
    from pathlib import Path

    from analysis.ablation_throws import perturbed_throws, throw_overrides
    from replay.runner import Runner
    from replay.scenario import load_scenario

    root = Path(__file__).resolve().parents[1]
    cells = cells or list(SHARED_CELLS)
    controllers = controllers or SHARED_CONTROLLERS
    rows = []
    with tempfile.TemporaryDirectory(prefix="catch-shared-") as tmp:
        for cell in cells:
            spec = SHARED_CELLS[cell]
            throws = perturbed_throws(n, seed, **spec["throws"])
            sets = [f"{k}={json.dumps(v)}" for k, v in spec["set"].items()]
            for label, name in controllers.items():
                for i, th in enumerate(throws):
                    sc = load_scenario(
                        root / "scenarios" / f"{name}.yaml",
                        throw_overrides(th)
                        + sets
                        + list(extra)
                        + ["timing.duration=0.45", "stop.after=0.0"],
                    )
                    o = Runner(sc).run(Path(tmp) / "run.mcap").outcome
                    rows.append(
                        {
                            "cell": cell,
                            "controller": label,
                            "throw": i,
                            "speed": round(th["speed"], 4),
                            "success": bool(o["success"]),
                            "reason": o["reason"],
                            "approach_angle": round(float(o.get("approach_angle", np.nan)), 1),
                            "contact_speed": round(float(o.get("contact_speed", np.nan)), 2),
                        }
                    )
    if out is not None:
        with open(out, "w", newline="", encoding="utf-8") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    return rows


def shared_table(rows: list[dict]) -> str:
    """Markdown: per cell and controller the catch rate with its Wilson 95 % interval and the
    failures' reasons."""
    from collections import Counter

    cells = list(dict.fromkeys(r["cell"] for r in rows))
    ctrls = list(dict.fromkeys(r["controller"] for r in rows))
    lines = ["| cell | " + " | ".join(ctrls) + " |", "|---" * (len(ctrls) + 1) + "|"]
    for cell in cells:
        parts = []
        for c in ctrls:
            sub = [r for r in rows if r["cell"] == cell and r["controller"] == c]
            k = sum(str(r["success"]) in ("True", "true", "1") for r in sub)
            why = Counter(r["reason"] for r in sub if str(r["success"]) not in ("True", "true"))
            parts.append(rate_cell(k, len(sub), why))
        lines.append(f"| {cell} | " + " | ".join(parts) + " |")
    return "\n".join(lines)


if (
    __name__ == "__main__"
):  # python -m analysis.ablation_catch [n]: data/ablations/catch_shared_throws.*
    import sys

    from replay.resources import data_path

    n_throws = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    dest = data_path("ablations")
    table_rows = run_shared(n_throws, out=dest / "catch_shared_throws.csv")
    text = shared_table(table_rows)
    (dest / "catch_shared_throws.md").write_text(text + "\n", encoding="utf-8")
    print(text)
