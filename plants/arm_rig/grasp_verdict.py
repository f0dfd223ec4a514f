"""The grasping rig's physical verdict, engine-free: a component the rig owns
(``GraspRig.verdict``), fed each step with that step's truth (``GraspReading``) and events, which
keeps its own record (each grasp's drift in the hand, its distance to the human's path, the
object's distance off its plane, slips, the tracking error before the grasp) and gives the run's
``outcome``. Every engine's grasp rig is judged by this one criterion.

It reads nothing of the rig: the plane, its in-plane axes and the criteria (``GraspParams``) are
given once, the readings each step (``GraspVerdict.observe``).
"""

from __future__ import annotations

import math
from collections import deque
from typing import NamedTuple, Sequence

from plants.arm_rig.params import GraspParams
from replay.interfaces import Occurrence
from replay.robot.arm_types import PlaneSpec


class GraspReading(NamedTuple):
    """One step's truth for the verdict (world frame, plain floats)."""

    t: float  # s
    pos: Sequence[float]  # m: the object's centre
    tool: tuple  # the tool (= hand) frame: (position m, orientation [qx, qy, qz, qw], ...)
    parts: Sequence[str]  # the robot's parts touching the object, sorted ("arm" among them)
    normal_force: float  # N: the contacts' total normal force
    held: bool  # the rig holds the object (its hold event's state)
    human_target: Sequence[float]  # m: the human's path point now
    human_force: Sequence[float]  # N: the human's force on the object over the last step


def in_hand_position(pos, tool: tuple) -> list[float]:
    """The object's centre ``pos`` in the tool (= hand) frame ``tool`` (m): R^T (x - p)."""
    (px, py, pz), (qx, qy, qz, qw) = tool[0], tool[1]
    dx, dy, dz = pos[0] - px, pos[1] - py, pos[2] - pz
    # the columns of R(q) dotted with d
    return [
        (1 - 2 * (qy * qy + qz * qz)) * dx
        + 2 * (qx * qy + qz * qw) * dy
        + 2 * (qx * qz - qy * qw) * dz,
        2 * (qx * qy - qz * qw) * dx
        + (1 - 2 * (qx * qx + qz * qz)) * dy
        + 2 * (qy * qz + qx * qw) * dz,
        2 * (qx * qz + qy * qw) * dx
        + 2 * (qy * qz - qx * qw) * dy
        + (1 - 2 * (qx * qx + qy * qy)) * dz,
    ]


class GraspVerdict:
    """The physical verdict's record and outcome. ``plane``: the object's constraint plane;
    ``u``, ``v``: its in-plane unit axes (the tracking error's components); ``P``: the
    criteria; ``dt``: the step (s)."""

    def __init__(self, P: GraspParams, plane: PlaneSpec, u, v, dt: float) -> None:
        self.params = P
        self._point = [float(x) for x in plane.point]
        self._normal = [float(x) for x in plane.normal]
        self._u, self._v = [float(x) for x in u], [float(x) for x in v]
        self._grasps: list[dict] = []
        self._grasp_start = 0.0
        self._slipping = False
        self._slips = 0
        self._held_path = 0.0
        self._window = max(1, round(P.slip_time / dt)) + 1  # steps: slip_time and its start
        self._in_hand: deque = deque(maxlen=self._window)
        self._off_plane = 0.0  # m, the largest |(x - plane point) . n| of the run
        self._off_plane_t = 0.0
        self._max_parts = 0
        self._touched: set = set()
        self._track_sq = 0.0
        self._track_n = 0
        self._last_pos: Sequence[float] | None = None

    def observe(self, r: GraspReading, events: Sequence[Occurrence]) -> list[Occurrence]:
        """Record the step ``r`` after the rig's events of this step (``events``: a ``grasp``
        starts a grasp's record and gets its ``normal_force``, a ``release`` ends it and gets
        its ``held_for``); the step's ``slip`` events."""
        for ev in events:
            if ev.kind == "grasp":
                self._start_grasp(r, ev)
            elif ev.kind == "release" and self._grasps:
                held = r.t - self._grasp_start
                self._grasps[-1]["held_for"] = held
                ev.data["held_for"] = held
        self._contacts_and_plane(r)
        slips: list[Occurrence] = []
        if r.held and self._grasps:
            slips = self._holding(r)
        else:
            self._slipping = False
            self._in_hand.clear()
            self._tracking(r)
        self._last_pos = r.pos
        return slips

    def _start_grasp(self, r: GraspReading, ev: Occurrence) -> None:
        """A grasp's record, from its event (which began ``hold_time`` before it)."""
        self._grasp_start = r.t - ev.data.get("hold_time", 0.0)
        ev.data["normal_force"] = float(r.normal_force)
        self._grasps.append(
            {
                "t": self._grasp_start,
                "held_for": None,
                "in_hand": in_hand_position(r.pos, r.tool),
                "drift": 0.0,
                "human": 0.0,
                "force_sq": 0.0,
                "force_max": 0.0,
                "n": 0,
            }
        )
        self._in_hand.clear()

    def _contacts_and_plane(self, r: GraspReading) -> None:
        """The hand parts touched and the run's distance off the plane."""
        parts = r.parts
        n_hand = len(parts) - ("arm" in parts)
        if n_hand:
            self._touched.update(x for x in parts if x != "arm")
        self._max_parts = max(self._max_parts, n_hand)
        ox, oy, oz = r.pos
        (cx, cy, cz), (nx, ny, nz) = self._point, self._normal
        off = abs((ox - cx) * nx + (oy - cy) * ny + (oz - cz) * nz)
        if off > self._off_plane:
            self._off_plane, self._off_plane_t = off, r.t

    def _holding(self, r: GraspReading) -> list[Occurrence]:
        """While grasped: the path held, the grasp's drift in the hand, its distance to the
        human's path and the human's force; a ``slip`` when the object moved >= slip_distance
        in the hand within slip_time (sustained relative motion), over when it moves less
        than half of that."""
        pos = r.pos
        ox, oy, oz = pos
        if self._last_pos is not None:
            lx, ly, lz = ox - self._last_pos[0], oy - self._last_pos[1], oz - self._last_pos[2]
            self._held_path += math.sqrt(lx * lx + ly * ly + lz * lz)
        g = self._grasps[-1]
        h = in_hand_position(pos, r.tool)
        g["drift"] = max(g["drift"], math.dist(h, g["in_hand"]))
        g["human"] = max(g["human"], math.dist(pos, r.human_target))
        fx, fy, fz = r.human_force
        f2 = fx * fx + fy * fy + fz * fz
        g["force_sq"] += f2
        g["force_max"] = max(g["force_max"], math.sqrt(f2))
        g["n"] += 1
        buf = self._in_hand
        buf.append(h)
        if len(buf) < self._window:
            return []
        d = math.dist(h, buf[0])
        P = self.params
        if d >= P.slip_distance and not self._slipping:
            self._slips += 1
            self._slipping = True
            return [Occurrence("slip", {"distance": d, "position": list(pos)})]
        if self._slipping and d < 0.5 * P.slip_distance:
            self._slipping = False
        return []

    def _tracking(self, r: GraspReading) -> None:
        """Before a grasp: the hand's in-plane distance to the object (the tracking error)."""
        ox, oy, oz = r.pos
        ex, ey, ez = r.tool[0]
        dx, dy, dz = ox - ex, oy - ey, oz - ez
        (ux, uy, uz), (vx, vy, vz) = self._u, self._v
        du = dx * ux + dy * uy + dz * uz
        dv = dx * vx + dy * vy + dz * vz
        self._track_sq += du**2 + dv**2
        self._track_n += 1

    # ------------------------------------------------------------------ verdict
    def outcome(self, t: float) -> dict:
        """The physical verdict (truth only): success needs the object grasped and **held**
        (within ``grasp_max_drift`` of where it sat in the hand, every grasp), **with the
        human** (within ``grasp_max_human_offset`` of the human's path while grasped, every
        grasp), **on its plane** (within ``grasp_max_off_plane`` all run), one grasp at least
        ``grasp_min_hold`` long and the object moved while held; a failure names every
        criterion it missed."""
        grasps = self._grasps
        holds = [(g["held_for"] if g["held_for"] is not None else t - g["t"]) for g in grasps]
        drift = max((g["drift"] for g in grasps), default=0.0)
        human = max((g["human"] for g in grasps), default=0.0)
        n_held = sum(g["n"] for g in grasps)
        out = {
            "success": True,
            "reason": "grasped and held with the human",
            "grasps": len(grasps),
            "first_grasp_t": grasps[0]["t"] if grasps else None,
            "hold_time": float(sum(holds)),
            "longest_hold": max(holds, default=0.0),
            "held_path": self._held_path,
            "slips": self._slips,
            "hold_drift_max": drift,
            "hold_human_offset_max": human,
            "off_plane_max": self._off_plane,
            "hold_human_force_rms": (
                math.sqrt(sum(g["force_sq"] for g in grasps) / n_held) if n_held else None
            ),
            "hold_human_force_max": max((g["force_max"] for g in grasps), default=None),
            "tracking_error_rms": (
                math.sqrt(self._track_sq / self._track_n) if self._track_n else None
            ),
            "hand_parts_touched": sorted(self._touched),
        }
        why = self._misses(holds, drift, human)
        if why:
            out["success"] = False
            out["reason"] = "; ".join(why)
        return out

    def _misses(self, holds: list, drift: float, human: float) -> list[str]:
        """Every criterion the run missed, in words."""
        P = self.params
        why: list[str] = []
        if not self._grasps:
            if not self._touched:
                why.append("no grasp: the hand never touched the object")
            else:
                why.append(
                    f"no grasp: touched by {', '.join(sorted(self._touched))} "
                    f"(at most {self._max_parts} parts at once, "
                    f"{P.catch_min_parts} needed) but never held still against "
                    "the palm"
                )
        else:
            if len(self._grasps) < P.grasp_min_grasps:
                why.append(f"only {len(self._grasps)} of {P.grasp_min_grasps} grasps")
            if max(holds) < P.grasp_min_hold - 1e-9:
                why.append(
                    f"grasp not held: longest hold {max(holds):.3f} s < {P.grasp_min_hold:g} s"
                )
            if drift > P.grasp_max_drift:
                why.append(
                    f"not held: the object moved {1e3 * drift:.1f} mm in the hand "
                    f"(> {1e3 * P.grasp_max_drift:g} mm)"
                )
            if human > P.grasp_max_human_offset:
                why.append(
                    f"carried away from the human: {1e3 * human:.1f} mm off the human's path "
                    f"(> {1e3 * P.grasp_max_human_offset:g} mm)"
                )
            if self._held_path <= 1e-3:
                why.append("held, but the object did not move while grasped")
        if self._off_plane > P.grasp_max_off_plane:
            why.append(
                f"off its plane: {1e3 * self._off_plane:.1f} mm at {self._off_plane_t:.3f} s "
                f"(> {1e3 * P.grasp_max_off_plane:g} mm)"
            )
        return why
