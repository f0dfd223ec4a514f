"""The grasping claims table: what Namiki, Nakabo, Ishii & Ishikawa 1999 state against the runs'
logs (``analysis.grasp_run`` reads them). Every number here comes from a log, except the arm's
top speed, which comes from the arm model the run's scenario names (``replay.robot``).

Quantities (all from the log):

- the loops' cycle and sensor-to-actuator latency: the runner's per-step task records
  (``/tasks/loops``), else the tasks' declared rates in the resolved scenario;
- the schedule's phases (tracking, reaching, grasping = holding, releasing) and the plant's
  ``grasp`` / ``release`` / ``drop`` / ``slip`` events;
- the hand x^a, the observed x^o and the reaching target x_d^a as eq. 2 used them
  (``/grasping/arm``), the object's truth (``/object/state``), the recognised shape
  (``/grasping/object``) and the hand's preshape (``/grasping/hand``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import yaml

from analysis.claims import Claim
from analysis.grasp_run import GRASP_PHASES, HOLDING, RELEASING, TRACKING, GraspRun, load_run
from replay.log import LogReader

STATED = Path(__file__).resolve().parents[1] / "data" / "claims" / "namiki1999.yaml"
ROUND = {"box": "rectangle", "ball": "circle"}  # the rig's object -> its image's shape
HOLD_DRIFT = 0.01  # m: a grasp "holds" while the object stays within this of the palm
TRACK_RATIO = 0.2  # tracking is "responsive" if RMS error < this x the object's excursion


def _stated() -> dict:
    return yaml.safe_load(STATED.read_text())


def _ms(x: float) -> str:
    return f"{1000.0 * x:.3g} ms"


# ------------------------------------------------------------------------------- loops
def loop_timing(run: GraspRun) -> dict[str, dict]:
    """Per task: its cycle (median and max of the intervals between its ticks, s) and its
    sensor-to-actuator latency (max over its ticks, s: the runner's "now minus the capture time
    of the oldest of its inputs' newest messages"), from ``/tasks/loops``; without that topic,
    the rates the scenario declares."""
    out: dict[str, dict] = {}
    if run.tasks:
        names = list(run.tasks[0]["names"])
        t = np.array([m["t"] for m in run.tasks], float)
        ticked = np.array([m["ticked"] for m in run.tasks], bool)
        lat = np.array(
            [[np.nan if v is None else v for v in m["latency"]] for m in run.tasks], float
        )
        for k, n in enumerate(names):
            tt = t[ticked[:, k]]
            period = np.diff(tt)
            lk = lat[ticked[:, k], k]
            lk = lk[np.isfinite(lk)]
            out[n] = {
                "period": float(np.median(period)) if len(period) else float("nan"),
                "period_max": float(np.max(period)) if len(period) else float("nan"),
                "latency": float(np.max(lk)) if len(lk) else float("nan"),
                "source": "log",
            }
        return out
    tasks = run.scenario.get("tasks") or {}
    items = (
        tasks.items()
        if isinstance(tasks, dict)
        else ((t.get("name", str(i)), t) for i, t in enumerate(tasks))
    )
    for n, spec in items:
        rate = float((spec or {}).get("rate", 0.0) or 0.0)
        out[str(n)] = {
            "period": 1.0 / rate if rate else float("nan"),
            "period_max": 1.0 / rate if rate else float("nan"),
            "latency": float("nan"),
            "source": "scenario",
        }
    return out


def _loop_rows(run: GraspRun, st: dict) -> list[Claim]:
    p = st["parameters"]
    timing = loop_timing(run)
    if not timing:
        return [
            Claim(
                "1 ms cycle of every loop",
                "1 ms (Secs. 2, 3)",
                "(no task timing in the log or the scenario)",
                "not run",
            )
        ]
    cyc = p["cycle_time"]["value"]
    parts = [
        f"{n} {_ms(d['period'])}"
        + (f" (max {_ms(d['period_max'])})" if d["period_max"] > d["period"] + 1e-9 else "")
        for n, d in timing.items()
    ]
    ok = all(abs(d["period_max"] - cyc) <= 1e-6 for d in timing.values())
    src = next(iter(timing.values()))["source"]
    rows = [
        Claim(
            "cycle of every feedback loop (Fig. 4)",
            f"{_ms(cyc)} (Secs. 2, 3)",
            "; ".join(parts),
            "reproduced" if ok else "differs",
            f"from the {'runner (/tasks/loops)' if src == 'log' else 'scenario'}: the "
            "interval between a task's ticks in simulated time (the loops run in step, "
            "not on 7 DSPs)",
        )
    ]
    lim = p["latency_max"]["value"]
    lats = {n: d["latency"] for n, d in timing.items() if np.isfinite(d["latency"])}
    if lats:
        worst = max(lats.values())
        rows.append(
            Claim(
                "sensor-to-actuator latency of every loop",
                f"< {_ms(lim)} (Sec. 4)",
                "; ".join(f"{n} {_ms(v)}" for n, v in lats.items()),
                "reproduced" if worst < lim else "differs",
                "per tick: now − the capture time of the oldest of the task's inputs' "
                "newest messages (the runner's /tasks/loops); the command is applied "
                "in the same step",
            )
        )
    else:
        rows.append(
            Claim(
                "sensor-to-actuator latency of every loop",
                f"< {_ms(lim)} (Sec. 4)",
                "(no latency recorded)",
                "not run",
            )
        )
    return rows


# ------------------------------------------------------------------------------- timing
def cycle_timing(run: GraspRun) -> dict | None:
    """The first grasp cycle: tracking time before the reach, reach-to-grasp time, the hand's
    travel along the reaching axis X during the reach, and its peak speed."""
    cycles = run.cycles()
    if not cycles:
        return None
    c = cycles[0]
    r = c["reach"]
    t_done = c["grasp"]["t"] if c["grasp"] else None
    end = t_done if t_done is not None else r.t1
    w = run.window(run.t_eff, r.t0, end)
    x = run.hand[w, 0]
    travel = float(np.max(x) - np.min(x)) if len(x) else float("nan")
    dt = np.diff(run.t_eff[w])
    peak = (
        float(np.max(np.linalg.norm(np.diff(run.hand[w], axis=0), axis=1) / dt))
        if len(dt)
        else float("nan")
    )
    return {
        "track": r.t0 - c["track_start"],
        "t_track0": c["track_start"],
        "t_reach": r.t0,
        "t_done": t_done,
        "reach": (end - r.t0),
        "travel": travel,
        "peak_speed": peak,
    }


def _arm_top_speed(run: GraspRun) -> float | None:
    """The run's arm model's top tool speed with its joint speed limits (over a sample of its
    joint box), as the catching claims compute it, from the rig's own settings."""
    from analysis.catch_claims import arm_capability
    from plants.bullet_arm.settings import resolve

    try:
        arm = resolve(run.params)
    except ValueError:
        return None
    return float(arm_capability(arm)["v_max"])


def _timing_rows(run: GraspRun, st: dict) -> list[Claim]:
    r = st["results"]
    tr0, tr1 = r["tracking_phase"]["value"]
    t_reach, t_done = r["reach_start"]["value"], r["grasp_done"]["value"]
    ct = cycle_timing(run)
    stated = (
        f"tracking {tr0:g}-{tr1:g} ms, reaching and grasping start at {t_reach:g} ms, "
        f"done at {t_done:g} ms (Fig. 7)"
    )
    if ct is None:
        return [
            Claim(
                f"{run.name}: tracking, reaching, grasping times",
                stated,
                "(no reaching phase in the run)",
                "not run",
            )
        ]
    rel_done = (ct["t_done"] - ct["t_track0"]) if ct["t_done"] is not None else None
    measured = (
        f"tracking {ct['track']:.3f} s, reach starts {ct['t_reach'] - ct['t_track0']:.3f}"
        f" s, "
        + (f"grasp event {rel_done:.3f} s" if rel_done is not None else "no grasp event")
        + f" after tracking began (t = "
        f"{ct['t_track0']:.3f} s); reach {1000 * ct['travel']:.0f} mm along X"
    )
    ok = (
        rel_done is not None
        and abs(ct["track"] - (tr1 - tr0)) <= 0.05
        and abs(rel_done - t_done) <= 0.05
    )
    rows = [
        Claim(
            f"{run.name}: tracking 0.0-0.5, reaching and grasping done at 0.8, read as seconds",
            stated.replace("ms", "s"),
            measured,
            "reproduced" if ok else "differs",
            "the schedule's times are the scenario's; the grasp event is the plant's "
            "(several hand parts in contact and the object still relative to the palm for "
            f"{run.params.catch_hold_time * 1000:.0f} ms before "
            "it fires)",
        )
    ]
    dur_ms = (t_done - t_reach) * 1e-3
    need = ct["travel"] / dur_ms
    top = _arm_top_speed(run)
    rows.append(
        Claim(
            f"{run.name}: the same times read as printed (ms)",
            stated,
            f"a {1000 * ct['travel']:.0f} mm reach in {_ms(dur_ms)} needs {need:.0f} m/s on average; "
            f"the run's hand peaked at {ct['peak_speed']:.2f} m/s"
            + (f", the WAM-7 model tops out at {top:.1f} m/s" if top else ""),
            "inconsistent",
            "0.3 ms for a reach of centimetres is beyond any arm; the text's 'ms' must mean s "
            "(Fig. 7 is a sequence of video frames)",
        )
    )
    return rows


# ------------------------------------------------------------------------------- shape
def recognised_shapes(run: GraspRun) -> list[str]:
    """The recognition task's shape for every frame it found the object in."""
    return [str(f["shape"]) for f in run.vis_features if f.get("shape")]


def _preshape_rows(run: GraspRun, st: dict) -> list[Claim]:
    kind = run.params.object
    want = ROUND.get(kind, kind)
    shapes = recognised_shapes(run)
    pre = [str(m["preshape"]) for m in run.hand_task if m.get("preshape")]
    at_reach = []
    for c in run.cycles():  # the hand task's preshape when each reach starts
        m = next((m for m in run.hand_task if m["t"] >= c["reach"].t0 - 1e-9), None)
        at_reach.append(str(m.get("preshape")) if m else None)
    if not shapes and not pre:
        return [
            Claim(
                f"{run.name}: preshape by shape",
                st["results"]["preshape"]["value"],
                "(no recognised shape in the log)",
                "not run",
            )
        ]
    right = sum(s == want for s in shapes)
    measured = f"object {kind} ({want}); vision says {want} in {right} of {len(shapes)} frames" + (
        f" ({100 * right / len(shapes):.1f} %)" if shapes else ""
    )
    if at_reach:
        measured += "; preshape at each reach: " + ", ".join(str(p) for p in at_reach)
    ok = (
        bool(at_reach) and all(p == want for p in at_reach) and shapes and right / len(shapes) > 0.9
    )
    return [
        Claim(
            f"{run.name}: the preshape matches the shape (Figs. 5b, 8)",
            "circle → sphere grasp, rectangle → hexahedron grasp",
            measured,
            "reproduced" if ok else "differs",
            "the recognition task's shape (moments of the binarised 16 × 16 image) over "
            "the frames it found the object in",
        )
    ]


# ------------------------------------------------------------------------------- grasp holds
def holds(run: GraspRun) -> list[dict]:
    """For each holding phase, from the plant's grasp event in it (the object held) to the end of
    the phase: the object's travel (path length, m) and span (m), its largest displacement
    relative to the hand x^a since the grasp (m), and the drop/slip events; ``grasp`` None if the
    plant never reported the object held in that phase."""
    out = []
    for p in run.phases:
        if p.name != HOLDING:
            continue
        g = next((e for e in run.kinds("grasp") if p.t0 - 1e-9 <= e["t"] <= p.t1 + 1e-9), None)
        t0 = g["t"] if g is not None else p.t0
        wo = run.window(run.t_obj, t0, p.t1)
        if wo.sum() < 2:
            continue
        obj = run.obj[wo]
        rel = obj - run.hand_at(run.t_obj[wo])
        bad = [
            e
            for e in run.events
            if e["kind"] in ("drop", "slip") and t0 - 1e-9 <= e["t"] <= p.t1 + 1e-9
        ]
        out.append(
            {
                "t0": t0,
                "t1": p.t1,
                "grasp": g,
                "bad": bad,
                "travel": float(np.sum(np.linalg.norm(np.diff(obj, axis=0), axis=1))),
                "drift": float(np.max(np.linalg.norm(rel - rel[0], axis=1))),
                "span": float(np.max(np.ptp(obj, axis=0))),
            }
        )
    return out


def _event_summary(evs: list[dict], kind: str) -> str:
    if len(evs) == 1:
        return f"{kind} at {evs[0]['t']:.3f} s"
    return f"{len(evs)} {kind}s ({evs[0]['t']:.3f}-{evs[-1]['t']:.3f} s)"


def _hold_rows(run: GraspRun, st: dict) -> list[Claim]:
    h = holds(run)
    if not h:
        return [
            Claim(
                f"{run.name}: the grasp holds while the object is moved",
                "holds (Fig. 9)",
                "(no holding phase)",
                "not run",
            )
        ]
    parts, ok = [], True
    for d in h:
        if d["grasp"] is None:
            parts.append(f"hold phase to {d['t1']:.2f} s: the plant never reported the object held")
            ok = False
            continue
        bad = "; ".join(
            _event_summary([e for e in d["bad"] if e["kind"] == k], k)
            for k in ("drop", "slip")
            if any(e["kind"] == k for e in d["bad"])
        )
        parts.append(
            f"grasped {d['t0']:.3f}-{d['t1']:.2f} s: object moved {1000 * d['travel']:.0f}"
            f" mm (span {1000 * d['span']:.0f} mm), drift from the hand "
            f"{1000 * d['drift']:.1f} mm" + (f"; {bad}" if bad else "")
        )
        ok &= not d["bad"] and d["drift"] < HOLD_DRIFT
    moved = all(d["span"] > 2 * HOLD_DRIFT for d in h)
    return [
        Claim(
            f"{run.name}: the grasp holds while the human keeps moving the object",
            "stable grasping during the grasping phase (Fig. 9)",
            "; ".join(parts),
            "reproduced" if ok and moved else "differs",
            f"holds: from the plant's grasp event on, no drop or slip and the object "
            f"within {1000 * HOLD_DRIFT:.0f} mm of where it was grasped relative to the "
            "hand x^a" + ("" if moved else "; the object hardly moved, so this shows little"),
        )
    ]


# ------------------------------------------------------------------------------- tracking
def tracking_error(run: GraspRun, names=(RELEASING, TRACKING)) -> dict | None:
    """Hand minus object on the tracking plane (Y, Z) during the given phases: RMS and max of
    the error (m), and the object's RMS excursion from its mean there (m)."""
    if not len(run.t_eff):
        return None
    m = run.in_phases(run.t_eff, names)
    if m.sum() < 2:
        return None
    obj = run.obj_at(run.t_eff[m])
    err = run.hand[m][:, 1:3] - obj[:, 1:3]
    e = np.linalg.norm(err, axis=1)
    exc = obj[:, 1:3] - obj[:, 1:3].mean(axis=0)
    return {
        "rms": float(np.sqrt(np.mean(e**2))),
        "max": float(np.max(e)),
        "excursion": float(np.sqrt(np.mean(np.sum(exc**2, axis=1)))),
        "duration": float(m.sum() * np.median(np.diff(run.t_eff))),
    }


def _tracking_rows(run: GraspRun, st: dict) -> list[Claim]:
    rows = []
    for names, label in (
        ((RELEASING,), "releasing phase"),
        ((RELEASING, TRACKING), "releasing and tracking phases"),
    ):
        te = tracking_error(run, names)
        if te is None:
            rows.append(
                Claim(
                    f"{run.name}: tracking error, {label}",
                    "responsive tracking (Fig. 9)",
                    f"(no {label} in the run)",
                    "not run",
                )
            )
            continue
        ok = te["rms"] < TRACK_RATIO * te["excursion"]
        rows.append(
            Claim(
                f"{run.name}: tracking error on the plane (Y, Z), {label}",
                "responsive tracking by visual feedback (Fig. 9; no number given)",
                f"RMS {1000 * te['rms']:.1f} mm, max {1000 * te['max']:.1f} mm over "
                f"{te['duration']:.2f} s; the object's RMS excursion {1000 * te['excursion']:.1f} mm "
                f"(ratio {te['rms'] / te['excursion']:.2f})",
                "reproduced" if ok else "differs",
                f"responsive: RMS error under {TRACK_RATIO:g} × the object's excursion",
            )
        )
    return rows


# ------------------------------------------------------------------------------- prediction
def tracking_lag(run: GraspRun, max_lag: float = 0.1) -> float | None:
    """The delay (s) that best aligns the hand's Y with the object's Y over the non-grasp phases
    (least squares over lags 0..max_lag, both ways): > 0 means the hand follows the object."""
    if len(run.t_eff) < 10:
        return None
    dt = float(np.median(np.diff(run.t_eff)))
    t = run.t_eff
    m = ~run.in_phases(t, GRASP_PHASES)
    if m.sum() < 10:
        m = np.ones(len(t), bool)
    n = int(max_lag / dt)
    best, best_lag = np.inf, 0.0
    hy = run.hand[:, 1]
    for k in range(-n, n + 1):
        oy = np.interp(t - k * dt, run.t_obj, run.obj[:, 1])
        c = float(np.mean((hy[m] - oy[m] - np.mean(hy[m] - oy[m])) ** 2))
        if c < best:
            best, best_lag = c, k * dt
    return best_lag


def _prediction_rows(run: GraspRun, st: dict) -> list[Claim]:
    lag = tracking_lag(run)
    used = []
    if len(run.t_eff) and len(run.t_vis):
        # x^o that eq. 2 used vs the recognition results captured in the 5 ms before the tick:
        # a measured value, not an extrapolation, matches one of them exactly
        d = np.full(len(run.t_eff), np.inf)
        hi = np.searchsorted(run.t_vis, run.t_eff + 1e-9)
        for back in range(1, 6):
            i = hi - back
            has = i >= 0
            dd = np.linalg.norm(run.seen[has] - run.vis[np.maximum(i[has], 0)], axis=1)
            d[has] = np.minimum(d[has], dd)
        seen = np.isfinite(d)
        if seen.any():
            used.append(float(np.max(d[seen])))
    measured = (
        f"hand Y follows the object Y with a best-fit delay of {_ms(lag)}"
        if lag is not None
        else "(no hand track)"
    )
    if used:
        measured += (
            f"; x^o in eq. 2 is a recognition result captured ≤ 5 ms before each tick "
            f"(worst mismatch {1000 * used[0]:.3g} mm)"
        )
    ok = lag is not None and lag >= 0.0 and (not used or used[0] < 1e-6)
    return [
        Claim(
            f"{run.name}: no prediction of the object's motion",
            "no prediction methods are used (Sec. 4)",
            measured,
            "reproduced" if ok else "differs",
            "a tracker fed only the last measurement lags the object (delay ≥ 0); a "
            "predictor would lead it",
        )
    ]


# ------------------------------------------------------------------------------- vision
def _vision_rows(run: GraspRun, st: dict) -> list[Claim]:
    if len(run.t_chip) < 2:
        return []
    p = st["parameters"]
    rate = (len(run.t_chip) - 1) / (run.t_chip[-1] - run.t_chip[0])
    w, h = run.chip_size
    ok = abs(rate - p["vision_rate"]["value"]) < 1.0 and [w, h] == p["vision_pixels"]["value"]
    return [
        Claim(
            "vision chip rate and resolution",
            "1 kHz, 16 × 16 (SPE-256, Sec. 3.2)",
            f"{rate:.0f} Hz, {w} × {h} ({run.name})",
            "reproduced" if ok else "differs",
        )
    ]


def evaluate(logs: dict[str, LogReader]) -> list[Claim]:
    st = _stated()
    runs = {name: load_run(log, name) for name, log in sorted(logs.items())}
    rows: list[Claim] = []
    for i, run in enumerate(runs.values()):
        if i == 0:
            rows += _loop_rows(run, st)
            rows += _vision_rows(run, st)
        rows += _timing_rows(run, st)
        rows += _preshape_rows(run, st)
        rows += _hold_rows(run, st)
        rows += _tracking_rows(run, st)
        rows += _prediction_rows(run, st)
    return [
        Claim(
            *(
                getattr(r, f).replace("|", "‖")
                for f in ("quantity", "stated", "measured", "status", "note")
            )
        )
        for r in rows
    ]
