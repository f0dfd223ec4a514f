"""One grasping run's log (Namiki, Nakabo, Ishii & Ishikawa 1999) as arrays: what the figures and
the claims table of this paper read.

Frames: the constraint plane is the tracking plane of eq. 3 (y, z, roll tracked: s_i = 1), its
normal x the reaching direction (s_x = 0). The run's ``/effector/state`` gives the hand x^a
(``position``) and the reaching target x_d^a (``desired_position``); ``/object/state`` the
object's true pose (the "human hand" moves it); the schedule's phases come from the method's
state topic (``phase`` per control step) or, failing that, from the plant's grasp/release events.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import yaml

from analysis.series import events
from replay.log import LogReader

T_EFFECTOR = "/effector/state"
T_OBJECT = "/object/state"
T_ARM = "/arm/joint_state"
T_HAND = "/hand/joint_state"
T_HEAD = "/head/joint_state"
T_VISION = "/vision/object"
T_STATE = "/grasping/state"          # the method's per-step state: phase, preshape, shape ...
T_TASKS = "/tasks/timing"            # per task and step: its period and sensor-to-actuator latency

# the schedule's phases: what the hand does (the arm tracks in all of them)
REACHING, HOLDING, RELEASING, TRACKING = "reaching", "grasping", "releasing", "tracking"
GRASP_PHASES = (REACHING, HOLDING)   # shaded as "grasp" in Fig. 9


def _vec(rows: list[dict], key: str, width: int | None = None) -> np.ndarray:
    vals = [r.get(key) for r in rows]
    if not vals or any(v is None for v in vals):
        return np.zeros((0, width)) if width else np.zeros(0)
    a = np.array(vals, dtype=float)
    return a.reshape(len(rows), -1) if width else a


@dataclass
class Phase:
    name: str
    t0: float
    t1: float


@dataclass
class GraspRun:
    name: str
    scenario: dict
    t_eff: np.ndarray
    hand: np.ndarray                 # x^a position (n, 3)
    target: np.ndarray               # x_d^a position (n, 3), reaching target
    t_obj: np.ndarray
    obj: np.ndarray                  # (m, 3)
    obj_orn: np.ndarray              # (m, 4) xyzw
    t_arm: np.ndarray
    arm_q: np.ndarray
    arm_names: list
    t_hand: np.ndarray
    hand_q: np.ndarray
    hand_names: list
    t_head: np.ndarray
    head_q: np.ndarray
    t_vis: np.ndarray
    vis: np.ndarray
    vis_features: list
    state: list = field(default_factory=list)      # T_STATE messages
    tasks: list = field(default_factory=list)      # T_TASKS messages
    events: list = field(default_factory=list)
    phases: list = field(default_factory=list)     # [Phase]

    # ---------------------------------------------------------------- helpers
    @property
    def plant_params(self) -> dict:
        return (self.scenario.get("plant") or {}).get("params") or {}

    @property
    def t_end(self) -> float:
        ts = [a[-1] for a in (self.t_eff, self.t_obj, self.t_arm) if len(a)]
        return float(max(ts)) if ts else 0.0

    def kinds(self, kind: str) -> list[dict]:
        return [e for e in self.events if e["kind"] == kind]

    def outcome(self) -> dict:
        e = self.kinds("outcome")
        return e[-1]["data"] if e else {}

    def obj_at(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, float))
        return np.column_stack([np.interp(t, self.t_obj, self.obj[:, i]) for i in range(3)])

    def hand_at(self, t) -> np.ndarray:
        t = np.atleast_1d(np.asarray(t, float))
        return np.column_stack([np.interp(t, self.t_eff, self.hand[:, i]) for i in range(3)])

    def window(self, t: np.ndarray, start: float, end: float) -> np.ndarray:
        return (t >= start - 1e-9) & (t <= end + 1e-9)

    def in_phases(self, t: np.ndarray, names) -> np.ndarray:
        names = {names} if isinstance(names, str) else set(names)
        m = np.zeros(len(t), bool)
        for p in self.phases:
            if p.name in names:
                m |= (t >= p.t0 - 1e-9) & (t < p.t1 - 1e-9)
        return m

    def cycles(self) -> list[dict]:
        """Grasp cycles: each reaching phase, the holding phase after it and its release, with
        the plant's grasp event inside (None if it never came)."""
        out = []
        for i, p in enumerate(self.phases):
            if p.name != REACHING:
                continue
            hold = next((q for q in self.phases[i + 1:] if q.name == HOLDING), None)
            end = hold.t1 if hold else p.t1
            grasp = next((e for e in self.kinds("grasp") if p.t0 - 1e-9 <= e["t"] <= end), None)
            prev = next((q for q in reversed(self.phases[:i]) if q.name != REACHING), None)
            out.append({"reach": p, "hold": hold, "grasp": grasp,
                        "track_start": prev.t0 if prev is not None else self.phases[0].t0})
        return out


def _phases_from_state(state: list[dict]) -> list[Phase]:
    out: list[Phase] = []
    for m in state:
        name = m.get("phase")
        if name is None:
            continue
        if out and out[-1].name == name:
            out[-1].t1 = float(m["t"])
        else:
            if out:
                out[-1].t1 = float(m["t"])
            out.append(Phase(str(name), float(m["t"]), float(m["t"])))
    return out


def _phases_from_events(evs: list[dict], t_end: float) -> list[Phase]:
    """Without a state topic: tracking until each grasp command (or grasp event), holding until
    the release, releasing until the hand is open again (``release`` -> next ``open`` or 0.3 s)."""
    marks = [(e["t"], e["kind"]) for e in evs if e["kind"] in ("reach", "grasp", "release")]
    out, cur, t = [], TRACKING, 0.0
    for te, kind in marks:
        nxt = {"reach": REACHING, "grasp": HOLDING, "release": RELEASING}[kind]
        if nxt == cur:
            continue
        out.append(Phase(cur, t, te))
        cur, t = nxt, te
    out.append(Phase(cur, t, t_end))
    return [p for p in out if p.t1 > p.t0]


def load_run(log: LogReader, name: str | None = None) -> GraspRun:
    sc = yaml.safe_load(log.scenario()["yaml"])
    eff = [m for m in log.series(T_EFFECTOR) if m.get("position") and m.get("desired_position")]
    ob = log.series(T_OBJECT)
    arm = log.series(T_ARM)
    hj = log.series(T_HAND)
    hd = log.series(T_HEAD)
    vi = log.series(T_VISION)
    st = log.series(T_STATE)
    run = GraspRun(
        name=name or sc["name"], scenario=sc,
        t_eff=_vec(eff, "t"), hand=_vec(eff, "position", 3)[:, :3],
        target=_vec(eff, "desired_position", 3)[:, :3],
        t_obj=_vec(ob, "t"), obj=_vec(ob, "position", 3), obj_orn=_vec(ob, "orientation", 4),
        t_arm=_vec(arm, "t"), arm_q=_vec(arm, "position", 1),
        arm_names=list(arm[0]["name"]) if arm else [],
        t_hand=_vec(hj, "t"), hand_q=_vec(hj, "position", 1),
        hand_names=list(hj[0]["name"]) if hj else [],
        t_head=_vec(hd, "t"), head_q=_vec(hd, "position", 1),
        t_vis=_vec(vi, "t"), vis=_vec(vi, "position", 3),
        vis_features=[m.get("features") or {} for m in vi],
        state=st, tasks=log.series(T_TASKS), events=events(log))
    run.phases = _phases_from_state(st) or _phases_from_events(run.events, run.t_end)
    return run


def head_position(run: GraspRun) -> np.ndarray | None:
    """Where the pan/tilt head stands (world, m): the plant's or a sensor's ``head_position``."""
    p = run.plant_params.get("head_position")
    if p is None:
        for s in (run.scenario.get("sensors") or {}).values():
            p = ((s or {}).get("params") or {}).get("head_position")
            if p is not None:
                break
    return None if p is None else np.asarray(p, float)
