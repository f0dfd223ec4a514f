"""The catch's measured quantities, each from one run's arrays (:mod:`analysis.catching.run`):
errors at the catch, contact, approach, hand closing, tool speeds, vision accuracy, and the arm
model's capability."""

from __future__ import annotations

import math

import numpy as np

from analysis.catching.run import ACTIVE, CatchRun
from plants.arm_rig.settings import ArmSettings


# ------------------------------------------------------------------------ per-run quantities
def terminal_error(run: CatchRun) -> dict | None:
    """Eq. 4 at t_c with eq. 5's r_e = l(q_d) - r_o, r_o being what the mapping used (from
    ``/catching/state``): |r_e(t_c)| (m) and the mean |r_e'| over the last control step (m/s),
    which falls to 0 as r_o reaches the catch surface (r_e vanishes to second order there).
    Also |l(q_d) - r_o| with the *true* ball (vision error, latency compensation, a ball already
    deflected by the hand) and the ball's arrival speed."""
    if run.t_c is None or len(run.cs_t) < 2:
        return None
    k = run.ctrl_index(run.t_c)
    i = int(np.argmin(np.abs(run.cs_t - run.t_ctrl[k])))
    if k < 1 or i < 1 or abs(run.cs_t[i] - run.t_ctrl[k]) > 1e-9:
        return None
    re = run.effector_desired[k] - run.cs_r_o[i]
    re_prev = run.effector_desired[k - 1] - run.cs_r_o[i - 1]
    rate = float(np.linalg.norm(re - re_prev)) / (run.t_ctrl[k] - run.t_ctrl[k - 1])
    ball, _ = run.ball_at(run.t_ctrl[k])
    return {
        "r_e": float(np.linalg.norm(re)),
        "rate": rate,
        "r_e_true": float(np.linalg.norm(run.effector_desired[k] - ball)),
        "speed": arrival_speed(run),
    }


def initial_error(run: CatchRun) -> tuple[float, float, float] | None:
    """Eq. 9 at t_0: max |q_d - q| (rad) at the first mapped step, and max |qd_d| (rad/s) at the
    instant t_s the true ball passes r_o(t_0) = ``throw_start`` (where eq. 13 imposes it),
    extrapolated linearly from the first two steps with a fitted ball velocity (the first step
    has one frame: no velocity yet). Returns (dq, qd_d, t_s)."""
    if run.t0 is None or len(run.cs_t) < 3:
        return None
    k = run.ctrl_index(run.t0)
    j = int(np.argmin(np.abs(run.t_arm - run.t_ctrl[k])))
    dq = float(np.max(np.abs(run.q_desired[k, list(ACTIVE)] - run.q[j, list(ACTIVE)])))
    start = np.asarray(run.controller_params.get("throw_start", run.ball[0]), float)
    t_s = float(run.t_obj[int(np.argmin(np.linalg.norm(run.ball - start, axis=1)))])
    (t1, t2), (w1, w2) = run.cs_t[1:3], run.cs_qd_desired[1:3]
    w_s = w1 + (w2 - w1) * (t_s - t1) / (t2 - t1)
    return dq, float(np.max(np.abs(w_s[list(ACTIVE)]))), t_s


def arrival_speed(run: CatchRun) -> float | None:
    """The ball's speed as it reaches the hand: just before the first contact if that precedes
    t_c (the ball is deflected then), else at t_c."""
    c = run.first_event("contact")
    if c is not None and (run.t_c is None or c["t"] <= run.t_c + 1e-9):
        return float(np.linalg.norm(c["data"]["object_velocity_before"]))
    if run.t_c is None:
        return None
    return float(np.linalg.norm(run.ball_at(run.t_c)[1]))


def first_contact(run: CatchRun) -> dict | None:
    """The first ball-robot contact: time, parts, relative speed, and |l(q) - r_o| there."""
    c = run.first_event("contact")
    if c is None:
        return None
    k = run.ctrl_index(c["t"])
    ball, _ = run.ball_at(run.t_ctrl[k])
    return {
        "t": c["t"],
        "parts": c["data"].get("parts", []),
        "speed": c["data"].get("speed"),
        "normal_speed": c["data"].get("normal_speed"),
        "distance": float(np.linalg.norm(run.effector[k] - ball)),
    }


def closest_approach(run: CatchRun, until: float | None = None) -> tuple[float, float]:
    """min of |l(q) - r_o| (m) up to ``until`` (default: the whole run) and when: how near the
    palm's catch point came to the ball's centre."""
    ball = np.column_stack([np.interp(run.t_ctrl, run.t_obj, run.ball[:, i]) for i in range(3)])
    d = np.linalg.norm(run.effector - ball, axis=1)
    if until is not None:
        d = np.where(run.t_ctrl <= until + 1e-9, d, np.inf)
    k = int(np.argmin(d))
    return float(d[k]), float(run.t_ctrl[k])


def throw_speed(run: CatchRun) -> tuple[float, float | None] | None:
    """Ball speed when first seen (t0) and as it reaches the hand, from the plant's truth."""
    if run.t0 is None:
        return None
    return float(np.linalg.norm(run.ball_at(run.t0)[1])), arrival_speed(run)


def hand_closing(run: CatchRun) -> dict | None:
    """From the hand_close command: when every finger joint reached 90 deg, or where the ball
    stopped them, and the peak finger speed."""
    e = run.first_event("hand_close")
    if e is None or not len(run.t_hand):
        return None
    w = run.t_hand >= e["t"] - 1e-9
    t, hq, hqd = run.t_hand[w], run.hand_q[w], run.hand_qd[w]
    target = math.pi / 2
    done = np.all(hq >= target - 1e-3, axis=1)
    out = {"t_cmd": e["t"], "peak_speed": float(np.max(np.abs(hqd))) if len(hqd) else 0.0}
    if done.any():
        out["time"] = float(t[np.argmax(done)] - e["t"])
    else:
        out["stopped_at"] = float(np.degrees(np.max(hq[: int(min(len(hq), 0.03 / run.dt))])))
    return out


def tool_peaks(run: CatchRun, until: float | None) -> tuple[float, float]:
    """Peak tool speed (m/s) and peak tool acceleration (m/s^2, over 5 ms differences) from the
    start of the run until ``until`` (the first contact: no impact shocks)."""
    w = run.t_tool <= (until if until is not None else np.inf) + 1e-9
    v = run.tool_velocity[w]
    t = run.t_tool[w]
    speed = float(np.max(np.linalg.norm(v, axis=1))) if len(v) else float("nan")
    n = 5
    if len(v) > n:
        acc = np.linalg.norm(v[n:] - v[:-n], axis=1) / (t[n:] - t[:-n])
        return speed, float(np.max(acc))
    return speed, float("nan")


def vision_accuracy(run: CatchRun) -> tuple[float, float, float] | None:
    """Measured rate (Hz), median and worst |r_o measured - truth| (m) at the capture times."""
    if len(run.t_vision) < 2:
        return None
    truth = np.column_stack([np.interp(run.t_vision, run.t_obj, run.ball[:, i]) for i in range(3)])
    err = np.linalg.norm(run.vision - truth, axis=1)
    rate = (len(run.t_vision) - 1) / (run.t_vision[-1] - run.t_vision[0])
    return float(rate), float(np.median(err)), float(np.max(err))


# ------------------------------------------------------------------------ the arm model
def arm_capability(arm: ArmSettings) -> dict:
    """What the scenario's arm model can do at the tool: max speed with its joint-speed limits
    (at q0 and over a sample of the joint-limit box, locked axes at q0) and acceleration from
    rest at q0 with its torque limits (replay.robot.capability)."""
    from replay.robot.capability import max_tool_speed, tool_acceleration_from_rest

    dof = arm.dof
    chain = arm.chain()
    vel = arm.velocity_limits.tolist()
    tau = arm.torque_limits.tolist()
    q0 = arm.initial_q
    act = list(arm.active)
    rng = np.random.default_rng(0)
    Q = rng.uniform(arm.lower, arm.upper, size=(400, dof))
    for i in range(dof):
        if i not in act:
            Q[:, i] = q0[i]
    v_q0 = max_tool_speed(chain, q0, vel, act)
    v_max = max(max_tool_speed(chain, q, vel, act) for q in Q)
    per_rad = max_tool_speed(chain, q0, [1.0] * dof, act)
    acc = tool_acceleration_from_rest(chain, q0, tau, act)
    return {
        "v_q0": v_q0,
        "v_max": v_max,
        "per_rad": per_rad,
        "vel_limits": vel,
        "tau_limits": tau,
        "acc_peak": acc["peak"],
        "acc_iso": acc["isotropic"],
    }


def run_outcome(run: CatchRun) -> dict | None:
    """The run's ``outcome`` event data (the plant's verdict with its first-touch metrics)."""
    ev = [e for e in run.events if e["kind"] == "outcome"]
    return ev[-1]["data"] if ev else None


def opt_limits(run: CatchRun) -> tuple[list, list]:
    cp = run.controller_params
    tau, vel = run.settings.torque_limits.tolist(), run.settings.velocity_limits.tolist()
    t = cp.get("opt_torque_limits") or [tau[i] for i in ACTIVE]
    w = cp.get("opt_velocity_limits") or [vel[i] for i in ACTIVE]
    return t, w
