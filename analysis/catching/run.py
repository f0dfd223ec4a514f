"""One catching run's log as arrays (SI units) with its key instants (Namiki & Ishikawa 2003),
and which runs are the paper's own experiment: what the claims table and the figures read."""

from __future__ import annotations

import copy

from dataclasses import dataclass, field

import numpy as np

from analysis.series import events
from plants.arm_rig.settings import ArmSettings, resolve
from replay.log import LogReader
from replay.messages import (
    TOPIC_ARM_JOINT_COMMAND,
    TOPIC_ARM_JOINT_STATE,
    TOPIC_CATCHING_STATE,
    TOPIC_EFFECTOR_MOTION,
    TOPIC_EFFECTOR_STATE,
    TOPIC_HAND_JOINT_STATE,
    TOPIC_OBJECT_STATE,
    TOPIC_OPTIMIZATION_COST,
    TOPIC_VISION_OBJECT,
)
from analysis.runs import once_per_reader, typed_scenario

ACTIVE = (0, 1, 3)  # axes 1, 2, 4 (axis 3 locked, Sec. IV-A)

JOINTS = ("J1", "J2", "J4")

# the paper's own throws (Sec. IV-B: "about 8 ~ 10 m/s"), all with the optimised mapping
PAPER_THROWS = ("catch_8ms", "catch_optimised", "catch_10ms")

LIMITED = "catch_enforced_limits"  # catch_optimised with the arm held to its speed limits

FEEDBACK = "catch_feedback"  # the "simple feedback control" of Sec. IV-B (replay/control/feedback)

# the paper's own experiment (Sec. IV): its throws, the unoptimised mapping of Figs. 8, 9, and its
# arm held to the speed it states (5 m/s)
PAPER_RUNS = (*PAPER_THROWS, "catch_initial", LIMITED)

# methods the paper does not have: an approach-direction term, a clamp-aware eq. 25, and the
# simple feedback control it says hardly catches but never specifies (ours: replay/control/feedback)
EXTENSION_RUNS = ("catch_optimised_approach", "catch_optimised_clamped", FEEDBACK)


def scope(name: str) -> str:
    """A run's rows' kind: "measured" for the paper's own experiment (:data:`PAPER_RUNS`),
    "extension" for a method the paper does not have, else "other regime"."""
    if name in PAPER_RUNS:
        return "measured"
    return "extension" if name in EXTENSION_RUNS else "other regime"


def _scenario(log: LogReader) -> dict:
    return copy.deepcopy(log.scenario_config())


def _vec(rows: list[dict], key: str) -> np.ndarray:
    return np.array([r[key] for r in rows], dtype=float)


@dataclass
class CatchRun:
    """One catching run's log as arrays (SI units), plus its key instants."""

    name: str
    scenario: dict
    mapping: str
    dt: float
    # controller side, every control step: l(q) and l(q_d) (the catch point of eqs. 2-3)
    t_ctrl: np.ndarray
    effector: np.ndarray  # l(q)  (n, 3)
    effector_desired: np.ndarray  # l(q_d) (n, 3)
    q_desired: np.ndarray  # q_d (n, 4), /arm/joint_command
    torque: np.ndarray  # commanded tau (n, 4), /arm/joint_command
    # plant side (ground truth)
    t_arm: np.ndarray
    q: np.ndarray  # (m, 4)
    qd: np.ndarray
    t_obj: np.ndarray
    ball: np.ndarray  # (k, 3)
    ball_velocity: np.ndarray
    t_tool: np.ndarray
    tool_velocity: np.ndarray  # tool-frame linear velocity (/effector/motion)
    t_hand: np.ndarray
    hand_q: np.ndarray
    hand_qd: np.ndarray
    t_vision: np.ndarray
    vision: np.ndarray
    settings: ArmSettings  # the arm plant's, from the log's resolved scenario
    cs_t: np.ndarray = field(default_factory=lambda: np.zeros(0))  # /catching/state
    cs_qd_desired: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)))
    cs_r_o: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    costs: list = field(default_factory=list)
    events: list = field(default_factory=list)
    t0: float | None = None
    t_c: float | None = None

    # -------------------------------------------------------------- helpers
    def first_event(self, kind: str) -> dict | None:
        return next((e for e in self.events if e["kind"] == kind), None)

    def ball_at(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """True ball position and velocity at t (interpolated between logged states)."""
        pos = np.array([np.interp(t, self.t_obj, self.ball[:, i]) for i in range(3)])
        vel = np.array([np.interp(t, self.t_obj, self.ball_velocity[:, i]) for i in range(3)])
        return pos, vel

    def ctrl_index(self, t: float) -> int:
        return int(np.argmin(np.abs(self.t_ctrl - t)))

    def window(self, t: np.ndarray, start: float, end: float) -> np.ndarray:
        return (t >= start - 1e-9) & (t <= end + 1e-9)

    @property
    def plant_params(self) -> dict:
        return self.scenario["plant"]["params"]

    @property
    def controller_params(self) -> dict:
        return self.scenario["controller"]["params"]


@once_per_reader
def load_run(log: LogReader, name: str | None = None) -> CatchRun:
    sc = _scenario(log)
    typed = typed_scenario(log)
    eff = [m for m in log.series(TOPIC_EFFECTOR_STATE) if m["desired_position"] and m["position"]]
    cmd = log.series(TOPIC_ARM_JOINT_COMMAND)
    cmd_t = {round(m["t"], 9): m for m in cmd}
    eff = [m for m in eff if round(m["t"], 9) in cmd_t]
    cmd = [cmd_t[round(m["t"], 9)] for m in eff]
    js = log.series(TOPIC_ARM_JOINT_STATE)
    ob = log.series(TOPIC_OBJECT_STATE)
    mo = log.series(TOPIC_EFFECTOR_MOTION)
    hj = log.series(TOPIC_HAND_JOINT_STATE)
    vi = log.series(TOPIC_VISION_OBJECT)
    cs = log.series(TOPIC_CATCHING_STATE)
    ev = events(log)
    ctrl, plant = typed.controller, typed.plant.params
    if ctrl is None or isinstance(plant, dict):  # (tasks, or a plant this version lacks)
        raise ValueError("not a catch run: its scenario has no controller or no known arm plant")
    run = CatchRun(
        name=name or log.scenario().get("name") or "?",  # (clipped by the reader)
        scenario=sc,
        # the typed scenario: no default here; a run of another controller (the feedback
        # baseline) has no mapping and is named by its controller
        mapping=str(getattr(ctrl.params, "mapping", ctrl.type)),
        dt=1.0 / float(ctrl.rate),
        t_ctrl=_vec(eff, "t"),
        effector=_vec(eff, "position").reshape(-1, 3),
        effector_desired=_vec(eff, "desired_position").reshape(-1, 3),
        q_desired=_vec(cmd, "position"),
        torque=_vec(cmd, "torque"),
        t_arm=_vec(js, "t"),
        q=_vec(js, "position"),
        qd=_vec(js, "velocity"),
        t_obj=_vec(ob, "t"),
        ball=_vec(ob, "position").reshape(-1, 3),
        ball_velocity=_vec(ob, "velocity").reshape(-1, 3),
        t_tool=_vec(mo, "t"),
        tool_velocity=_vec(mo, "velocity").reshape(-1, 3),
        t_hand=_vec(hj, "t"),
        hand_q=_vec(hj, "position"),
        hand_qd=_vec(hj, "velocity"),
        t_vision=_vec(vi, "t"),
        vision=_vec(vi, "position").reshape(-1, 3),
        costs=sorted(log.series(TOPIC_OPTIMIZATION_COST), key=lambda c: c["iteration"]),
        cs_t=_vec(cs, "t"),
        cs_qd_desired=_vec(cs, "velocity_desired"),
        cs_r_o=_vec(cs, "r_o").reshape(-1, 3),
        settings=resolve(plant),
        events=ev,
    )
    run.t0 = float(cs[0]["t"]) if cs else None
    hold = run.first_event("mapping_hold")
    if hold is not None:
        run.t_c = float(hold["t"]) - run.dt
    return run


def optimised_and_initial(runs: dict[str, CatchRun]) -> tuple[CatchRun | None, CatchRun | None]:
    """The optimised run and the initial-mapping run of the same throw (catch_optimised and
    catch_initial when there), either None when missing."""
    opt, ini = runs.get("catch_optimised"), runs.get("catch_initial")
    if opt is None:
        opt = next((r for r in runs.values() if r.mapping == "optimised"), None)
    if ini is None and opt is not None:
        v = opt.plant_params.get("object_velocity")
        ini = next(
            (
                r
                for r in runs.values()
                if r.mapping == "initial" and r.plant_params.get("object_velocity") == v
            ),
            None,
        )
    return opt, ini
