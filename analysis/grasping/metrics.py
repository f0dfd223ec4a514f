"""The grasp's measured quantities, each from one run's arrays (:mod:`analysis.grasping.run`):
loop and cycle timing, recognised shapes, contact, holds, tracking, the image centre, the reach."""

from __future__ import annotations

import numpy as np

from analysis.grasping.run import (
    GRASP_PHASES,
    HOLDING,
    REACHING,
    RELEASING,
    TRACKING,
    GraspRun,
)


HOLD_DRIFT = 0.01  # m: a grasp "holds" while the object stays within this of the palm


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


# ------------------------------------------------------------------------------- timing
def cycle_timing(run: GraspRun) -> dict | None:
    """The first grasp cycle: tracking time before the reach, reach-to-grasp time, the hand's
    travel along the reaching axis X during the reach, and its peak speed."""
    cycles = run.cycles()
    if not cycles:
        return None
    c = cycles[0]
    r = c["reach"]
    # the grasp is done when the object came to rest in the hand: the plant's grasp event
    # fires hold_time (catch_hold_time) after that
    g = c["grasp"]
    t_done = (g["t"] - float(g["data"].get("hold_time", 0.0))) if g else None
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


def arm_top_speed(run: GraspRun) -> float | None:
    """The run's arm model's top tool speed with its joint speed limits (over a sample of its
    joint box), as the catching claims compute it, from the rig's own settings."""
    from analysis.catching.metrics import arm_capability
    from plants.arm_rig.settings import resolve

    try:
        arm = resolve(run.params)
    except ValueError:
        return None
    return float(arm_capability(arm)["v_max"])


# ------------------------------------------------------------------------------- shape
def recognised_shapes(run: GraspRun) -> list[str]:
    """The recognition task's shape for every frame it found the object in."""
    return [str(f["shape"]) for f in run.vis_features if f.get("shape")]


# ------------------------------------------------------------------------------- contact
def first_contact(run: GraspRun) -> dict | None:
    """The plant's first ``contact`` event of the run (the physics: the touching link's point
    velocity against the object's just before), with the time each hand part first touched the
    object (``/object/contacts``)."""
    e = next((e for e in run.events if e["kind"] == "contact"), None)
    if e is None:
        return None
    return {"t": float(e["t"]), "speed": float(e["data"]["speed"]), "parts": e["data"]["parts"]}


def knock_speed(run: GraspRun) -> float:
    """The contact speed (m/s) that would knock the object a hold's tolerance out of the
    human's hand: a 1-D impulse m v on the object held by the human's spring k displaces it by
    v sqrt(m / k) (undamped), so v = grasp_max_drift sqrt(k / m)."""
    P = run.params
    return float(P.grasp_max_drift * np.sqrt(P.human_stiffness / P.object_mass))


# ------------------------------------------------------------------------------- grasp holds
def holds(run: GraspRun) -> list[dict]:
    """For each holding phase, from the plant's grasp event in it to the end of the phase, from
    the truth topics: the object's travel (path length, m) and span (m); its largest motion in
    the true hand frame since the grasp (``drift``, m); its largest distance from the human's
    path (``human``, m); the human's force on it (RMS, max, N); the hand's grip (summed contact
    normal force: mean, min, N); the drop/slip events. ``grasp`` None if the plant never
    reported the object held in that phase."""
    out = []
    rel = run.in_hand()
    for p in run.phases:
        if p.name != HOLDING:
            continue
        g = next((e for e in run.kinds("grasp") if p.t0 - 1e-9 <= e["t"] <= p.t1 + 1e-9), None)
        t0 = g["t"] if g is not None else p.t0
        wo = run.window(run.t_obj, t0, p.t1)
        if wo.sum() < 2:
            continue
        obj = run.obj[wo]
        r = rel[wo[: len(rel)]] if len(rel) else np.zeros((0, 3))
        wh = run.window(run.t_human, t0, p.t1)
        target = (
            np.column_stack(
                [np.interp(run.t_obj[wo], run.t_human, run.human[:, i]) for i in range(3)]
            )
            if len(run.t_human)
            else obj
        )
        f = np.linalg.norm(run.human_force[wh], axis=1) if wh.any() else np.zeros(1)
        wc = run.window(run.t_contacts, t0, p.t1)
        grip = run.grip_force[wc] if wc.any() else np.zeros(1)
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
                "drift": float(np.max(np.linalg.norm(r - r[0], axis=1))) if len(r) else np.nan,
                "human": float(np.max(np.linalg.norm(obj - target, axis=1))),
                "span": float(np.max(np.ptp(obj, axis=0))),
                "human_force_rms": float(np.sqrt(np.mean(f**2))),
                "human_force_max": float(np.max(f)),
                "grip_mean": float(np.mean(grip)),
                "grip_min": float(np.min(grip)),
            }
        )
    return out


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


# ------------------------------------------------------------------------------- eq. 1
def _quat_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def image_centre_error(run: GraspRun) -> dict | None:
    """The true object's direction from the head camera's optical axis (the image centre), in
    the chip's pixels (fov / width per pixel), from /head/state and /object/state: RMS and max
    over the run after its first 50 ms (the head's acquisition)."""
    if not len(run.t_head) or not len(run.t_obj):
        return None
    chip = ((run.scenario.get("sensors") or {}).get("chip") or {}).get("params") or {}
    fov = float(chip.get("fov", 0.0)) or None
    w = run.chip_size[0] or 16
    if fov is None:
        return None
    m = run.t_head >= run.t_head[0] + 0.05
    obj = run.obj_at(run.t_head[m])
    ang = []
    for c, q, o in zip(run.head_camera[m], run.head_orn[m], obj):
        d = _quat_matrix(q).T @ (o - c)
        ang.append(np.arctan2(np.hypot(d[0], d[1]), d[2]))
    px = np.asarray(ang) / (fov / w)
    return {"rms": float(np.sqrt(np.mean(px**2))), "max": float(np.max(px)), "px": fov / w}


# ------------------------------------------------------------------------------- Fig. 9 X
def reach_following(run: GraspRun) -> dict | None:
    """The hand's X (the plane's normal, truth x^a) against the reaching trajectory x_d^a along
    it during the reaching and releasing phases: the largest lag (m) and the distance left when
    each reach ends (m)."""
    m = run.in_phases(run.t_eff, (REACHING, RELEASING))
    if m.sum() < 2:
        return None
    d = run.hand[:, 0] - run.target[:, 0]
    travel = float(np.ptp(run.target[m, 0]))
    ends = []
    for p in run.phases:
        if p.name == REACHING:
            i = int(np.clip(np.searchsorted(run.t_eff, p.t1 - 1e-9), 0, len(d) - 1))
            ends.append(float(abs(d[i])))
    return {"max": float(np.max(np.abs(d[m]))), "ends": ends, "travel": travel}


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
