"""One grasping run's log (Namiki, Nakabo, Ishii & Ishikawa 1999) as arrays: what the figures and
the claims table of this paper read.

Frames (docs/DESIGN.md, "Grasping runs"): the constraint plane x = plane_x is the tracking plane of
eq. 3 (y, z, roll tracked: s_i = 1), its normal x the reaching direction (s_x = 0). The arm
task's ``/grasping/arm`` gives the hand x^a, the observed object x^o and the reaching target
x_d^a that eq. 2 used; ``/object/state`` the object's true pose (the "human hand" moves it); the
schedule's phases come from ``/grasping/state`` (``phase`` every step) or, failing that, from the
plant's grasp/release events.
"""

from __future__ import annotations

import copy

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from analysis.runs import once_per_reader
from analysis.series import events
from replay.log import LogReader

T_ARM_TASK = "/grasping/arm"  # x_a, x_o, x_d (eq. 2), per arm-task tick
T_OBJECT = "/object/state"
T_ARM = "/arm/joint_state"
T_HAND = "/hand/joint_state"
T_HEAD = "/head/state"  # pan, tilt, camera_position, camera_orientation
T_VISION = "/grasping/object"  # recognition: found, xi, phi, x_o, shape, ...
T_CHIP = "/vision/chip"  # the 16 x 16 binary images
T_HAND_TASK = "/grasping/hand"  # preshape, theta_d, load, command (eq. 4)
T_STATE = "/grasping/state"  # the schedule: phase, cycle, x_d, grasp
T_TASKS = "/tasks/loops"  # runner: names, ticked, latency per task, every step
T_EFFECTOR = "/effector/motion"  # the tool (= hand) frame's true pose
T_HUMAN = "/human/state"  # the human hand's path (target) and its force on the object
T_CONTACTS = "/object/contacts"  # parts touching the object and their normal force
T_HEAD_CMD = "/grasping/head"  # eq. 1: image error and command

# the schedule's phases: what the hand does (the arm tracks in all of them)
TRACKING, REACHING, HOLDING, RELEASING = "track", "reach", "hold", "release"
GRASP_PHASES = (REACHING, HOLDING)  # shaded as "grasp" in Fig. 9


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
    t_eff: np.ndarray  # arm-task ticks
    hand: np.ndarray  # x^a position (n, 3)
    target: np.ndarray  # x_d^a position (n, 3), reaching target
    seen: np.ndarray  # x^o position (n, 3), as eq. 2 used it
    t_obj: np.ndarray
    obj: np.ndarray  # (m, 3)
    obj_orn: np.ndarray  # (m, 4) xyzw
    t_arm: np.ndarray
    arm_q: np.ndarray
    arm_names: list
    t_hand: np.ndarray
    hand_q: np.ndarray
    hand_names: list
    t_head: np.ndarray
    head_q: np.ndarray
    head_camera: np.ndarray  # (k, 3) camera position
    head_orn: np.ndarray  # (k, 4) camera-to-world xyzw
    t_vis: np.ndarray  # recognition results (capture times)
    vis: np.ndarray  # x_o position (3) where found
    vis_features: list  # the /grasping/object messages
    t_chip: np.ndarray = field(default_factory=lambda: np.zeros(0))
    chip_size: tuple = (0, 0)
    hand_task: list = field(default_factory=list)  # T_HAND_TASK messages
    state: list = field(default_factory=list)  # T_STATE messages
    tasks: list = field(default_factory=list)  # T_TASKS messages
    events: list = field(default_factory=list)
    phases: list = field(default_factory=list)  # [Phase]
    t_tool: np.ndarray = field(default_factory=lambda: np.zeros(0))  # true tool frame
    tool: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    tool_orn: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))  # xyzw
    t_human: np.ndarray = field(default_factory=lambda: np.zeros(0))
    human: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # the path's point
    human_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # N, world
    t_contacts: np.ndarray = field(default_factory=lambda: np.zeros(0))
    grip_force: np.ndarray = field(default_factory=lambda: np.zeros(0))  # N, summed normals
    arm_task: list = field(default_factory=list)  # T_ARM_TASK messages (x_a, wrench, terms)

    # ---------------------------------------------------------------- helpers
    @property
    def plant_params(self) -> dict:
        return (self.scenario.get("plant") or {}).get("params") or {}

    @cached_property
    def params(self):
        """The rig's typed ``GraspParams``, rebuilt from the log's resolved scenario (every
        default the plant's own): its plant type's ``Params`` (an engine's settings included),
        the engine-free rig's where the type is not installed."""
        from plants.arm_rig.params import GraspParams
        from replay import registry
        from replay.scenario import params_from_data

        plant_type = str((self.scenario.get("plant") or {}).get("type"))
        cls = GraspParams
        if registry.known("plant", plant_type):
            cls = getattr(registry.load("plant", plant_type), "Params", GraspParams)
        return params_from_data(cls, self.plant_params, "plant.params")

    @property
    def t_end(self) -> float:
        ts = [a[-1] for a in (self.t_eff, self.t_obj, self.t_arm) if len(a)]
        return float(max(ts)) if ts else 0.0

    def in_hand(self) -> np.ndarray:
        """The object's centre in the true tool (= hand) frame at the object's samples (m):
        R^T (x - p), from /object/state and /effector/motion (truth only)."""
        n = min(len(self.t_obj), len(self.t_tool))
        out = np.zeros((n, 3))
        for i in range(n):
            x, y, z, w = self.tool_orn[i]
            R = np.array(
                [
                    [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                    [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                    [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
                ]
            )
            out[i] = R.T @ (self.obj[i] - self.tool[i])
        return out

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
            hold = next((q for q in self.phases[i + 1 :] if q.name == HOLDING), None)
            end = hold.t1 if hold else p.t1
            grasp = next((e for e in self.kinds("grasp") if p.t0 - 1e-9 <= e["t"] <= end), None)
            prev = next((q for q in reversed(self.phases[:i]) if q.name != REACHING), None)
            out.append(
                {
                    "reach": p,
                    "hold": hold,
                    "grasp": grasp,
                    "track_start": prev.t0 if prev is not None else self.phases[0].t0,
                }
            )
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
    """Without the schedule's state topic: the method's ``phase`` events."""
    out: list[Phase] = []
    for e in evs:
        if e["kind"] != "phase":
            continue
        if out:
            out[-1].t1 = float(e["t"])
        out.append(Phase(str(e["data"].get("phase")), float(e["t"]), t_end))
    return [p for p in out if p.t1 > p.t0]


def _first3(rows: list[dict], key: str) -> np.ndarray:
    return np.array([r[key][:3] for r in rows], dtype=float).reshape(len(rows), 3)


@once_per_reader
def load_run(log: LogReader, name: str | None = None) -> GraspRun:
    sc = copy.deepcopy(log.scenario_config())
    eff = [m for m in log.series(T_ARM_TASK) if m.get("x_a") and m.get("x_d") and m.get("x_o")]
    ob = log.series(T_OBJECT)
    arm = log.series(T_ARM)
    hj = log.series(T_HAND)
    hd = [m for m in log.series(T_HEAD) if m.get("camera_position")]
    vi = [m for m in log.series(T_VISION) if m.get("found") and m.get("position")]
    chip = log.series(T_CHIP)
    st = log.series(T_STATE)
    run = GraspRun(
        name=name or log.scenario().get("name") or "?",  # (clipped by the reader)
        scenario=sc,
        t_eff=_vec(eff, "t"),
        hand=_first3(eff, "x_a"),
        target=_first3(eff, "x_d"),
        seen=_first3(eff, "x_o"),
        t_obj=_vec(ob, "t"),
        obj=_vec(ob, "position", 3),
        obj_orn=_vec(ob, "orientation", 4),
        t_arm=_vec(arm, "t"),
        arm_q=_vec(arm, "position", 1),
        arm_names=list(arm[0]["name"]) if arm else [],
        t_hand=_vec(hj, "t"),
        hand_q=_vec(hj, "position", 1),
        hand_names=list(hj[0]["name"]) if hj else [],
        t_head=_vec(hd, "t"),
        head_q=np.array([[m["pan"], m["tilt"]] for m in hd], float),
        head_camera=_vec(hd, "camera_position", 3),
        head_orn=_vec(hd, "camera_orientation", 4),
        t_vis=_vec(vi, "t"),
        vis=_first3(vi, "position"),
        vis_features=vi,
        t_chip=_vec(chip, "t"),
        chip_size=(int(chip[0]["width"]), int(chip[0]["height"])) if chip else (0, 0),
        hand_task=log.series(T_HAND_TASK),
        state=st,
        tasks=log.series(T_TASKS),
        events=events(log),
    )
    run.arm_task = eff
    ef = [m for m in log.series(T_EFFECTOR) if m.get("position")]
    run.t_tool, run.tool = _vec(ef, "t"), _vec(ef, "position", 3)
    run.tool_orn = _vec(ef, "orientation", 4)
    hu = log.series(T_HUMAN)
    run.t_human, run.human = _vec(hu, "t"), _vec(hu, "target", 3)
    run.human_force = _vec(hu, "force", 3)
    co = log.series(T_CONTACTS)
    run.t_contacts, run.grip_force = _vec(co, "t"), _vec(co, "normal_force")
    run.phases = _phases_from_state(st) or _phases_from_events(run.events, run.t_end)
    return run


def head_camera_at(run: GraspRun, t: float) -> tuple[np.ndarray, np.ndarray] | None:
    """The head camera's position (m) and camera-to-world orientation (xyzw) at t."""
    if not len(run.t_head):
        return None
    i = int(np.clip(np.searchsorted(run.t_head, t + 1e-9) - 1, 0, len(run.t_head) - 1))
    return run.head_camera[i], run.head_orn[i]
