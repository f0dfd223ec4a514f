"""The stick-capture ablations (sweeps/stick_*.yaml): a metrics function the sweep runs on each
log, and the plots drawn from the tables."""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis.ablation_plot import (  # noqa: E402
    RATE_NOTE,
    plain_log_ticks,
    plot_rates,
    shifts,
)
from analysis.figure_files import save  # noqa: E402
from replay.sweep.table import as_bool, as_float  # noqa: E402


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


# rad/s: eq. 29's "pure translation" holds after its step when |omega| is below this; the plant's
# own "held" test (hold_omega) and the method's capture_spin use the same 0.5 rad/s (our choice,
# the paper gives none; over the 0.1-0.3 s of closing it turns the stick by < 9 deg)
EQ29_TOL = 0.5
EQ29_STEP = {"stick_3step": 2, "stick_2step": 1}  # the collision after which eq. 29 must hold


def run_metrics(log) -> dict:
    """What the table's ``m.`` columns (the outcome: the plant's ``captured``, ``t_capture``;
    the method's ``t_capture_method``) lack, from the truth: the throw, whether the stick's
    centre was still within the hand's reach at the end, when the method's ``capture`` event
    declared it, the stick's motion just after the step that should
    leave eq. 29's pure translation, and the slider workspace and speed used."""
    from analysis.series import events

    out: dict = {}
    for e in events(log, "throw"):
        out.update(v0=e["data"]["speed"], omega0=e["data"]["omega"])
    out["in_reach"] = _in_reach_at_end(log)
    cam = (log.scenario_config().get("sensors") or {}).get("camera") or {}
    if cam.get("rate") is not None:
        out["fps"] = float(cam["rate"])
    out["t_capture_declared"] = next((e["t"] for e in events(log, "capture")), None)
    out.update(_eq29(log, events(log, "collision")))
    hand = log.series("/hand/state")
    if hand:
        t = np.array([h["t"] for h in hand])
        base = np.array([h["base"] for h in hand], dtype=float)
        out["base_x_max"] = float(np.max(np.abs(base[:, 0])))
        out["base_y_max"] = float(np.max(np.abs(base[:, 1])))
        if len(t) > 1:
            v = np.abs(np.diff(base, axis=0)) / np.diff(t)[:, None]
            out["base_speed_max"] = float(np.max(v))
    return out


def _in_reach_at_end(log) -> bool | None:
    """Could the hand still get to the stick where the run ended (``settings.in_reach``)?"""
    from plants.airtable import Params, settings
    from replay.scenario.loader import params_from_data

    states = log.series("/stick/state")
    if not states:
        return None
    p = params_from_data(Params, log.scenario_config()["plant"].get("params"), "plant.params")
    last = states[-1]
    return settings.in_reach(settings.hand_spec(p), p.stick.length, (last["x"], last["y"]))


def _eq29(log, collisions: list[dict]) -> dict:
    """omega and the slip along the stick's axis (s^T v, eq. 29 wants both 0) just after the
    strategy's eq.-29 step: the first collision the method planned as that step."""
    ctrl = (log.scenario_config().get("controller") or {}).get("type")
    step = EQ29_STEP.get(str(ctrl))
    if step is None:
        return {}
    for e in collisions:
        d = e["data"]
        if (d.get("planned") or {}).get("index") == step:
            c, s = math.cos(d["theta"]), math.sin(d["theta"])
            vx, vy = d["v_after"]
            return {
                "omega_eq29": d["omega_after"],
                "slip_eq29": vx * c + vy * s,
                "speed_eq29": math.hypot(vx, vy),
                "clamped_eq29": bool((d.get("planned") or {}).get("clamped")),
            }
    return {}


def truth_captured(row: dict) -> bool:
    """Captured by the physics: the plant's outcome (never the method's own ``capture``)."""
    return as_bool(row.get("m.captured"))


def undecided(row: dict) -> bool:
    """Not captured and the stick still within the hand's reach when the run ended."""
    return not truth_captured(row) and as_bool(row.get("x.in_reach"))


def eq29_holds(row: dict) -> bool:
    w = as_float(row.get("x.omega_eq29"))
    return bool(np.isfinite(w) and abs(w) < EQ29_TOL)


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


# -- the condition sweeps (stick_conditions, stick_factors, stick_workspace, stick_vision) ------


def _wilson(k: int, n: int) -> tuple[float, float]:
    from analysis.catching.ablations import wilson

    return wilson(k, n)


def rate_text(k: int, n: int) -> str:
    """'17/20 (64-95 %)': a rate with its Wilson 95 % interval."""
    if not n:
        return "0/0"
    lo, hi = _wilson(k, n)
    return f"{k}/{n} ({100 * lo:.0f}-{100 * hi:.0f} %)"


def cells(rows: list[dict], *columns: str) -> dict[tuple, list[dict]]:
    """Rows grouped by the values of ``columns``, in first-seen order."""
    out: dict[tuple, list[dict]] = {}
    for r in rows:
        out.setdefault(tuple(r.get(c, "") for c in columns), []).append(r)
    return out


def kn(rows: list[dict], ok=truth_captured) -> tuple[int, int]:
    return sum(bool(ok(r)) for r in rows), len(rows)


def tie(counts: list[tuple[int, int]]) -> bool:
    """Every pair of Wilson 95 % intervals overlaps: no difference the runs can resolve."""
    bounds = [_wilson(k, n) for k, n in counts if n]
    return bool(bounds) and max(lo for lo, _ in bounds) <= min(hi for _, hi in bounds)


def decided_note(rows: list[dict]) -> str:
    """The slowest capture and the runs that ended undecided (none, if the duration suffices)."""
    t = [as_float(r.get("m.t_capture")) for r in rows if truth_captured(r)]
    end = max((as_float(r.get("t_end")) for r in rows), default=float("nan"))
    slow = f"slowest capture at {max(t):.2f} s" if t else "no capture"
    return f"{slow}, {sum(undecided(r) for r in rows)} of {len(rows)} runs undecided (runs up to {end:.1f} s)"


def _strategy(r: dict) -> str:
    return {"stick_3step": "3-step", "stick_2step": "2-step"}.get(r.get("scenario", ""), "3-step")


def _rate_axes(ax, xlabel: str) -> None:
    ax.set_ylim(-0.05, 1.05)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(f"capture rate k/n\n({RATE_NOTE})", fontsize=8)
    ax.grid(True, alpha=0.3)


def plot_conditions(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, (ax, ax_w) = plt.subplots(2, 1, sharex=True, figsize=(6.4, 6.0))
    groups = cells(rows, "scenario", "plant.params.stick.collision_width")
    for (sc, w), dx in zip(sorted(groups), shifts(len(groups), 0.02)):
        sub = groups[(sc, w)]
        by_mu = cells(sub, "plant.params.stick.friction")
        mus = sorted(by_mu, key=lambda m: float(m[0]))
        xs = [float(m[0]) for m in mus]
        counts = [kn(by_mu[m]) for m in mus]
        fmt = "o-" if _strategy(sub[0]) == "3-step" else "s--"
        label = f"{_strategy(sub[0])}, W = {float(w) * 1e3:g} mm"
        line = plot_rates(ax, xs, [k for k, _ in counts], [n for _, n in counts], fmt, label, dx)
        med, q1, q3 = [], [], []
        for m in mus:
            w29 = np.abs([as_float(r.get("x.omega_eq29")) for r in by_mu[m]])
            w29 = w29[np.isfinite(w29)]
            med.append(np.median(w29) if len(w29) else np.nan)
            q1.append(np.percentile(w29, 25) if len(w29) else np.nan)
            q3.append(np.percentile(w29, 75) if len(w29) else np.nan)
        xw = np.array(xs) + dx
        ax_w.errorbar(
            xw,
            med,
            yerr=[np.array(med) - q1, np.array(q3) - med],
            fmt=fmt,
            capsize=3,
            color=line[0].get_color(),
            label=label,
        )
    ax_w.axhline(EQ29_TOL, color="k", lw=0.8, ls=":", label=f"eq. 29 tolerance {EQ29_TOL:g} rad/s")
    _rate_axes(ax, "")
    ax.legend(fontsize=7)
    ax.set_title("Capture rate vs friction μ and width W (20 random throws a point)", fontsize=10)
    ax_w.set_ylabel("|ω| after the eq.-29 step [rad/s]\n(median, quartiles)", fontsize=8)
    ax_w.set_xlabel("friction coefficient μ")
    ax_w.grid(True, alpha=0.3)
    ax_w.legend(fontsize=7)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_conditions(rows: list[dict]) -> str:
    parts = []
    for (sc, w), sub in sorted(
        cells(rows, "scenario", "plant.params.stick.collision_width").items()
    ):
        by_mu = cells(sub, "plant.params.stick.friction")
        mus = sorted(by_mu, key=lambda m: float(m[0]))
        counts = [kn(by_mu[m]) for m in mus]
        rates = ", ".join(f"μ {float(m[0]):g}: {rate_text(*c)}" for m, c in zip(mus, counts))
        verdict = "tie across μ" if tie(counts) else "differs with μ"
        parts.append(f"{_strategy(sub[0])}, W = {float(w) * 1e3:g} mm: {rates} ({verdict})")
    return "Captured (physics): " + "; ".join(parts) + f"; {decided_note(rows)}."


def _factor_order(rows: list[dict]) -> list[str]:
    return list(dict.fromkeys(r.get("factor", "") for r in rows))


def plot_factors(rows: list[dict], out: Path, stem: str) -> list[Path]:
    names = _factor_order(rows)
    groups = cells(rows, "factor")
    fig, ax = plt.subplots(figsize=(7.2, 4.4))
    ys = np.arange(len(names))[::-1]
    for i, (name, y) in enumerate(zip(names, ys)):
        for ok, fmt, off, label in (
            (truth_captured, "o", 0.12, "captured (physics)"),
            (eq29_holds, "^", -0.12, f"eq. 29 after step 2 (|ω₂| < {EQ29_TOL:g} rad/s)"),
        ):
            k, n = kn(groups[(name,)], ok)
            lo, hi = _wilson(k, n)
            ax.errorbar(
                [k / n],
                [y + off],
                xerr=[[k / n - lo], [hi - k / n]],
                fmt=fmt,
                capsize=3,
                color="C0" if ok is truth_captured else "C1",
                label=label if i == 0 else None,
            )
    ax.set_yticks(ys, [f"{nm} (n = {len(groups[(nm,)])})" for nm in names], fontsize=8)
    ax.set_xlim(-0.05, 1.05)
    ax.set_xlabel(f"rate k/n ({RATE_NOTE})", fontsize=8)
    ax.grid(True, axis="x", alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2)
    ax.set_title("3-step strategy: one condition changed at a time", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_factors(rows: list[dict]) -> str:
    groups = cells(rows, "factor")
    parts = [
        f"{nm}: {rate_text(*kn(groups[(nm,)]))}, eq. 29 held {rate_text(*kn(groups[(nm,)], eq29_holds))}"
        for nm in _factor_order(rows)
    ]
    return "Captured (physics): " + "; ".join(parts) + f"; {decided_note(rows)}."


def _median(rows: list[dict], column: str) -> float:
    v = np.array([as_float(r.get(column)) for r in rows])
    v = v[np.isfinite(v)]
    return float(np.median(v)) if len(v) else float("nan")


def plot_workspace(rows: list[dict], out: Path, stem: str) -> list[Path]:
    limits = list(dict.fromkeys(r.get("slider", "") for r in rows))
    groups = cells(rows, "scenario", "slider")
    fig, (ax, ax_u) = plt.subplots(2, 1, sharex=True, figsize=(6.8, 6.0))
    xs = np.arange(len(limits))
    for sc, fmt, dx in (("stick_3step", "o-", -0.06), ("stick_2step", "s--", 0.06)):
        counts = [kn(groups.get((sc, lim), [])) for lim in limits]
        label = _strategy({"scenario": sc})
        line = plot_rates(ax, xs, [k for k, _ in counts], [n for _, n in counts], fmt, label, dx)
        c = line[0].get_color()
        sub = [groups.get((sc, lim), []) for lim in limits]
        ax_u.plot(
            xs + dx,
            [_median(g, "x.base_x_max") for g in sub],
            fmt,
            color=c,
            label=f"{label}: |x| max [m]",
        )
        ax_u.plot(
            xs + dx,
            [_median(g, "x.base_y_max") for g in sub],
            fmt[1:] + "x",
            color=c,
            alpha=0.5,
            label=f"{label}: |y| max [m]",
        )
        ax_u.plot(
            xs + dx,
            [_median(g, "x.base_speed_max") for g in sub],
            "d:",
            color=c,
            label=f"{label}: peak axis speed [m/s]",
        )
    _rate_axes(ax, "")
    ax.legend(fontsize=7)
    ax.set_title("2-step vs 3-step under the slider's limits (Sec. III-C)", fontsize=10)
    ax_u.set_xticks(xs, limits, fontsize=7)
    ax_u.set_ylabel("used by the slider (median)", fontsize=8)
    ax_u.set_xlabel("slider travel (each axis) and speed limit")
    ax_u.grid(True, alpha=0.3)
    ax_u.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_workspace(rows: list[dict]) -> str:
    groups = cells(rows, "slider", "scenario")
    parts = []
    for lim in dict.fromkeys(r.get("slider", "") for r in rows):
        c3, c2 = kn(groups.get((lim, "stick_3step"), [])), kn(groups.get((lim, "stick_2step"), []))
        verdict = (
            "tie"
            if tie([c3, c2])
            else (
                "3-step higher"
                if c3[0] / max(c3[1], 1) > c2[0] / max(c2[1], 1)
                else "2-step higher"
            )
        )
        parts.append(f"{lim}: 3-step {rate_text(*c3)}, 2-step {rate_text(*c2)} ({verdict})")
    return "Captured (physics) on the same throws: " + "; ".join(parts) + f"; {decided_note(rows)}."


def _vision_rule(r: dict) -> str:
    label = r.get("camera", "")
    return "seconds" if "seconds" in label else ("samples" if "samples" in label else "both")


def _vision_curves(rows: list[dict]) -> dict[str, tuple[list[float], list[tuple[int, int]]]]:
    """{rule: (frame rates, (k, n) at each)}; the 300 fps runs (both rules) join both lines."""
    out = {}
    for rule in ("seconds", "samples"):
        sub = [r for r in rows if _vision_rule(r) in (rule, "both")]
        by = cells(sub, "x.fps")
        fps = sorted(by, key=lambda f: float(f[0]))
        out[rule] = ([float(f[0]) for f in fps], [kn(by[f]) for f in fps])
    return out


def plot_vision(rows: list[dict], out: Path, stem: str) -> list[Path]:
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    labels = {
        "seconds": "estimator spans kept in seconds (fair rule)",
        "samples": "estimator spans in frames (as shipped)",
    }
    for (rule, (xs, counts)), dx, fmt in zip(
        _vision_curves(rows).items(), shifts(2, 0.02), ("o-", "s--")
    ):
        plot_rates(
            ax,
            xs,
            [k for k, _ in counts],
            [n for _, n in counts],
            fmt,
            labels[rule],
            dx,
            log_x=True,
        )
    ax.axvline(300, color="0.5", lw=0.8, ls=":", label="paper: 300 fps")
    ax.set_xscale("log")
    plain_log_ticks(ax)
    ax.set_xticks(sorted({x for xs, _ in _vision_curves(rows).values() for x in xs}))
    _rate_axes(ax, "camera frame rate [Hz] (latency one frame, pixel noise σ = 10)")
    ax.legend(fontsize=8)
    ax.set_title("3-step strategy: capture rate vs vision rate", fontsize=10)
    fig.tight_layout()
    return save(fig, out, stem)


def summary_vision(rows: list[dict]) -> str:
    parts = []
    for rule, (xs, counts) in _vision_curves(rows).items():
        parts.append(
            f"spans in {rule}: "
            + ", ".join(f"{x:g} fps {rate_text(*c)}" for x, c in zip(xs[::-1], counts[::-1]))
        )
    return "Captured (physics): " + "; ".join(parts) + f"; {decided_note(rows)}."


# -- the thesis (the report's "Theses" section) --------------------------------------------------

THESIS = (
    "Higashimori et al. 2007: friction-independent collisions let the 2-step and 3-step "
    "strategies capture a thin stick whatever the friction coefficient mu (Sec. III; the "
    "3-step one shown at 300 fps, Sec. IV)."
)
THESIS_SWEEPS = ("stick_conditions", "stick_factors", "stick_workspace", "stick_vision")


def _stored_rows(name: str) -> list[dict]:
    from replay.sweep.ablations import table_path
    from replay.sweep.table import read_table

    path, _ = table_path(name)
    return read_table(path) if path is not None else []


def _strict_three_steps(factors: dict, numbers: dict) -> bool | None:
    """Does the 3-step capture as often with only the paper's three collisions as with the
    method's added spin stops (a tie)? None when the factor sweep lacks the two levels."""
    base, strict = factors.get(("default",)), factors.get(("3 steps only",))
    if not base or not strict:
        return None
    numbers["3-step: default vs 3 steps only"] = {
        "default": rate_text(*kn(base)),
        "3 steps only": rate_text(*kn(strict)),
    }
    return tie([kn(base), kn(strict)])


def thesis(tables: dict[str, list[dict]] | None = None) -> dict:
    """The verdict on the friction independence of the capture, from the stored tables
    (``tables``: {sweep name: rows}; a sweep left out is read from data/ablations/ or a fresh
    out/ablations/ run): per strategy and width, whether the capture rates over mu tie (every
    pair of Wilson 95 % intervals overlaps), and beside it how often eq. 29's pure translation
    held after its step. "holds" when every cell ties over mu at both widths and captures
    most throws (lower bound >= 50 %); "holds only when ..." when that is so only at zero
    width, or when the 3-step's rate with only the paper's three collisions (stick_factors'
    "3 steps only") does not tie with the method's (which adds spin stops); "does not hold"
    when it fails at zero width too."""
    tables = dict(tables or {})
    for name in THESIS_SWEEPS:
        if name not in tables:
            tables[name] = _stored_rows(name)
    rows = tables["stick_conditions"]
    numbers: dict = {}
    ok_by_width: dict[float, bool] = {}
    for (sc, w), sub in sorted(
        cells(rows, "scenario", "plant.params.stick.collision_width").items()
    ):
        by_mu = cells(sub, "plant.params.stick.friction")
        counts = [kn(by_mu[m]) for m in sorted(by_mu, key=lambda m: float(m[0]))]
        lows = [_wilson(k, n)[0] for k, n in counts]
        width = float(w)
        good = tie(counts) and min(lows) >= 0.5
        ok_by_width[width] = ok_by_width.get(width, True) and good
        key = f"{_strategy(sub[0])} W={width * 1e3:g}mm"
        numbers[key] = {
            f"mu={float(m[0]):g}": rate_text(*c)
            for m, c in zip(sorted(by_mu, key=lambda m: float(m[0])), counts)
        }
        numbers[key]["tie over mu"] = tie(counts)
        numbers[key]["eq29 held"] = rate_text(*kn(sub, eq29_holds))
    factors = cells(tables["stick_factors"], "factor")
    numbers["eq29 after step 2 (3-step)"] = {
        nm[0]: rate_text(*kn(g, eq29_holds))
        for nm, g in factors.items()
        if "e = " in nm[0] or nm[0] == "default"
    }
    strict = _strict_three_steps(factors, numbers)
    if not ok_by_width:
        verdict = "not run"
    elif not ok_by_width.get(0.0):
        verdict = "does not hold"
    else:
        when = (
            [] if all(ok_by_width.values()) else ["the width is negligible (W = 0, Assumption 5)"]
        )
        if strict is False:
            when.append(
                "the 3-step method may add spin-stop collisions beyond the paper's three "
                "(eq. 29 fails at step 2 with the paper's m, I, e)"
            )
        verdict = "holds only when " + " and ".join(when) if when else "holds"
    if rows:
        numbers["undecided runs"] = sum(undecided(r) for r in rows)
    for rule, (xs, counts) in _vision_curves(tables["stick_vision"]).items():
        if xs:
            numbers[f"camera, estimator spans in {rule}"] = {
                **{f"{x:g} fps": rate_text(*c) for x, c in zip(xs[::-1], counts[::-1])},
                "tie over rates": tie(counts),
            }
    slider = cells(tables["stick_workspace"], "slider", "scenario")
    if slider:
        numbers["slider (Sec. III-C)"] = {
            f"{lim} {_strategy({'scenario': sc})}": rate_text(*kn(g))
            for (lim, sc), g in slider.items()
        }
    return {
        "thesis": THESIS,
        "verdict": verdict,
        "numbers": numbers,
        "figure": "ablation_stick_conditions.png",
    }
