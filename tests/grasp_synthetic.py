"""A small synthetic grasping log (Namiki et al. 1999) written with the log contract's topics, for
the figures', claims' and viewer's tests before (and besides) real runs. Kinematic make-believe:
the object moves on the plane x = PLANE_X, the hand follows it in y, z with a fixed lag (no
prediction), reaches along x on a given schedule, and the joint angles come from the WAM-7's own
kinematics (damped least squares), so the drawn arm and the logged hand agree.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from analysis.grasping.run import (
    HOLDING,
    REACHING,
    RELEASING,
    T_ARM,
    T_ARM_TASK,
    T_CHIP,
    T_HAND,
    T_HAND_TASK,
    T_HEAD,
    T_OBJECT,
    T_STATE,
    T_TASKS,
    T_VISION,
    TRACKING,
)
from replay.log import LogWriter, seconds_to_ns
from replay.messages import Event, JointState, ObjectState, ScenarioInfo
from replay.spatial import matrix_to_quaternion
from tests.replay.robot.oracles import tool_position

PLANE_X = 0.65
STANDOFF = 0.15  # m, the hand's distance from the plane while only tracking
GRIP_X = PLANE_X - 0.04  # the palm's x when grasping (box half depth + palm)
LAG = 0.003  # s, the tracking lag
# (phase, start): track, reach, hold, release, track, reach, hold
SCHEDULE = [
    (TRACKING, 0.0),
    (REACHING, 0.5),
    (HOLDING, 0.8),
    (RELEASING, 1.3),
    (TRACKING, 1.5),
    (REACHING, 1.7),
    (HOLDING, 2.0),
]
TASKS = ["vision", "head", "arm", "hand"]
HEAD = [0.0, -0.6, 0.9]


def _phase(t: float) -> str:
    name = SCHEDULE[0][0]
    for n, t0 in SCHEDULE:
        if t >= t0 - 1e-12:
            name = n
    return name


def _phase_start(t: float) -> float:
    return max(t0 for _, t0 in SCHEDULE if t0 <= t + 1e-12)


def object_path(t: float) -> np.ndarray:
    return np.array(
        [
            PLANE_X,
            0.05 * math.sin(2 * math.pi * 0.7 * t) + 0.02 * math.sin(2 * math.pi * 1.6 * t + 1.0),
            0.55 + 0.02 * math.sin(2 * math.pi * 0.9 * t),
        ]
    )


def _reach_x(t: float) -> float:
    ph = _phase(t)
    s = min(max((t - _phase_start(t)) / (0.8 - 0.5), 0.0), 1.0)
    if ph == REACHING:
        return PLANE_X - STANDOFF + (GRIP_X - PLANE_X + STANDOFF) * s
    if ph == HOLDING:
        return GRIP_X
    if ph == RELEASING:
        s = min((t - _phase_start(t)) / 0.2, 1.0)
        return GRIP_X + (PLANE_X - STANDOFF - GRIP_X) * s
    return PLANE_X - STANDOFF


def write_grasp_log(
    path,
    *,
    duration: float = 2.3,
    rate: int = 500,
    obj: str = "box",
    name: str = "synthetic_grasp",
    lag: float = LAG,
    slip_at: float | None = None,
) -> Path:
    """``lag`` < 0 makes the hand lead the object (as a predictor would); ``slip_at`` adds a
    ``slip`` event and lets the object slide off the palm from then on."""
    from replay.robot.hand import GRASP4
    from replay.robot.wam import wam_chain, wam_joint_names

    chain = wam_chain(7)
    names = list(wam_joint_names(7))
    params = {
        "arm": "wam7",
        "tool_d": -1.0,
        "base_position": [0.0, 0.0, 0.0],
        "base_rpy": [0.0, 0.0, 0.0],
        "initial_q": [0.0, 0.9, 0.0, 1.6, 0.0, -0.9, 0.0],
        "initial_qd": [],
        "locked_joints": [],
        "torque_limit_set": "public_urdf",
        "torque_limits": [],
        "velocity_limits": [],
        "hand": "grasp4",
        "hand_initial": [],
        "object": obj,
        "object_radius": 0.03,
        "object_size": [0.05, 0.05, 0.05],
        "object_position": object_path(0.0).tolist(),
        "plane_normal": [1.0, 0.0, 0.0],
        "head_position": HEAD,
    }
    sc = {
        "name": name,
        "paper": "namiki1999",
        "description": "synthetic grasping log",
        "seed": 0,
        "timing": {"physics_rate": rate, "duration": duration},
        "plant": {"type": "grasp_rig", "params": params},
        "sensors": {
            "chip": {
                "type": "vision_chip",
                "rate": float(rate),
                "params": {"fov": 0.21, "width": 16, "height": 16},
            }
        },
        "controller": {"type": "none", "rate": float(rate), "params": {}},
        "tasks": {k: {"rate": float(rate)} for k in TASKS},
        "stop": {"on_events": [], "after": 0.0},
        "notes": "",
    }
    text = yaml.safe_dump(sc, sort_keys=False)
    n = int(round(duration * rate))
    q = np.array(params["initial_q"], float)
    h_open = GRASP4.open_posture
    h_closed = GRASP4.closed_posture
    preshape = "rectangle" if obj == "box" else "circle"
    with LogWriter(path) as log:
        log.write("/scenario", ScenarioInfo(0.0, name, "namiki1999", text, 0, "synthetic"), 0)
        prev_phase = None
        for k in range(n + 1):
            t = k / rate
            ns = seconds_to_ns(t)
            ph = _phase(t)
            o = object_path(t)
            if slip_at is not None and t >= slip_at:
                o = o + np.array([0.0, 0.0, -0.2 * (t - slip_at)])
                if t - slip_at < 0.5 / rate:
                    log.write(
                        "/events", Event(t, "slip", {"speed": 0.2, "position": o.tolist()}), ns
                    )
            lagged = object_path(max(t - lag, 0.0))
            goal = np.array([_reach_x(t), lagged[1], lagged[2]])
            for _ in range(1 if k else 60):  # damped least squares to the goal
                J = chain.position_jacobian(q)
                e = goal - tool_position(chain, q)
                q = q + J.T @ np.linalg.solve(J @ J.T + 1e-4 * np.eye(3), e)
            hand = tool_position(chain, q)
            if ph != prev_phase:
                log.write("/events", Event(t, "phase", {"phase": ph, "cycle": 0}), ns)
                kind = {HOLDING: "grasp", RELEASING: "release"}.get(ph)
                if kind:
                    data = {"parts": ["palm", "index", "thumb"]} if kind == "grasp" else {}
                    log.write("/events", Event(t, kind, {**data, "position": o.tolist()}), ns)
                prev_phase = ph
            close = {
                REACHING: min((t - _phase_start(t)) / 0.3, 1.0),
                HOLDING: 1.0,
                RELEASING: max(1.0 - (t - _phase_start(t)) / 0.1, 0.0),
            }.get(ph, 0.0)
            hq = h_open + close * (h_closed - h_open)
            log.write(T_ARM, JointState(t, names, q.tolist(), [0.0] * 7, [0.0] * 7), ns)
            log.write(
                T_HAND,
                JointState(t, list(GRASP4.joint_names), hq.tolist(), [0.0] * 14, [0.0] * 14),
                ns,
            )
            d = o - np.array(HEAD)
            pan, tilt = math.atan2(d[1], d[0]), math.atan2(d[2], math.hypot(d[0], d[1]))
            log.write(
                "/head/joint_state",
                JointState(t, ["pan", "tilt"], [pan, tilt], [0.0, 0.0], [0.0, 0.0]),
                ns,
            )
            z = d / np.linalg.norm(d)  # optical axis at the object
            x = np.cross(z, [0.0, 0.0, 1.0])
            x /= np.linalg.norm(x)
            R = np.column_stack([x, np.cross(z, x), z])  # OpenCV: x right, y down, z ahead
            log.write(
                T_HEAD,
                {
                    "t": t,
                    "pan": pan,
                    "tilt": tilt,
                    "velocity": [0.0, 0.0],
                    "camera_position": HEAD,
                    "camera_orientation": matrix_to_quaternion(R).tolist(),
                },
                ns,
            )
            seen = object_path(max(t - 0.001, 0.0))
            six = lambda p: [*p, 0.0, 0.0, 0.0]  # noqa: E731
            log.write(
                T_ARM_TASK,
                {
                    "t": t,
                    "x_a": six(hand.tolist()),
                    "x_o": six(seen.tolist()),
                    "x_d": six([_reach_x(t), lagged[1], lagged[2]]),
                },
                ns,
            )
            log.write(
                T_OBJECT,
                ObjectState(t, o.tolist(), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]),
                ns,
            )
            # the truth of the hand (the tool frame), the human's path (the object's own, off
            # which a slipping object slides) and the grip
            log.write(
                "/effector/motion",
                {"t": t, "position": hand.tolist(), "orientation": [0.0, 0.0, 0.0, 1.0]},
                ns,
            )
            log.write(
                "/human/state",
                {"t": t, "target": object_path(t).tolist(), "force": [0.0, 0.0, 1.0]},
                ns,
            )
            held = ph == HOLDING and (slip_at is None or t < slip_at)
            log.write("/object/contacts", {"t": t, "normal_force": 20.0 if held else 0.0}, ns)
            log.write(
                T_CHIP,
                {
                    "t": t,
                    "width": 16,
                    "height": 16,
                    "rows": [0x07C0 if 5 <= v < 10 else 0 for v in range(16)],
                    "count": 20,
                },
                ns,
            )
            log.write(
                T_VISION,
                {
                    "t": t - 0.001,
                    "found": True,
                    "xi": [8.0, 8.0],
                    "phi": 0.0,
                    "area": 20,
                    "position": seen.tolist(),
                    "x_o": six(seen.tolist()),
                    "shape": preshape,
                },
                ns,
            )
            log.write(T_HAND_TASK, {"t": t, "preshape": preshape, "theta_d": hq.tolist()}, ns)
            log.write(
                T_STATE,
                {
                    "t": t,
                    "phase": ph,
                    "cycle": 0,
                    "x_d": six([_reach_x(t), 0, 0]),
                    "grasp": ph in (REACHING, HOLDING),
                },
                ns,
            )
            log.write(
                T_TASKS,
                {
                    "t": t,
                    "names": TASKS,
                    "ticked": [True] * 4,
                    "latency": [0.001, 0.001, 0.0012, 0.0011],
                },
                ns,
            )
        log.write(
            "/events",
            Event(duration, "outcome", {"success": True, "reason": "completed"}),
            seconds_to_ns(duration),
        )
    return Path(path)
