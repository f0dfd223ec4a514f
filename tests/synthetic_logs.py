"""Small synthetic logs for the viewer's tests, benchmark and screenshots (no simulator).

``write_stick_log``: a stick sliding and spinning on the air table, two fingertips on a moving
slider base, two collisions and a rest; a 300 fps camera. ``write_arm_log``: a WAM-4 with the
3-finger catching hand swinging while a ball flies into the palm (catch event), or a WAM-7
with the 4-finger hand and a spinning box (grasp event); a stereo pair.
The motion is kinematic make-believe written with ``LogWriter``: shapes, not physics.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import yaml

from replay.log import LogWriter, seconds_to_ns
from replay.messages import (
    TOPIC_ARM_JOINT_COMMAND,
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_STATE,
    TOPIC_EVENTS,
    TOPIC_FINGERS_STATE,
    TOPIC_HAND_JOINT_STATE,
    TOPIC_HAND_STATE,
    TOPIC_OBJECT_STATE,
    TOPIC_SCENARIO,
    TOPIC_STICK_STATE,
    TOPIC_VISION_OBJECT,
    TOPIC_VISION_STICK,
    EffectorState,
    Event,
    FingersState,
    JointCommand,
    JointState,
    ObjectState,
    ScenarioInfo,
    StickState,
    VisionObject,
    VisionStick,
)
from tests.replay.robot.oracles import tool_position


def _scenario(name: str, paper: str, duration: float, rate: int, plant: dict, sensors: dict) -> str:
    return yaml.safe_dump(
        {
            "name": name,
            "paper": paper,
            "description": "synthetic log for the viewer",
            "seed": 0,
            "timing": {"physics_rate": rate, "duration": duration, "state_log_rate": 0},
            "plant": plant,
            "sensors": sensors,
            "controller": {"type": "none", "rate": float(rate), "params": {}},
            "stop": {"on_events": [], "after": 0.0},
            "notes": "",
        },
        sort_keys=False,
    )


def _finger_tips(base, joints, l1=0.07, l2=0.07, roots=((-0.03, 0.0), (0.03, 0.0))):
    out = []
    for (rx, ry), (q1, q2) in zip(roots, joints):
        out.append(
            [
                base[0] + rx + l1 * math.cos(q1) + l2 * math.cos(q1 + q2),
                base[1] + ry + l1 * math.sin(q1) + l2 * math.sin(q1 + q2),
            ]
        )
    return out


def write_stick_log(
    path,
    *,
    duration: float = 1.0,
    rate: int = 1000,
    length: float = 0.1,
    name: str = "synthetic_stick",
    spin: float = 4.0,
) -> Path:
    """A stick log like the air-table plant's (topics and fields of docs/DESIGN.md)."""
    params = {
        "stick": {
            "mass": 0.0225,
            "inertia": 3.2e-5,
            "length": length,
            "collision_width": 0.0,
            "visual_width": 0.01,
            "thickness": 0.005,
            "marker_length": 0.8 * length,
            "marker_width": 0.006,
            "restitution": 0.19,
            "friction": 0.3,
        },
        "initial": {"x": -0.15, "y": 0.30, "theta": 0.3, "vx": 0.6, "vy": -0.7, "omega": spin},
        "hand": {
            "link_lengths": [0.07, 0.07],
            "root_offset0": [-0.03, 0.0],
            "root_offset1": [0.03, 0.0],
            "tip_radius": 0.005,
            "tip_height": 0.02,
            "base": [0.0, 0.0],
            "joints0": [2.0, -1.0],
            "joints1": [math.pi - 2.0, 1.0],
        },
    }
    sensors = {
        "camera": {
            "type": "stick_camera",
            "rate": 300.0,
            "latency": 0.003,
            "params": {
                "position": [0.0, 0.15, 0.7],
                "target": [0.0, 0.15, 0.0],
                "up": [0.0, 1.0, 0.0],
                "width": 256,
                "height": 256,
                "fov_x": 0.6,
            },
        }
    }
    text = _scenario(
        name, "higashimori2007", duration, rate, {"type": "airtable", "params": params}, sensors
    )
    rng = np.random.default_rng(0)
    hits = [(0.2, 0, (0.15, -0.05), -2.0), (0.45, 1, (0.02, -0.01), 0.5)]
    n = int(round(duration * rate))
    x, y, th = params["initial"]["x"], params["initial"]["y"], params["initial"]["theta"]
    v, w = (params["initial"]["vx"], params["initial"]["vy"]), spin
    cam_div = max(1, int(round(rate / 300.0)))
    with LogWriter(path) as log:
        log.write(
            TOPIC_SCENARIO, ScenarioInfo(0.0, name, "higashimori2007", text, 0, "synthetic"), 0
        )
        for k in range(n + 1):
            t = k / rate
            t_ns = seconds_to_ns(t)
            base = [0.0, min(t, 0.15) * 0.2]
            joints = [[2.0 - 0.3 * min(t, 0.3), -1.0], [math.pi - 2.0 + 0.3 * min(t, 0.3), 1.0]]
            tips = _finger_tips(base, joints)
            for t_hit, finger, v_after, w_after in hits:
                if abs(t - t_hit) < 0.5 / rate:
                    log.write(
                        TOPIC_EVENTS,
                        Event(
                            t,
                            "collision",
                            {
                                "index": hits.index((t_hit, finger, v_after, w_after)) + 1,
                                "finger": finger,
                                "r_x": 0.02,
                                "r_y": 0.0,
                                "theta": th,
                                "v_before": list(v),
                                "omega_before": w,
                                "v_after": list(v_after),
                                "omega_after": w_after,
                                "contact": tips[finger],
                                "planned": {"r_x": 0.02},
                            },
                        ),
                        t_ns,
                    )
                    v, w = v_after, w_after
            log.write(TOPIC_STICK_STATE, StickState(t, x, y, th, v[0], v[1], w), t_ns)
            log.write(TOPIC_FINGERS_STATE, FingersState(t, tips), t_ns)
            log.write(
                TOPIC_HAND_STATE,
                {
                    "t": t,
                    "base": base,
                    "joints": joints,
                    "base_target": base,
                    "joint_targets": joints,
                },
                t_ns,
            )
            if k % cam_div == 0:
                e = rng.normal(0.0, 0.0005, 3)
                log.write(
                    TOPIC_VISION_STICK, VisionStick(t, x + e[0], y + e[1], th + 10 * e[2]), t_ns
                )
            if abs(t - 0.9) < 0.5 / rate:
                log.write(TOPIC_EVENTS, Event(t, "rest", {"x": x, "y": y}), t_ns)
            x, y, th = x + v[0] / rate, y + v[1] / rate, th + w / rate
    return Path(path)


def write_arm_log(
    path,
    *,
    duration: float = 0.8,
    rate: int = 1000,
    name: str = "synthetic_catch",
    swing: float = 0.6,
    arm: str = "wam4",
    hand: str = "catch3",
    obj: str = "ball",
    limit_events: int = 0,
    outcome: bool = False,
) -> Path:
    """An arm log like the PyBullet arm plant's: a WAM (4 axes with J3 locked, as for catching,
    or 7), its hand closing (``catch3`` / ``grasp4``), a ball or a spinning box that flies into
    the hand (``obj="none"``: no object). ``limit_events``: that many ``torque_limit`` /
    ``velocity_limit`` events (alternating, one a step from the first), as a plant at its limits
    floods the log; ``outcome``: an ``outcome`` event at the end."""
    from replay.robot.hand import HANDS
    from replay.robot.wam import wam_chain, wam_joint_names

    dof = 4 if arm == "wam4" else 7
    q0 = [0.0, math.pi / 4, 0.0, 1.2] if dof == 4 else [0.0, 0.6, 0.0, 1.6, 0.0, 0.5, 0.0]
    locked = ["J3"] if dof == 4 else []
    table = HANDS.get(hand)
    hand_names = list(table.joint_names) if table else []
    h_open = table.open_posture if table else np.zeros(0)
    h_closed = table.closed_posture if table else np.zeros(0)
    params = {
        "arm": arm,
        "tool_d": -1.0,
        "base_position": [0.0, 0.0, 0.0],
        "base_rpy": [0.0, 0.0, 0.0],
        "initial_q": q0,
        "initial_qd": [],
        "locked_joints": locked,
        "torque_limit_set": "public_urdf",
        "torque_limits": [],
        "velocity_limits": [],
        "hand": hand if table else "none",
        "hand_initial": [],
        "object": obj,
        "object_radius": 0.0175,
        "object_size": [0.05, 0.04, 0.03],
        "object_position": [1.5, 0.0, 1.0],
    }
    sensors = {
        "stereo": {
            "type": "stereo_ball",
            "rate": 1000.0,
            "latency": 0.001,
            "params": {
                "cam0_position": [0.4, -1.2, 1.3],
                "cam0_target": [0.6, 0.0, 0.9],
                "cam1_position": [0.8, -1.2, 1.3],
                "cam1_target": [0.6, 0.0, 0.9],
                "fov": 0.7,
            },
        }
    }
    paper = "namiki2003" if obj == "ball" else "namiki1999"
    text = _scenario(name, paper, duration, rate, {"type": "arm_rig", "params": params}, sensors)
    chain = wam_chain(dof)
    names = list(wam_joint_names(dof))
    n = int(round(duration * rate))
    t_catch = 0.5 * duration
    moving = [0, 1, 3]

    def q_at(t):
        s = 0.5 * (1.0 - math.cos(math.pi * min(t / t_catch, 1.0)))
        q = np.array(q0, dtype=float)
        q[moving] += swing * s * np.array([0.4, 0.3, -0.8])
        return q

    grip = tool_position(chain, q_at(t_catch))
    p0 = np.array(params["object_position"])
    g = np.array([0.0, 0.0, -9.81])
    v0 = (grip - p0 - 0.5 * g * t_catch**2) / t_catch
    kind = "catch" if obj == "ball" else "grasp"
    with LogWriter(path) as log:
        log.write(TOPIC_SCENARIO, ScenarioInfo(0.0, name, paper, text, 0, "synthetic"), 0)
        q_prev = q_at(0.0)
        for k in range(n + 1):
            t = k / rate
            t_ns = seconds_to_ns(t)
            q = q_at(t)
            qd = (q - q_prev) * rate
            q_prev = q
            tau = 5.0 * np.sin(2 * math.pi * t / duration + np.arange(dof))
            tau[[names.index(j) for j in locked]] = 0.0
            close = min(max((t - 0.8 * t_catch) / 0.02, 0.0), 1.0)
            log.write(
                TOPIC_ARM_JOINT_STATE,
                JointState(t, names, q.tolist(), qd.tolist(), tau.tolist()),
                t_ns,
            )
            if table:
                hq = h_open + close * (h_closed - h_open)
                log.write(
                    TOPIC_HAND_JOINT_STATE,
                    JointState(t, hand_names, hq.tolist(), [0.0] * len(hq), [0.0] * len(hq)),
                    t_ns,
                )
            log.write(TOPIC_ARM_JOINT_COMMAND, JointCommand(t, q.tolist(), tau.tolist()), t_ns)
            tool = tool_position(chain, q)
            log.write(TOPIC_EFFECTOR_STATE, EffectorState(t, tool.tolist(), grip.tolist()), t_ns)
            if obj == "none":
                continue
            if t <= t_catch:
                pos, vel = p0 + v0 * t + 0.5 * g * t * t, v0 + g * t
            else:
                pos, vel = tool, np.zeros(3)
            yaw = 6.0 * min(t, t_catch)
            log.write(
                TOPIC_OBJECT_STATE,
                ObjectState(
                    t,
                    pos.tolist(),
                    [0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)],
                    vel.tolist(),
                    [0.0, 0.0, 6.0 if t <= t_catch else 0.0],
                ),
                t_ns,
            )
            if t <= t_catch:
                log.write(TOPIC_VISION_OBJECT, VisionObject(t, (pos + 0.002).tolist()), t_ns)
            if abs(t - t_catch) < 0.5 / rate:
                log.write(
                    TOPIC_EVENTS,
                    Event(t, "contact", {"parts": ["palm"], "position": pos.tolist()}),
                    t_ns,
                )
            if abs(t - (t_catch + 0.05)) < 0.5 / rate:
                log.write(
                    TOPIC_EVENTS,
                    Event(t, kind, {"parts": ["palm", "f1", "f2"], "position": pos.tolist()}),
                    t_ns,
                )
            if 1 <= k <= limit_events:
                limit = ("torque_limit", "velocity_limit")[k % 2]
                log.write(TOPIC_EVENTS, Event(t, limit, {"joint": names[k % dof]}), t_ns)
            if outcome and k == n:
                log.write(TOPIC_EVENTS, Event(t, "outcome", {"success": True}), t_ns)
    return Path(path)


def write_hostile_log(
    path,
    *,
    name: str,
    paper: str = "higashimori2007",
    kinds: tuple[str, ...] = (),
    field: str = "",
    yaml_text: str | None = None,
    duration: float = 0.2,
    rate: int = 100,
) -> Path:
    """A small stick log whose strings are someone else's: ``name`` and ``paper`` in its
    /scenario message (and YAML), an event of each of ``kinds`` besides a ``collision`` and a
    ``rest``, a /stick/state field called ``field`` whose length changes (the viewer notes it by
    name), and ``yaml_text`` as the stored scenario YAML if given."""
    text = yaml_text
    if text is None:
        text = _scenario(name, paper, duration, rate, {"type": "airtable", "params": {}}, {})
    n = int(round(duration * rate))
    with LogWriter(path) as log:
        log.write(TOPIC_SCENARIO, ScenarioInfo(0.0, name, paper, text, 0, "synthetic"), 0)
        for k in range(n + 1):
            t = k / rate
            state = {"t": t, "x": 0.5 * t - 0.05, "y": 0.2, "theta": 3.0 * t}
            state |= {"vx": 0.5, "vy": 0.0, "omega": 3.0}
            if field:
                state[field] = [1.0] * (1 + k % 2)
            log.write(TOPIC_STICK_STATE, state, seconds_to_ns(t))
        kinds = ("collision", *kinds, "rest")
        for i, kind in enumerate(kinds):
            t = duration * (i + 1) / (len(kinds) + 1)
            log.write(TOPIC_EVENTS, Event(t, kind, {"reason": kind}), seconds_to_ns(t))
    return Path(path)
