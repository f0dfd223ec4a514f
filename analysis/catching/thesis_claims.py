"""Namiki & Ishikawa 2003's optimisation claim (Figs. 6, 8, 9: eq. 25 removes "useless
movement") tested fairly, in two regimes (issue #21):

- the paper's 8-10 m/s (``catch_optimised`` vs ``catch_initial``, the 9 m/s throw), where no
  alpha meets eq. 22 under the assumed (60, 60, 30) N*m limits: rows of kind "measured" (they
  count), Figs. 8 and 9 only (Fig. 6 and the catch are rows of ``analysis.catching.claims``);
- 4-5 m/s (``catch_5ms_optimised`` vs ``catch_5ms_initial``), OUTSIDE the paper's stated speeds,
  where eq. 22 can hold: rows of kind "other regime" (shown, never counted).

The clamp-aware eq. 25 (``catch_optimised_clamped``, not in the paper) gives rows of kind
"extension".

Every run quantity is read from the plant's truth over the window t0 -> first contact: t0 the
first control step with a ball measurement (``/catching/state``), first contact the plant's
first ball-robot ``contact`` event (no figure window runs past it). Joint travel is sum |dq| of
``/arm/joint_state`` positions, torque its ``effort`` (what PyBullet applied: the clamped
command), on the active joints J1, J2, J4. A relative difference within ``TIE`` is a tie.

The model rows evaluate the optimiser's own eq.-17 torque along the nominal throw of its sample
set (``Objective.torques``), unclamped (what eq. 25 weighs) and clamped at the limits (what the
arm can deliver), for alpha_initial and alpha_optimised, against the run's applied torque: they
say *why* the runs come out as they do: status "note" (not verdicts), of their regime's kind.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from analysis.claims import Claim, Falsifier
from analysis.series import events
from replay.log import LogReader
from replay.messages import TOPIC_ARM_JOINT_STATE, TOPIC_CATCHING_STATE, TOPIC_OPTIMIZATION_COST

ACTIVE = [0, 1, 3]  # J1, J2, J4 (J3 locked, Sec. IV-A)
TIE = 0.02  # relative difference below which optimised and initial are a tie (our choice)
ROOT = Path(__file__).resolve().parents[2]


class Pair(NamedTuple):
    regime: str
    optimised: str  # scenario names
    initial: str
    kind: str  # the rows' kind (analysis/claims.py): "measured" only in the paper's regime


PAIRS = (
    Pair("8-10 m/s (paper)", "catch_optimised", "catch_initial", "measured"),
    Pair(
        "4.5 m/s (outside the paper's 8-10 m/s)",
        "catch_5ms_optimised",
        "catch_5ms_initial",
        "other regime",
    ),
)


def window_effort(log: LogReader) -> dict | None:
    """Over [t0, first contact] from the plant's truth: joint travel (rad, per joint and sum),
    sum tau^2 dt (N^2 m^2 s, per joint and sum) and RMS applied torque (N*m), t0 and t_contact."""
    cs = log.series(TOPIC_CATCHING_STATE)
    contact = next(iter(events(log, "contact")), None)
    if not cs or contact is None:
        return None
    t0, t1 = float(cs[0]["t"]), float(contact["t"])
    js = [m for m in log.series(TOPIC_ARM_JOINT_STATE) if t0 - 1e-9 <= m["t"] <= t1 + 1e-9]
    if len(js) < 3:
        return None
    t = np.array([m["t"] for m in js])
    q = np.array([m["position"] for m in js])[:, ACTIVE]
    tau = np.array([m["effort"] for m in js])[:, ACTIVE]
    dt = np.diff(t)
    travel = np.sum(np.abs(np.diff(q, axis=0)), axis=0)
    sq = np.sum(tau[1:] ** 2 * dt[:, None], axis=0)  # sum tau^2 dt, left samples dropped
    return {
        "t0": t0,
        "t_contact": t1,
        "travel": travel,
        "travel_sum": float(np.sum(travel)),
        "tau_sq_dt": sq,
        "tau_sq_dt_sum": float(np.sum(sq)),
        "tau_rms": float(np.sqrt(np.mean(tau**2))),
        "caught": bool(events(log, "catch")),
    }


def compare(a: float, b: float, tie: float = TIE) -> str:
    """'reproduced' if a < b beyond the tie band, 'tie' within it, else 'differs'."""
    if abs(a - b) <= tie * abs(b):
        return "tie"
    return "reproduced" if a < b else "differs"


def _pct(a: float, b: float) -> str:
    return f"{100.0 * (a / b - 1.0):+.1f} %"


def _fmt3(x) -> str:
    return "(" + ", ".join(f"{v:.2f}" for v in x) + ")"


def model_torques(name: str) -> dict | None:
    """The optimiser's eq.-17 torque along the nominal throw of the scenario's sample set, for
    alpha_initial and alpha_optimised: RMS unclamped and clamped at the limits (N*m), and the
    last sample's share (t = t_c) of the unclamped torque cost. From the scenario file (the
    alpha file it names), evaluated on the arm model; None if the scenario is absent."""
    from replay.runner import Runner
    from replay.scenario import load_scenario

    path = ROOT / "scenarios" / f"{name}.yaml"
    if not path.is_file():
        return None
    runner = Runner(load_scenario(path))
    try:
        ctrl: Any = runner.controller  # a CatchingController (the scenario's type)
        prob = ctrl.problem
        obj = prob.objective
        n = prob.config.n_samples
        k = prob.throws.nominal
        alphas = {"initial": ctrl.alpha0}
        if ctrl.alpha_opt is not None:
            alphas["optimised"] = ctrl.alpha_opt
        lim = np.asarray(obj.tau_max, float)
        out: dict = {"limits": lim}
        for label, alpha in alphas.items():
            tau = obj.torques(alpha)[k * n : (k + 1) * n]
            cost = np.sum(obj.kt * tau**2, axis=1)
            clamped = np.clip(tau, -lim, lim)
            out[label] = {
                "rms": float(np.sqrt(np.mean(tau**2))),
                "rms_clamped": float(np.sqrt(np.mean(clamped**2))),
                "last_share": float(cost[-1] / np.sum(cost)),
                "peak": np.max(np.abs(tau), axis=0),
            }
        return out
    finally:
        runner.plant.close()


def _cost_row(log: LogReader, regime: str, kind: str) -> Claim:
    costs = sorted(log.series(TOPIC_OPTIMIZATION_COST), key=lambda c: c["iteration"])
    q = f"{regime}: optimisation lowers both costs, first vs last iterate (Fig. 6)"
    if len(costs) < 2:
        return Claim(
            q, "Σ τᵀK_τ τ and Σ ωᵀK_ω ω reduced", "(no cost history)", "not run", kind=kind
        )
    tc0, tc1 = costs[0]["torque_cost"], costs[-1]["torque_cost"]
    vc0, vc1 = costs[0]["velocity_cost"], costs[-1]["velocity_cost"]
    st_t, st_v = compare(tc1, tc0), compare(vc1, vc0)
    status = (
        "reproduced"
        if st_t == st_v == "reproduced"
        else ("tie" if "tie" in (st_t, st_v) else "differs")
    )
    return Claim(
        q,
        "Σ τᵀK_τ τ and Σ ωᵀK_ω ω reduced",
        f"torque cost {tc0:.1f} → {tc1:.1f} ({_pct(tc1, tc0)}), velocity cost {vc0:.1f} → "
        f"{vc1:.1f} ({_pct(vc1, vc0)}) in {len(costs) - 1} iterations",
        status,
        "the optimiser's model costs (unclamped eq.-17 torque over the sample set)",
        kind=kind,
        measures=(f"{_name(log)}:optimisation costs",),
    )


def _name(log: LogReader) -> str:
    return str(log.scenario().get("name", "?"))


def _pair_rows(pair: Pair, opt: LogReader, ini: LogReader) -> list[Claim]:
    """Figs. 8 and 9 (and, outside the paper's regime, whether both mappings catch)."""
    regime, kind = pair.regime, pair.kind
    a, b = window_effort(opt), window_effort(ini)
    if a is None or b is None:
        return [
            Claim(
                f"{regime}: optimised vs initial motion (Figs. 8, 9)",
                "optimised moves less",
                "a run has no ball measurement or no contact",
                "not run",
                kind=kind,
            )
        ]
    win = (
        f"; t0 → first contact: {a['t0']:.3f} → {a['t_contact']:.3f} s optimised, "
        f"{b['t0']:.3f} → {b['t_contact']:.3f} s initial"
    )
    tie = f"tie if within {100 * TIE:g} %"
    both = (pair.optimised, pair.initial)
    rows = [
        Claim(
            f"{regime}: joint travel Σ‖Δq‖ before first contact (Fig. 8)",
            "smaller when optimised",
            f"optimised {a['travel_sum']:.3f} rad {_fmt3(a['travel'])} vs initial "
            f"{b['travel_sum']:.3f} rad {_fmt3(b['travel'])} (J1, J2, J4): "
            f"{_pct(a['travel_sum'], b['travel_sum'])}{win}",
            compare(a["travel_sum"], b["travel_sum"]),
            f"plant truth (/arm/joint_state); {tie}",
            kind=kind,
            measures=tuple(f"{n}:joint travel" for n in both),
        ),
        Claim(
            f"{regime}: Σ τ² dt of the applied torque before first contact (Fig. 9)",
            "smaller when optimised",
            f"optimised {a['tau_sq_dt_sum']:.1f} vs initial {b['tau_sq_dt_sum']:.1f} N²·m²·s "
            f"({_pct(a['tau_sq_dt_sum'], b['tau_sq_dt_sum'])}); RMS {a['tau_rms']:.1f} vs "
            f"{b['tau_rms']:.1f} N·m{win}",
            compare(a["tau_sq_dt_sum"], b["tau_sq_dt_sum"]),
            f"plant truth (/arm/joint_state effort = the clamped command PyBullet applied); {tie}",
            kind=kind,
            measures=tuple(f"{n}:applied torque" for n in both),
        ),
    ]
    if kind == "measured":  # (the paper's catches are analysis.catching.claims' rows)
        return rows
    return rows + [
        Claim(
            f"{regime}: both mappings catch",
            "not stated for this regime (the paper: caught at 8 ~ 10 m/s, Figs. 10, 11)",
            f"optimised {'caught' if a['caught'] else 'not caught'}, initial "
            f"{'caught' if b['caught'] else 'not caught'}",
            "reproduced" if a["caught"] and b["caught"] else "differs",
            "the plant's catch event",
            kind=kind,
            measures=tuple(f"{n}:catch" for n in both),
        )
    ]


def _model_rows(pair: Pair, opt: LogReader, ini: LogReader) -> list[Claim]:
    regime = pair.regime
    m = model_torques(pair.optimised)
    a, b = window_effort(opt), window_effort(ini)
    if m is None or a is None or b is None or "optimised" not in m:
        return []
    mi, mo = m["initial"], m["optimised"]
    return [
        Claim(
            f"{regime}: why: eq. 25's model torque vs the run's (α_initial, α_optimised)",
            "(not stated; eq. 25 weighs the eq.-17 torque τ, unclamped)",
            f"model RMS unclamped {mi['rms']:.1f} → {mo['rms']:.1f} N·m, clamped at "
            f"{_fmt3(m['limits'])} N·m {mi['rms_clamped']:.1f} → {mo['rms_clamped']:.1f} N·m; "
            f"run RMS applied {b['tau_rms']:.1f} → {a['tau_rms']:.1f} N·m; last sample (t = t_c) "
            f"{100 * mi['last_share']:.0f} % → {100 * mo['last_share']:.0f} % of the torque cost, "
            f"peaks {_fmt3(mi['peak'])} → {_fmt3(mo['peak'])} N·m",
            "note",
            "nominal throw of the sample set (15 samples t0 → t_c); where the unclamped peaks "
            "exceed the limits, eq. 25 buys them down with torque the arm does deliver earlier: "
            "the clamped model, not the unclamped one, predicts the run",
            kind=pair.kind,
        )
    ]


EXTENSION = "catch_optimised_clamped"  # clamp-aware eq. 25 (not in the paper)


def _extension_rows(ext: LogReader, ini: LogReader) -> list[Claim]:
    a, b = window_effort(ext), window_effort(ini)
    if a is None or b is None:
        return []
    return [
        Claim(
            f"EXTENSION (not in the paper), 8-10 m/s: clamp-aware eq. 25 vs initial, {what} "
            "before first contact",
            "(not stated: the extension's question)",
            f"clamp-aware {a[key]:.3f} vs initial {b[key]:.3f} {unit} ({_pct(a[key], b[key])}); "
            f"{'caught' if a['caught'] else 'not caught'} (initial "
            f"{'caught' if b['caught'] else 'not caught'})",
            compare(a[key], b[key]),
            "cost Σ sat(τ)ᵀK_τ sat(τ) + 0.1 Σ (τ − sat τ)ᵀK_τ (τ − sat τ) + eq. 25's ω term "
            "(scenarios/catch_optimised_clamped.yaml); plant truth; "
            f"tie if within {100 * TIE:g} %",
            kind="extension",
            measures=(f"{EXTENSION}:{key}",),
        )
        for key, what, unit in (
            ("travel_sum", "joint travel Σ‖Δq‖", "rad"),
            ("tau_sq_dt_sum", "Σ τ² dt", "N²·m²·s"),
        )
    ]


def rows(logs: dict[str, LogReader]) -> list[Claim]:
    """The thesis rows for whichever pairs of ``PAIRS`` are among ``logs`` (by scenario name)."""
    out: list[Claim] = []
    for pair in PAIRS:
        opt, ini = logs.get(pair.optimised), logs.get(pair.initial)
        if opt is None or ini is None:
            continue
        if pair.kind != "measured":  # (the paper's Fig. 6 is analysis.catching.claims' row)
            out.append(_cost_row(opt, pair.regime, pair.kind))
        out += _pair_rows(pair, opt, ini)
        out += _model_rows(pair, opt, ini)
    if EXTENSION in logs and PAIRS[0].initial in logs:
        out += _extension_rows(logs[EXTENSION], logs[PAIRS[0].initial])
    return out


# The falsifiers of the rows outside the paper's experiment (other regime, extension): listed,
# not run by replay falsify (those rows are never counted). At 4.5 m/s the 'optimised' log replaced by the same scenario whose alpha is
# optimised for the paper's 8-10 m/s throw set instead (recomputed at start-up, a 'warning'
# event): eq. 13 then holds for a 9 m/s throw, not this one, so the mapping starts off the arm's
# state and moves more (measured: travel 2.56 vs initial 1.87 rad, sum tau^2 dt 157 vs 107).
_OTHER_SET = {"controller.params.throw_speeds": [8.0, 9.0, 10.0]}
_WHY = "an alpha optimised for 8-10 m/s throws, thrown at 4.5 m/s: not eq. 25's optimum here"
FALSIFIERS: tuple[Falsifier, ...] = (
    tuple(
        Falsifier(
            row=f"{PAIRS[1].regime}: {what} before first contact ({fig})",
            name="alpha_for_8_10_ms",
            replaces="catch_5ms_optimised",
            overrides=_OTHER_SET,
            why=_WHY,
        )
        for what, fig in (
            ("joint travel Σ‖Δq‖", "Fig. 8"),
            ("Σ τ² dt of the applied torque", "Fig. 9"),
        )
    )
    + (
        # Fig. 6 at 4.5 m/s: the same 8-10 m/s optimisation in the 4.5 m/s run, whose velocity
        # cost rises over its iterates (+12 % at 8-10 m/s: the paper's regime's own Fig. 6 row)
        Falsifier(
            row=f"{PAIRS[1].regime}: optimisation lowers both costs, first vs last iterate (Fig. 6)",
            name="alpha_for_8_10_ms",
            replaces="catch_5ms_optimised",
            overrides=_OTHER_SET,
            why="the optimisation of the 8-10 m/s throw set, whose velocity cost rises",
        ),
        Falsifier(
            row=f"{PAIRS[1].regime}: both mappings catch",
            name="half_speed_fingers",
            replaces=PAIRS[1].optimised,
            overrides={"plant.params.hand_closing_speed": 39.27},
            why="fingers at half the stated speed (90° in 40 ms) close too late on the ball",
        ),
    )
    + tuple(
        # the extension's alpha optimised for the 4-5 m/s throw set, thrown at 9 m/s: not the
        # clamp-aware optimum for this throw, it moves more than the initial mapping
        Falsifier(
            row=f"EXTENSION (not in the paper), 8-10 m/s: clamp-aware eq. 25 vs initial, {what} "
            "before first contact",
            name="alpha_for_4_5_ms",
            replaces=EXTENSION,
            overrides={"controller.params.throw_speeds": [4.0, 4.5, 5.0]},
            why="the clamp-aware optimisation of another throw set (4-5 m/s)",
        )
        for what in ("joint travel Σ‖Δq‖", "Σ τ² dt")
    )
)
