"""The grasping claims table: what Namiki, Nakabo, Ishii & Ishikawa 1999 state against the runs'
logs (``analysis.grasping.run`` reads them). Every number here comes from a log, except the arm's
top speed, which comes from the arm model the run's scenario names (``replay.robot``).

Quantities (all from the log):

- the loops' cycle and sensor-to-actuator latency: the runner's per-step task records
  (``/tasks/loops``), else the tasks' declared rates in the resolved scenario;
- the schedule's phases (tracking, reaching, grasping = holding, releasing) and the plant's
  ``grasp`` / ``release`` / ``drop`` / ``slip`` events;
- the hand x^a, the observed x^o and the reaching target x_d^a as eq. 2 used them
  (``/grasping/arm``), the object's truth (``/object/state``), the recognised shape
  (``/grasping/object``) and the hand's preshape (``/grasping/hand``).

One row per finding (analysis/claims.py): each claim is evaluated on every run and the runs'
rows merged into one (``grasp_cycle`` grasps the box as ``grasp_hexahedron`` does, then
releases and tracks it: Fig. 9). Every shipped grasp scenario is the paper's experiment (Figs.
6-9), so its rows are "measured"; the preshape row is "configuration": it compares the method's
own labels, and a wrong preshape still grasps.

The quantities are measured by ``analysis.grasping.metrics``, the falsifiers are
``analysis.grasping.falsifiers``; this module makes the rows.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import yaml

from analysis.claims import Claim, agrees, merge
from analysis.needs import has
from analysis.grasping.falsifiers import FALSIFIERS as FALSIFIERS  # (beside evaluate: claims.py)
from analysis.grasping.falsifiers import STABLE
from analysis.grasping.metrics import (
    arm_top_speed,
    cycle_timing,
    first_contact,
    holds,
    image_centre_error,
    knock_speed,
    loop_timing,
    reach_following,
    recognised_shapes,
    tracking_error,
    tracking_lag,
)
from analysis.grasping.run import (
    T_ARM_TASK,
    T_OBJECT,
    REACHING,
    RELEASING,
    TRACKING,
    GraspRun,
    load_run,
)
from replay.log import LogReader
from replay.resources import data_path

STATED = data_path("claims", "namiki1999.yaml")
ROUND = {"box": "rectangle", "ball": "circle"}  # the rig's object -> its image's shape
TRACK_RATIO = 0.2  # tracking is "responsive" if RMS error < this x the object's excursion


HOLDS = "the grasp holds while the human keeps moving the object"
COMPLIANT = "compliant hold: grip force and the human's force (eqs. 2, 4)"
STABLE_STATED = (
    "'stable grasping by visual and force feedback during the grasping phase' (Sec. 5, Fig. 9)"
)


def _stated() -> dict:
    return yaml.safe_load(STATED.read_text())


def _ms(x: float) -> str:
    return f"{1000.0 * x:.3g} ms"


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
                kind="configuration",
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
            "consistent" if ok else "differs",
            f"from the {'runner (/tasks/loops)' if src == 'log' else 'scenario'}: the "
            "interval between a task's ticks in simulated time (the loops run in step, "
            "not on 7 DSPs): the scenario's rates, echoed",
            kind="configuration",
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
                "consistent" if worst < lim else "differs",
                "per tick: now − the capture time of the oldest of the task's inputs' "
                "newest messages (the runner's /tasks/loops); the command is applied "
                "in the same step: the scenario's sensor latencies, echoed",
                kind="configuration",
            )
        )
    else:
        rows.append(
            Claim(
                "sensor-to-actuator latency of every loop",
                f"< {_ms(lim)} (Sec. 4)",
                "(no latency recorded)",
                "not run",
                kind="configuration",
            )
        )
    return rows


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
        + (
            f"object at rest in the hand from {rel_done:.3f} s"
            if rel_done is not None
            else "no grasp event"
        )
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
            "the schedule's times are the scenario's; done: the start of the plant's grasp "
            "(several hand parts in contact and the object still relative to the palm, "
            f"confirmed {run.params.catch_hold_time * 1000:.0f} ms later by the grasp event); "
            "within 50 ms of the paper's",
        )
    ]
    dur_ms = (t_done - t_reach) * 1e-3
    need = ct["travel"] / dur_ms
    top = arm_top_speed(run)
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
            kind="paper",
        )
    )
    return rows


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
                f"{run.name}: the preshape matches the shape (Figs. 5b, 8)",
                st["results"]["preshape"]["value"],
                "(no recognised shape in the log)",
                "not run",
                kind="configuration",
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
            agrees(bool(ok)),
            "the recognition task's shape (moments of the binarised 16 × 16 image) over "
            "the frames it found the object in, and the hand task's preshape: the method's own "
            "labels, not the physics (with the recognition's thresholds out of range the box is "
            "judged a circle, preshaped for a ball, and still grasped), so this row shows the "
            "labels agree, not that the preshape is needed",
            kind="configuration",
        )
    ]


def _contact_rows(run: GraspRun, st: dict) -> list[Claim]:
    q = f"{run.name}: the hand meets the object without impact (first contact speed)"
    stated = "a moving object reached and grasped (Sec. 5, Figs. 6-8; no contact speed given)"
    c = first_contact(run)
    if c is None:
        return [Claim(q, stated, "(the hand never touched the object)", "not run")]
    bound = knock_speed(run)
    return [
        Claim(
            q,
            stated,
            f"first contact ({', '.join(c['parts'])}) at {c['t']:.3f} s, "
            f"{c['speed']:.2f} m/s relative to the object (bound {bound:.2f} m/s)",
            "reproduced" if c["speed"] <= bound else "differs",
            "the plant's first contact event (the touching link's point velocity against the "
            "object's, from the physics). Bound: the speed whose impulse would push the object "
            f"{1000 * run.params.grasp_max_drift:.0f} mm (the hold's tolerance) against the "
            f"human's {run.params.human_stiffness:.0f} N/m, v = d sqrt(k/m); the paper gives no "
            "number, its figures show the object not knocked away",
        )
    ]


def _event_summary(evs: list[dict], kind: str) -> str:
    if len(evs) == 1:
        return f"{kind} at {evs[0]['t']:.3f} s"
    return f"{len(evs)} {kind}s ({evs[0]['t']:.3f}-{evs[-1]['t']:.3f} s)"


def _hold_rows(run: GraspRun, st: dict) -> list[Claim]:
    h = holds(run)
    P = run.params
    q = f"{run.name}: the grasp holds while the human keeps moving the object"
    if not h:
        return [Claim(q, "holds (Fig. 9)", "(no holding phase)", "not run")]
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
            f" mm (span {1000 * d['span']:.0f} mm), {1000 * d['drift']:.1f} mm in the hand, "
            f"≤ {1000 * d['human']:.1f} mm from the human's path" + (f"; {bad}" if bad else "")
        )
        ok &= (
            not any(e["kind"] == "drop" for e in d["bad"])
            and d["drift"] <= P.grasp_max_drift
            and d["human"] <= P.grasp_max_human_offset
        )
    moved = all(d["span"] > 2 * P.grasp_max_drift for d in h)
    return [
        Claim(
            q,
            "stable grasping during the grasping phase (Fig. 9)",
            "; ".join(parts),
            "reproduced" if ok and moved else "differs",
            f"from the truth: from the plant's grasp event on, no drop, the object within "
            f"{1000 * P.grasp_max_drift:.0f} mm of where it sat in the hand and within "
            f"{1000 * P.grasp_max_human_offset:.0f} mm of the human's path (held, and with "
            "the human: not carried away)" + ("" if moved else "; the object hardly moved"),
        )
    ]


def _compliance_rows(run: GraspRun, st: dict) -> list[Claim]:
    """Eqs. 2 and 4 together: while held, the hand grips (contact force never zero) and the arm
    yields to the human (the human's force stays well under its strength)."""
    h = [d for d in holds(run) if d["grasp"] is not None]
    q = f"{run.name}: compliant hold: grip force and the human's force (eqs. 2, 4)"
    stated = "stable grasping by visual and force feedback (Sec. 5; no force given)"
    if not h:
        return [Claim(q, stated, "(no grasp held)", "not run")]
    limit = 0.5 * run.params.human_max_force
    ok = all(d["grip_min"] > 0.0 and d["human_force_max"] <= limit for d in h)
    return [
        Claim(
            q,
            stated,
            "; ".join(
                f"grip {d['grip_mean']:.0f} N (min {d['grip_min']:.0f} N), the human's force "
                f"RMS {d['human_force_rms']:.1f} N, max {d['human_force_max']:.1f} N"
                for d in h
            ),
            "reproduced" if ok else "differs",
            "grip: the summed contact normal force on the object (/object/contacts); the "
            "human's force on the object (/human/state); compliant: never released by the "
            f"fingers and the human never pulls with more than {limit:.0f} N (half its "
            "strength): the wrist force term K^af moves the arm with the human",
        )
    ]


def _tracking_rows(run: GraspRun, st: dict) -> list[Claim]:
    rows = []
    # (one row: the releasing phase alone is part of it, not a finding of its own)
    for names, label in (((RELEASING, TRACKING), "releasing and tracking phases"),):
        te = tracking_error(run, names)
        if te is None:
            rows.append(
                Claim(
                    f"{run.name}: tracking error on the plane (Y, Z), {label}",
                    "responsive tracking by visual feedback (Fig. 9; no number given)",
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


def _eq1_rows(run: GraspRun, st: dict) -> list[Claim]:
    q = f"{run.name}: eq. 1 keeps the target at the image centre"
    stated = "active vision: the head servoes the target to xi_d, the image centre (eq. 1)"
    e = image_centre_error(run)
    if e is None:
        return [Claim(q, stated, "(no head or chip in the log)", "not run")]
    return [
        Claim(
            q,
            stated,
            f"true object {e['rms']:.2f} px RMS, {e['max']:.2f} px max off the optical axis "
            f"(1 px = {1000 * e['px']:.1f} mrad)",
            "reproduced" if e["rms"] <= 1.0 else "differs",
            "the true object's direction in the true head camera frame; kept: RMS within one "
            "of the chip's pixels (its resolution)",
        )
    ]


# ------------------------------------------------------------------------------- eq. 3
def _partition_rows(run: GraspRun, st: dict) -> list[Claim]:
    """Eq. 3's S: tracking (y, z) goes on while the arm reaches along x."""
    q = f"{run.name}: eq. 3's partition: tracking unaffected by reaching"
    stated = "S = diag(0, 1, 1, 1, 0, 0): tracking in the plane, reaching along its normal (eq. 3)"
    tr, re = tracking_error(run, (TRACKING,)), tracking_error(run, (REACHING,))
    if tr is None or re is None:
        return [Claim(q, stated, "(no tracking or no reaching phase)", "not run")]
    ok = re["rms"] <= 2.0 * tr["rms"] + 1e-3
    return [
        Claim(
            q,
            stated,
            f"in-plane error RMS {1000 * tr['rms']:.1f} mm tracking, {1000 * re['rms']:.1f} mm "
            f"while reaching (max {1000 * re['max']:.1f} mm)",
            "reproduced" if ok else "differs",
            "truth: hand x^a vs /object/state on the plane; unaffected: the reach's RMS within "
            "twice the tracking phase's + 1 mm",
        )
    ]


# ------------------------------------------------------------------------------- x^o
def _xo_rows(run: GraspRun, st: dict) -> list[Claim]:
    q = f"{run.name}: x^o from the 16 × 16 chip against the truth"
    stated = "the object's position from the chip image and the head angles (Sec. 4.1)"
    if not len(run.t_vis):
        return [Claim(q, stated, "(no recognition result)", "not run")]
    err = run.vis - run.obj_at(run.t_vis)
    e_plane = np.linalg.norm(err[:, 1:3], axis=1)
    return [
        Claim(
            q,
            stated,
            f"in the plane RMS {1000 * np.sqrt(np.mean(e_plane**2)):.1f} mm, max "
            f"{1000 * np.max(e_plane):.1f} mm over {len(e_plane)} frames",
            "note",
            "recognition results vs /object/state at their capture times; the paper gives "
            "no accuracy",
        )
    ]


def _x_axis_rows(run: GraspRun, st: dict) -> list[Claim]:
    q = f"{run.name}: the hand's X follows the reaching trajectory (Fig. 9)"
    stated = "X of the hand follows x_d^a, reaching and releasing (Fig. 9)"
    r = reach_following(run)
    if r is None:
        return [Claim(q, stated, "(no reaching phase)", "not run")]
    ok = r["max"] <= TRACK_RATIO * r["travel"]
    return [
        Claim(
            q,
            stated,
            f"largest lag {1000 * r['max']:.1f} mm over a {1000 * r['travel']:.0f} mm reach; at "
            "the end of each reach " + ", ".join(f"{1000 * e:.1f} mm" for e in r["ends"]),
            "reproduced" if ok else "differs",
            "the hand x^a from the joint encoders through the nominal chain (the plant's "
            "model: its tool frame) vs the schedule's x_d^a; follows: the lag under "
            f"{TRACK_RATIO:g} × the reach (as tracking is 'responsive'); at its end the palm "
            "meets the object",
        )
    ]


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
            "consistent" if ok else "differs",
            "a tracker fed only the last measurement lags the object (delay ≥ 0); a "
            "predictor would lead it. The method has no predictor to switch on: this "
            "shows how it is built, it cannot fail",
            kind="configuration",
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
            "consistent" if ok else "differs",
            "the scenario's chip, echoed",
            kind="configuration",
        )
    ]


# what the rows read (the contract a grasping controller fulfils: docs/grasping.md); a log that
# lacks one is left out of every row, with a note naming the topic
TOPICS = (T_ARM_TASK, T_OBJECT)


def _run_rows(run: GraspRun, st: dict) -> list[Claim]:
    """One run's rows, each named "<run>: <claim>" (merged across runs by :func:`evaluate`)."""
    return [
        *_timing_rows(run, st),
        *_preshape_rows(run, st),
        *_contact_rows(run, st),
        *_hold_rows(run, st),
        *_compliance_rows(run, st),
        *_tracking_rows(run, st),
        *_eq1_rows(run, st),
        *_partition_rows(run, st),
        *_x_axis_rows(run, st),
        *_xo_rows(run, st),
        *_prediction_rows(run, st),
    ]


def _readable(logs: dict[str, LogReader]) -> dict[str, GraspRun]:
    logs = {n: log for n, log in logs.items() if has({n: log}, TOPICS, "claims (every row)")}
    return {name: load_run(log, name) for name, log in sorted(logs.items())}


def per_run(logs: dict[str, LogReader]) -> dict[str, list[Claim]]:
    """Each run's own rows, "<run>: <claim>", before :func:`evaluate` merges them (what a
    single run shows; the table has one row per claim)."""
    st = _stated()
    return {name: _clean(_run_rows(run, st)) for name, run in _readable(logs).items()}


def evaluate(logs: dict[str, LogReader]) -> list[Claim]:
    """The table: the loops' and the chip's configuration (from the first run), then one row per
    claim over every run (:func:`per_run` merged), the two observables of 'stable grasping'
    (held, compliant) in one row."""
    st = _stated()
    runs = _readable(logs)
    rows: list[Claim] = []
    per_claim: dict[str, list[tuple[str, Claim]]] = {}
    for i, run in enumerate(runs.values()):
        if i == 0:
            rows += _loop_rows(run, st)
            rows += _vision_rows(run, st)
        for r in _run_rows(run, st):
            what = r.quantity.removeprefix(f"{run.name}: ")
            per_claim.setdefault(what, []).append(
                (run.name, replace(r, measures=(f"{run.name}:{what}",)))
            )
    merged = {what: merge(what, parts) for what, parts in per_claim.items()}
    if HOLDS in merged and COMPLIANT in merged:  # one statement (Sec. 5), two observables
        parts = [("held", merged.pop(HOLDS)), ("compliant", merged.pop(COMPLIANT))]
        merged[STABLE] = replace(merge(STABLE, parts), stated=STABLE_STATED)
    return _clean(rows + list(merged.values()))


def _clean(rows: list[Claim]) -> list[Claim]:
    """A "|" would split a Markdown table cell: magnitudes are written ‖x‖."""
    return [
        replace(
            r,
            **{
                f: getattr(r, f).replace("|", "‖")
                for f in ("quantity", "stated", "measured", "status", "note")
            },
        )
        for r in rows
    ]
