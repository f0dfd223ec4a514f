"""Namiki, Nakabo, Ishii & Ishikawa 1999, Figs. 6-9, drawn from runs' logs.

- Fig. 9 ("Feedback Response"): the hand x^a and the object along Y (the tracking of eq. 2's
  first term; with the human's path) and the hand and the reaching target x_d^a along X (its
  second term), against time, and the forces of the hold: the human's force on the object
  (truth) and the wrist's external force F^a that eq. 2's K^af term acts on; the schedule's
  grasp phases (reaching and holding) and releasing phases shaded.
- Figs. 6-8 (the grasp as a sequence of pictures, the close-up, the sphere): a filmstrip of the
  first grasp cycle drawn from the log: the WAM-7 from its kinematics (``replay.robot.wam``) at the
  logged joint angles, the 14-joint hand (``replay.robot.hand``) at the logged hand angles, the
  object at its logged pose, the head and its line of sight, in one fixed oblique view.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from analysis import runs as run_labels  # noqa: E402
from analysis.figure_files import save  # noqa: E402
from analysis.line_labels import MORE, first  # noqa: E402
from analysis.needs import has  # noqa: E402
from analysis.grasping.run import (
    GRASP_PHASES,
    REACHING,
    RELEASING,
    T_ARM,
    T_ARM_TASK,
    T_OBJECT,
    GraspRun,  # noqa: E402
    head_camera_at,
    load_run,
)
from replay.log import LogReader  # noqa: E402
from replay.scenario.yamlio import one_line  # noqa: E402
from replay.spatial import quaternion_matrix  # noqa: E402

C_OBJ, C_HAND, C_TARGET = "tab:orange", "tab:blue", "tab:green"
SHADE = {"grasp": ("tab:blue", 0.10), RELEASING: ("tab:red", 0.10)}
EVENT_KINDS = ("grasp", "release", "drop", "slip")
VIEW = (math.radians(-125.0), math.radians(22.0))  # azimuth, elevation of the filmstrip view
# what each figure reads (the contract a grasping controller fulfils: docs/grasping.md)
TOPICS = {"Fig. 9": (T_ARM_TASK, T_OBJECT), "filmstrip": (T_ARM, T_OBJECT)}


# ----------------------------------------------------------------------------- Fig. 9
def _shade(ax, run: GraspRun, labels: bool = False) -> set[str]:
    """Shade the grasp and releasing phases, draw the plant's events and slip ticks; returns
    what was drawn (for the figure's footer: it explains only those)."""
    drawn: set[str] = set()
    keys = ((p, _shade_key(p.name)) for p in run.phases)
    phases, more = first((p, key) for p, key in keys if key is not None)
    marked, more_marked = first(
        e for e in run.events if e["kind"] in EVENT_KINDS and e["kind"] != "slip"
    )
    slips, more_slips = first(e["t"] for e in run.events if e["kind"] == "slip")
    drawn.update(("more",) if more or more_marked or more_slips else ())
    for p, key in phases:
        color, alpha = SHADE[key]
        ax.axvspan(p.t0, p.t1, color=color, alpha=alpha, lw=0)
        drawn.add(key)
        if labels and p.name in (REACHING, RELEASING):
            ax.annotate(
                "grasp" if p.name == REACHING else "release",
                (p.t0, 1.0),
                xycoords=("data", "axes fraction"),
                xytext=(2, -9),
                textcoords="offset points",
                fontsize=7,
                color="0.3",
            )
    for e in marked:
        ax.axvline(e["t"], color="0.45", lw=0.7, ls=":" if e["kind"] != "drop" else "-")
        drawn.add(e["kind"])
    if slips:  # a rug along the bottom edge
        ax.plot(
            slips,
            [0.02] * len(slips),
            "|",
            color="tab:red",
            ms=6,
            transform=ax.get_xaxis_transform(),
        )
        drawn.add("slip")
    return drawn


def _shade_key(phase: str) -> str | None:
    """What a phase is shaded as: a grasp phase, releasing, or not shaded (None)."""
    return "grasp" if phase in GRASP_PHASES else phase if phase == RELEASING else None


def _footer(drawn: set[str]) -> str:
    """Fig. 9's footer: the axes, then only the shading and marks that are drawn."""
    said = []
    if "grasp" in drawn:
        said.append("blue: grasp phases (reach, hold)")
    if RELEASING in drawn:
        said.append("red: releasing")
    events = [k for k in ("grasp", "release") if k in drawn]
    if events:
        said.append(f"dotted: the plant's {' and '.join(events)} event{'s' * (len(events) > 1)}")
    if "drop" in drawn:
        said.append("solid grey: drop")
    said.append("red ticks at the bottom: slip events" if "slip" in drawn else "no slip event")
    said += [MORE] if "more" in drawn else []
    return (
        "Y: tracking on the constraint plane (S = 1); X: reaching along its normal (S = 0).\n"
        + "; ".join(said)
    )


def fig9(run: GraspRun, key: str = ""):
    fig, (ax_y, ax_x, ax_f) = plt.subplots(
        3, 1, sharex=True, figsize=(7.0, 6.8), gridspec_kw={"height_ratios": [3, 3, 2]}
    )
    if len(run.t_human):
        ax_y.plot(run.t_human, run.human[:, 1], color="0.55", lw=0.9, ls=":", label="human's path")
    ax_y.plot(run.t_obj, run.obj[:, 1], color=C_OBJ, lw=1.4, label="object (truth)")
    ax_y.plot(run.t_eff, run.hand[:, 1], color=C_HAND, lw=1.2, label="hand x^a")
    ax_x.plot(
        run.t_eff, run.target[:, 0], color=C_TARGET, lw=1.4, ls="--", label="reaching target x_d^a"
    )
    ax_x.plot(run.t_eff, run.hand[:, 0], color=C_HAND, lw=1.2, label="hand x^a")
    ax_x.plot(run.t_obj, run.obj[:, 0], color=C_OBJ, lw=0.8, alpha=0.7, label="object (truth)")
    if len(run.t_human):
        ax_f.plot(
            run.t_human,
            np.linalg.norm(run.human_force, axis=1),
            color=C_OBJ,
            lw=1.0,
            label="the human's force on the object",
        )
    wr = [m for m in run.arm_task if m.get("wrench")] if run.arm_task else []
    if wr:
        ax_f.plot(
            [m["t"] for m in wr],
            [float(np.linalg.norm(m["wrench"][:3])) for m in wr],
            color=C_HAND,
            lw=0.9,
            label="F^a: external force at the wrist (eq. 2)",
        )
    drawn: set[str] = set()
    for ax, name in ((ax_y, "Y [m]"), (ax_x, "X [m]"), (ax_f, "force [N]")):
        ax.set_ylabel(name)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower right" if ax is not ax_f else "upper right")
        ax.set_xlim(0.0, run.t_end)
        drawn |= _shade(ax, run, labels=ax is ax_y)
    ax_f.set_xlabel("time [s]")
    ax_y.set_title(f"Feedback response: {one_line(key or run.name)} (cf. Fig. 9)", fontsize=10)
    fig.text(
        0.01,
        0.005,
        _footer(drawn),
        fontsize=7,
        color="0.35",
        va="bottom",
    )
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    return fig


# ----------------------------------------------------------------------------- filmstrip
def _project(p: np.ndarray) -> np.ndarray:
    """Orthographic view from VIEW: world points (..., 3) -> picture (..., 2)."""
    az, el = VIEW
    right = np.array([-math.sin(az), math.cos(az), 0.0])
    up = np.array([-math.cos(az) * math.sin(el), -math.sin(az) * math.sin(el), math.cos(el)])
    return np.stack([p @ right, p @ up], axis=-1)


class _Robot:
    """The run's arm and hand models, from the rig's own settings (``plants.bullet_arm``'s
    resolver on the log's ``plant.params``)."""

    def __init__(self, params) -> None:
        from plants.arm_rig.settings import resolve

        arm = resolve(params)
        self.chain = arm.chain()
        self.hand = arm.hand

    def segments(self, q_arm, q_hand) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
        """Arm polyline (world), finger polylines (world), palm corners (world)."""
        from replay.robot.hand import finger_frames

        frames = self.chain.frames(q_arm)
        tool = frames[-1] @ self.chain.tool
        arm = np.array([T[:3, 3] for T in frames] + [tool[:3, 3]])
        fingers, palm = [], np.zeros((0, 3))
        if self.hand is not None:
            k = 0
            for f in self.hand.fingers:
                n = len(f.joints)
                q = q_hand[k : k + n] if len(q_hand) >= k + n else np.zeros(n)
                pts = [(tool @ T)[:3, 3] for T in finger_frames(f, q)]
                fingers.append(np.array(pts))
                k += n
            sx, sy, sz = self.hand.palm_size
            c = np.array([[sx, sy], [sx, -sy], [-sx, -sy], [-sx, sy], [sx, sy]]) / 2.0
            if self.hand.palm_shape == "cylinder":
                a = np.linspace(0, 2 * math.pi, 17)
                c = np.column_stack([sx * np.cos(a), sx * np.sin(a)])
            local = np.column_stack([c, np.full(len(c), sz), np.ones(len(c))])
            palm = (tool @ local.T).T[:, :3]
        return arm, fingers, palm


def _object_outline(run: GraspRun, i: int) -> tuple[str, np.ndarray]:
    p = run.params
    pos = run.obj[i]
    if p.object == "ball":
        return "circle", np.array([*_project(pos), p.object_radius])
    size = np.asarray(p.object_size, float) / 2.0
    R = quaternion_matrix(run.obj_orn[i]) if len(run.obj_orn) else np.eye(3)
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    world = pos + (corners * size) @ R.T
    edges = [
        (a, b) for a in range(8) for b in range(a + 1, 8) if np.sum(corners[a] != corners[b]) == 1
    ]
    return "box", np.array([[_project(world[a]), _project(world[b])] for a, b in edges])


def filmstrip_times(run: GraspRun, n: int = 6) -> list[tuple[float, str]]:
    """The first grasp cycle: tracking (start, middle), reaching (start, middle), the grasp, and
    holding while the object moves on."""
    cycles = run.cycles()
    if not cycles:
        ts = np.linspace(0.0, run.t_end, n)
        return [(float(t), "") for t in ts]
    c = cycles[0]
    r = c["reach"]
    t_g = c["grasp"]["t"] if c["grasp"] else r.t1
    t_hold_end = c["hold"].t1 if c["hold"] else min(t_g + 0.3, run.t_end)
    picks = [
        (c["track_start"], "tracking"),
        ((c["track_start"] + r.t0) / 2.0, "tracking"),
        (r.t0, "reaching starts"),
        ((r.t0 + t_g) / 2.0, "reaching"),
        (t_g, "grasped" if c["grasp"] else "reach ends"),
        ((t_g + t_hold_end) / 2.0, "holding, object moving"),
    ]
    return [(float(min(max(t, 0.0), run.t_end)), s) for t, s in picks[:n]]


def _index(t_series: np.ndarray, t: float) -> int:
    return int(min(max(np.searchsorted(t_series, t + 1e-9) - 1, 0), len(t_series) - 1))


def filmstrip(run: GraspRun, title: str):
    robot = _Robot(run.params)
    picks = filmstrip_times(run)
    fig, axes = plt.subplots(2, 3, figsize=(9.6, 6.6))
    near = [_project(run.obj)]  # the close-up frames the hand and the object
    drawn = []
    for t, label in picks:
        ia, io = _index(run.t_arm, t), _index(run.t_obj, t)
        qh = run.hand_q[_index(run.t_hand, t)] if len(run.t_hand) else np.zeros(0)
        arm, fingers, palm = robot.segments(run.arm_q[ia], qh)
        drawn.append((t, label, arm, fingers, palm, io))
        near += [_project(f) for f in fingers] + [_project(arm[-1:])]
    pts = np.concatenate(near)
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    half = max(float(np.max(pts.max(axis=0) - pts.min(axis=0))) / 2.0 + 0.08, 0.15)
    lo, hi = centre - half, centre + half
    for ax, (t, label, arm, fingers, palm, io) in zip(axes.ravel(), drawn):
        trail = run.window(run.t_obj, t - 0.3, t)
        ax.plot(*_project(run.obj[trail]).T, color=C_OBJ, lw=0.8, alpha=0.6)
        kind, shape = _object_outline(run, io)
        if kind == "circle":
            ax.add_patch(
                plt.Circle(
                    (float(shape[0]), float(shape[1])),
                    float(shape[2]),
                    color=C_OBJ,
                    alpha=0.55,
                    zorder=1,
                )
            )
        else:
            for a, b in shape:
                ax.plot([a[0], b[0]], [a[1], b[1]], color=C_OBJ, lw=1.2)
        a2 = _project(arm)
        ax.plot(*a2.T, "-o", color="0.25", lw=3.0, ms=3)
        if len(palm):
            ax.fill(*_project(palm).T, color="0.55", alpha=0.8, lw=0)
        for f in fingers:
            ax.plot(*_project(f).T, "-", color=C_HAND, lw=1.6, zorder=3)
        cam = head_camera_at(run, t)
        if cam is not None:  # the head camera and its optical axis (OpenCV z)
            axis = cam[0] + quaternion_matrix(cam[1])[:, 2] * np.linalg.norm(run.obj[io] - cam[0])
            h2, a2 = _project(cam[0]), _project(axis)
            ax.plot(*h2, "s", color="0.2", ms=6)
            ax.plot([h2[0], a2[0]], [h2[1], a2[1]], color="tab:purple", lw=0.7, ls="--")
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"t = {t:.3f} s  {label}", fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.text(
        0.01,
        0.005,
        "close-up drawn from the log: WAM-7 joint frames (grey), palm and 14-joint hand "
        "(blue), object and its last 0.3 s (orange),\nhead camera and its optical axis "
        f"(purple, as long as the distance to the object); view azimuth {math.degrees(VIEW[0]):.0f}°, elevation {math.degrees(VIEW[1]):.0f}°",
        fontsize=7,
        color="0.35",
        va="bottom",
    )
    fig.tight_layout(rect=(0, 0.02, 1, 0.96))
    return fig


def make_figures(logs: dict[str, LogReader], out: Path) -> list[Path]:
    """Fig. 9 and the filmstrip (Figs. 6-8) for every grasping run."""
    out = Path(out)
    paths: list[Path] = []
    for name, log in sorted(logs.items()):
        if not has({name: log}, TOPICS["Fig. 9"], "grasp Fig. 9"):
            continue
        run = load_run(log, name)
        titled = run_labels.titled(name, log)  # (a variant: what it changes)
        paths += save(fig9(run, titled), out, f"{name}_fig9", [name])
        if has({name: log}, TOPICS["filmstrip"], "grasp filmstrip (Figs. 6-8)"):
            what = (
                "a sphere (cf. Fig. 8)"
                if run.params.object == "ball"
                else "a hexahedron (cf. Figs. 6, 7)"
            )
            paths += save(
                filmstrip(run, f"Grasping of {what}: {titled}"), out, f"{name}_filmstrip", [name]
            )
    return paths
