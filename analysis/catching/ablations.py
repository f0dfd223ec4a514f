"""Plots of the catching ablations (sweeps/catch_*.yaml), each drawn from its sweep table."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import numpy as np  # noqa: E402

from analysis.ablation_table import (  # noqa: E402
    caught,
    mean_by,
    overall,
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
from replay.sweep.results import wilson  # noqa: E402


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


def _split(rows, *cols):
    out: dict = {}
    for r in rows:
        out.setdefault(tuple(r.get(c, "") for c in cols), []).append(r)
    return out


# -- one sentence per plot (the report's text), computed from the same table -------------------


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


# -- the rate study (sweeps/catch_rate.yaml, issue #38) ----------------------------------------

RATE_PERIODS_MS = (1, 2, 5, 10, 15, 20, 33)  # loop periods: each a whole number of 1 ms steps
RATE_DESIGN_PERIOD = 0.001  # s: the period the scenarios' PD gains were tuned at
RATE_THROWS = 20  # held-out throws a cell (catch_shared_throws' "arrival spread +-0.1 m")
RATE_SEED = 20030914
RATE_SPREAD = 0.1  # m
BALLISTIC, FREE, PREDICTOR = "catch_optimised", "prediction_free_catch", "predictive_catch"
RATE_CONTROLLERS = {
    BALLISTIC: "direct (ballistic fit)",
    FREE: "direct, prediction-free",
    PREDICTOR: "predict-then-intercept",
}
RATE_MOTIONS = {"spread": "throw spread", "spread+kick": "throw spread + mid-flight kick"}


def sampled_pd_poles(kp: float, kd: float, inertia: float, period: float) -> np.ndarray:
    """The closed-loop poles (z-plane) of one joint under PD sampled every ``period`` with the
    torque held in between (the runner's zero-order hold; encoders read at the control step):
    e = q - q_d of I e'' = -(kp e + kd e') over one period, x = (e, e'),
    x+ = [[1 - kp T^2 / 2I, T - kd T^2 / 2I], [-kp T / I, 1 - kd T / I]] x."""
    a, b = kp * period / inertia, kd * period / inertia
    phi = np.array([[1.0 - a * period / 2.0, period * (1.0 - b / 2.0)], [-a, 1.0 - b]])
    return np.linalg.eigvals(phi)


def step_response(kp: float, kd: float, inertia: float, period: float, duration: float = 0.3):
    """(t, e): the sampled joint loop of :func:`sampled_pd_poles` from e = 1 rad at rest."""
    a, b = kp * period / inertia, kd * period / inertia
    phi = np.array([[1.0 - a * period / 2.0, period * (1.0 - b / 2.0)], [-a, 1.0 - b]])
    n = int(round(duration / period))
    x, e = np.array([1.0, 0.0]), [1.0]
    for _ in range(n):
        x = phi @ x
        e.append(float(x[0]))
    return period * np.arange(n + 1), np.array(e)


def plot_gain_rule(out: Path, stem: str = "catch_rate_steps") -> list[Path]:
    """The step responses the rule gives at every period (one panel per joint), beside the
    scenarios' fixed 1 ms gains at 33 ms (docs/catching.md)."""
    from replay.scenario import load_scenario

    from replay.resources import scenario_dir

    controller: Any = load_scenario(scenario_dir() / f"{BALLISTIC}.yaml").controller
    params = controller.params
    inertias = joint_inertias()
    fig, axes = plt.subplots(1, len(inertias), sharey=True, figsize=(10.0, 3.4))
    for ax, (j, inertia) in zip(axes, inertias.items()):
        for T_ms, c in zip(RATE_PERIODS_MS, plt.cm.viridis(np.linspace(0, 0.9, 7))):
            kp, kd = rate_gains(params.kp[j], params.kd[j], inertia, T_ms * 1e-3)
            ax.step(
                *step_response(kp, kd, inertia, T_ms * 1e-3),
                where="post",
                color=c,
                label=f"{T_ms} ms, rule",
            )
        t, e = step_response(params.kp[j], params.kd[j], inertia, 0.033)
        ax.step(t, e, "--", where="post", color="tab:red", label="33 ms, 1 ms gains")
        ax.set_title(f"J{j + 1} (I = {inertia:.3f} kg m^2)", fontsize=9)
        ax.set_xlabel("t [s]")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("joint error e [rad] from 1 rad")
    axes[-1].legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out, stem)


def rate_gains(
    kp: float, kd: float, inertia: float, period: float, design: float = RATE_DESIGN_PERIOD
) -> tuple[float, float]:
    """The fair-ablation rule: the gains that give the joint sampled at ``period`` the closed-loop
    poles of the ``design``-period loop, matched (z = exp(s T), s = ln(z_design) / T_design): the
    same natural frequency and damping at every period (kp, kd returned at T = design).

    Derivation: with sigma = z1 + z2 and p = z1 z2 the characteristic polynomial of
    :func:`sampled_pd_poles` is z^2 - (2 - kp T^2 / 2I - kd T / I) z + (1 - kd T / I +
    kp T^2 / 2I), so kp = I (1 - sigma + p) / T^2 and kd = I (3 - p - sigma) / (2 T)."""
    s = np.log(sampled_pd_poles(kp, kd, inertia, design).astype(complex)) / design
    z = np.exp(s * period)
    sigma, p = float(np.real(z.sum())), float(np.real(np.prod(z)))
    return inertia * (1.0 - sigma + p) / period**2, inertia * (3.0 - p - sigma) / (2.0 * period)


def joint_inertias(scenario: str = "catch_optimised") -> dict[int, float]:
    """The active joints' effective inertias (kg m^2): the diagonal of the arm model's M(q) at
    the initial posture (hand and ball included as the controller's model has them)."""
    from replay.runner import Runner
    from replay.scenario import load_scenario

    from replay.resources import scenario_dir

    ctl: Any = Runner(load_scenario(scenario_dir() / f"{scenario}.yaml")).controller
    model = ctl.model
    act = [int(i) for i in model.active]
    mass = model.mass(np.asarray(ctl.q_init, float)[act])
    return {i: float(mass[k, k]) for k, i in enumerate(act)}


def _rate_counts(rows: list[dict]) -> dict[tuple[str, str], dict[float, tuple[int, int]]]:
    """{(scenario, motion): {period in ms: (caught k, runs n)}} of the catch_rate table."""
    out: dict = {}
    for (scenario, motion), sub in _split(rows, "scenario", "motion").items():
        ((xs, ks, ns),) = counts_by(sub, "period_ms", None, caught).values()
        out[(scenario, motion)] = {x: (k, n) for x, k, n in zip(xs, ks, ns)}
    return out


def plot_rate(rows: list[dict], out: Path, stem: str) -> list[Path]:
    """Catch rate against the loop period, one line per controller, one panel per motion."""
    counts = _rate_counts(rows)
    motions = [m for m in RATE_MOTIONS if any(k[1] == m for k in counts)]
    motions += sorted({k[1] for k in counts} - set(motions))
    fig, axes = plt.subplots(1, max(1, len(motions)), sharey=True, figsize=(10.0, 4.2))
    axes = np.atleast_1d(axes)
    colours = dict(zip(RATE_CONTROLLERS, ("tab:blue", "tab:green", "tab:orange")))
    names = [c for c in RATE_CONTROLLERS if any(k[0] == c for k in counts)]
    names += sorted({k[0] for k in counts} - set(names))
    for ax, motion in zip(axes, motions):
        for name, dx in zip(names, shifts(len(names), 0.015)):
            cell = counts.get((name, motion))
            if not cell:
                continue
            xs = sorted(cell)
            plot_rates(
                ax,
                xs,
                [cell[x][0] for x in xs],
                [cell[x][1] for x in xs],
                "o-",
                RATE_CONTROLLERS.get(name, name),
                dx,
                log_x=True,
                color=colours.get(name, "0.4"),
            )
        _rate_axes(ax, "loop period T [ms] (stereo 1/T, latency T, control 1/T)", log_x=True)
        ax.set_title(RATE_MOTIONS.get(motion, motion), fontsize=10)
    for ax in axes[1:]:
        ax.set_ylabel("")
    axes[0].legend(fontsize=7, loc="lower left")
    fig.suptitle(
        "Catch rate vs loop period, gains re-tuned per period (matched poles)", fontsize=10
    )
    fig.tight_layout()
    return save(fig, out, stem)


def _k_n(cell: dict, x: float) -> str:
    k, n = cell.get(x, (0, 0))
    lo, hi = wilson(k, n)
    return f"{k}/{n} [{100 * lo:.0f}-{100 * hi:.0f} %]"


def _ties_up_to(cell: dict) -> float:
    """The longest period up to which every period's catch interval overlaps the fastest's."""
    xs = sorted(cell)
    lo0, hi0 = wilson(*cell[xs[0]])
    last = xs[0]
    for x in xs[1:]:
        lo, hi = wilson(*cell[x])
        if hi < lo0 or lo > hi0:
            break
        last = x
    return last


def _against(a: tuple[int, int], b: tuple[int, int]) -> str:
    """'ahead of' / 'tied with' / 'behind': rate a against b by their Wilson 95 % intervals."""
    lo_a, hi_a = wilson(*a)
    lo_b, hi_b = wilson(*b)
    return "ahead of" if lo_a > hi_b else "behind" if hi_a < lo_b else "tied with"


def thesis(tables: dict[str, list[dict]]) -> dict:
    """Namiki & Ishikawa's thesis from the stored catch_rate table: does the direct mapping catch
    without prediction, and is the fast loop what makes it work? Per motion level the
    prediction-free mapping works if at the fastest period it catches at least half the throws
    and is not behind the ballistic default (Wilson 95 % intervals disjoint: ahead / behind;
    overlapping: a tie); the longest period up to which it ties with its fastest rate says where
    the thesis stops."""
    counts = _rate_counts(tables.get("catch_rate", []))
    parts: list[str] = []
    works, spans, ahead_of_both = {}, {}, {}
    for motion, label in RATE_MOTIONS.items():
        f, b, p = (counts.get((c, motion), {}) for c in (FREE, BALLISTIC, PREDICTOR))
        if not f or not b or not p:
            continue
        fast, slow = min(f), max(f)
        k, n = f[fast]
        works[motion] = n > 0 and k / n >= 0.5 and _against(f[fast], b[fast]) != "behind"
        spans[motion] = _ties_up_to(f)
        ahead_of_both[motion] = all(_against(f[fast], o[fast]) == "ahead of" for o in (b, p))
        after = [x for x in sorted(f) if x > spans[motion]][:1]  # where it stops tying
        parts.append(
            f"{label}: at {fast:g} ms prediction-free {_k_n(f, fast)} ({_against(f[fast], b[fast])}"
            f" the ballistic fit's {_k_n(b, fast)}, {_against(f[fast], p[fast])} the predictor's "
            f"{_k_n(p, fast)}); tied with its {fast:g} ms rate up to {spans[motion]:g} ms; "
            + "; ".join(
                f"at {x:g} ms prediction-free {_k_n(f, x)}, ballistic {_k_n(b, x)}, predictor "
                f"{_k_n(p, x)}"
                for x in dict.fromkeys(after + [slow])
            )
        )
    if not works:
        return {
            "verdict": "not run",
            "numbers": "run `replay ablate catch_rate`",
            "figure": "catch_rate",
        }
    ok = [m for m, w in works.items() if w]
    ahead = [m for m in ok if ahead_of_both.get(m)]
    beats = "".join(
        f"; under the {RATE_MOTIONS[m]} the prediction-free mapping is ahead of the ballistic "
        "fit and the predictor"
        for m in ahead
    )
    slowest = max(max(f) for (c, _), f in counts.items() if c == FREE)
    span = min(spans[m] for m in ok) if ok else 0.0
    if not ok:
        verdict = "does not hold: without prediction the direct mapping does not catch"
    elif len(ok) < len(works):
        verdict = (
            "holds only when "
            + " and ".join(f"the motion is the {RATE_MOTIONS[m]}" for m in ok)
            + (f" and the loop period is <= {span:g} ms" if span < slowest else "")
            + beats
        )
    elif span < slowest:
        verdict = f"holds only when the loop period is <= {span:g} ms" + beats
    else:
        verdict = (
            f"holds only in part: no prediction is needed, but no ~1 kHz loop either "
            f"({slowest:g} ms ties with the fastest)"
        )
    return {"verdict": verdict, "numbers": "; ".join(parts) + ".", "figure": "catch_rate"}


def summary_rate(rows: list[dict]) -> str:
    said = thesis({"catch_rate": rows})
    return f"The thesis {said['verdict']}. {said['numbers']}"


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

    from analysis.catching.throws import perturbed_throws, throw_overrides
    from replay.runner import Runner
    from replay.scenario import load_scenario

    from replay.resources import scenario_dir

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
                        scenario_dir() / f"{name}.yaml",
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
):  # python -m analysis.catching.ablations [n]: data/ablations/catch_shared_throws.*
    import sys

    from replay.resources import data_path

    n_throws = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    dest = data_path("ablations")
    table_rows = run_shared(n_throws, out=dest / "catch_shared_throws.csv")
    text = shared_table(table_rows)
    (dest / "catch_shared_throws.md").write_text(text + "\n", encoding="utf-8")
    print(text)
