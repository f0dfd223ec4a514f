"""The grasping rig's physical verdict, engine-free: the record kept each step from the truth
(each grasp's drift in the hand, its distance to the human's path, the object's distance off its
plane, slips, the tracking error before the grasp) and the run's ``outcome``. Shared by the
PyBullet rig (``grasp_plant.BulletGraspPlant``) and the MuJoCo one, so both engines are judged
by the same criterion.

Its state is the rig's (``grasp_rig.GraspRig``, its base): the plane, the human, the object's
state, the tool frame (``engine.effector_now``) and the contacts (``engine.contact_summary``).
"""

from __future__ import annotations

import math
from collections import deque
import numpy as np

from plants.arm_rig.grasp_rig import GraspRig
from plants.arm_rig.params import GraspParams
from replay.interfaces import Occurrence


class GraspVerdict(GraspRig):
    def __init__(self, params: GraspParams, *, dt: float, rng: np.random.Generator) -> None:
        super().__init__(params, dt=dt, rng=rng)
        self._start_verdict(params.slip_time, dt)

    def _start_verdict(self, slip_time: float, dt: float) -> None:
        """The verdict's record, empty."""
        self._grasps: list[dict] = []
        self._grasp_start = 0.0
        self._slipping = False
        self._slips = 0
        self._held_path = 0.0
        self._in_hand: deque = deque(maxlen=max(1, round(slip_time / dt)) + 1)
        self._off_plane = 0.0  # m, the largest |(x - plane point) . n| of the run
        self._off_plane_t = 0.0
        self._max_parts = 0
        self._touched: set = set()
        self._track_sq = 0.0
        self._track_n = 0
        self._last_pos: tuple | None = None

    def _in_hand_position(self, pos) -> list[float]:
        """The object's centre in the tool (= hand) frame (m): R^T (x - p)."""
        (px, py, pz), (qx, qy, qz, qw), _, _ = self.engine.effector_now()
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

    def _judge_step(self) -> None:
        """After a step: the servos' torque_limit events, the arm rig's events and the
        verdict's record."""
        self._servo_limit_events()
        n_before = len(self._events)
        self._check_events()
        self._grasp_bookkeeping(n_before)

    def _grasp_bookkeeping(self, n_before: int) -> None:
        """The physical verdict's record, from the truth of this step: each grasp's drift in
        the hand, its distance to the human's path, the run's distance off the plane, slips."""
        pos, _, v, _ = self._state()[2]
        for ev in self._events[n_before:]:
            if ev.kind == "grasp":
                self._grasp_start = self._t - ev.data.get("hold_time", 0.0)
                ev.data["normal_force"] = float(self.engine.contact_summary()[2])
                self._grasps.append(
                    {
                        "t": self._grasp_start,
                        "held_for": None,
                        "in_hand": self._in_hand_position(pos),
                        "drift": 0.0,
                        "human": 0.0,
                        "force_sq": 0.0,
                        "force_max": 0.0,
                        "n": 0,
                    }
                )
                self._in_hand.clear()
            elif ev.kind == "release" and self._grasps:
                held = self._t - self._grasp_start
                self._grasps[-1]["held_for"] = held
                ev.data["held_for"] = held
        parts = self.engine.contact_summary()[0]  # sorted, "arm" among them if it touches
        n_hand = len(parts) - ("arm" in parts)
        if n_hand:
            self._touched.update(x for x in parts if x != "arm")
        self._max_parts = max(self._max_parts, n_hand)
        # 3-vectors in floats
        ox, oy, oz = pos
        (cx, cy, cz), (nx, ny, nz) = self.plane.point, self._n_l
        off = abs((ox - cx) * nx + (oy - cy) * ny + (oz - cz) * nz)
        if off > self._off_plane:
            self._off_plane, self._off_plane_t = off, self._t
        if self.caught and self._grasps:
            if self._last_pos is not None:
                lx, ly, lz = ox - self._last_pos[0], oy - self._last_pos[1], oz - self._last_pos[2]
                self._held_path += math.sqrt(lx * lx + ly * ly + lz * lz)
            g = self._grasps[-1]
            h = self._in_hand_position(pos)
            r0 = g["in_hand"]
            g["drift"] = max(g["drift"], math.dist(h, r0))
            g["human"] = max(g["human"], math.dist(pos, self.human.target_l))
            fx, fy, fz = self.human.force_l  # the human's force on the object (last step)
            f2 = fx * fx + fy * fy + fz * fz
            g["force_sq"] += f2
            g["force_max"] = max(g["force_max"], math.sqrt(f2))
            g["n"] += 1
            # a slip: the object moved >= slip_distance in the hand within slip_time
            # (sustained relative motion); over when it moves less than half of that
            buf = self._in_hand
            buf.append(h)
            if len(buf) == buf.maxlen:
                d = math.dist(h, buf[0])
                P = self.params
                if d >= P.slip_distance and not self._slipping:
                    self._slips += 1
                    self._slipping = True
                    self._events.append(Occurrence("slip", {"distance": d, "position": list(pos)}))
                elif self._slipping and d < 0.5 * P.slip_distance:
                    self._slipping = False
        else:
            self._slipping = False
            self._in_hand.clear()
            ex, ey, ez = self.engine.effector_now()[0]
            dx, dy, dz = ox - ex, oy - ey, oz - ez
            (ux, uy, uz), (vx, vy, vz) = self._u_l, self._v_l
            du = dx * ux + dy * uy + dz * uz
            dv = dx * vx + dy * vy + dz * vz
            self._track_sq += du**2 + dv**2
            self._track_n += 1
        self._last_pos = pos

    # ------------------------------------------------------------------ verdict
    def outcome(self, t: float) -> dict:
        """The physical verdict (truth only): success needs the object grasped and **held**
        (within ``grasp_max_drift`` of where it sat in the hand, every grasp), **with the
        human** (within ``grasp_max_human_offset`` of the human's path while grasped, every
        grasp), **on its plane** (within ``grasp_max_off_plane`` all run), one grasp at least
        ``grasp_min_hold`` long and the object moved while held; a failure names every
        criterion it missed."""
        P = self.params
        holds = [(g["held_for"] if g["held_for"] is not None else t - g["t"]) for g in self._grasps]
        drift = max((g["drift"] for g in self._grasps), default=0.0)
        human = max((g["human"] for g in self._grasps), default=0.0)
        n_held = sum(g["n"] for g in self._grasps)
        out = {
            "success": True,
            "reason": "grasped and held with the human",
            "grasps": len(self._grasps),
            "first_grasp_t": self._grasps[0]["t"] if self._grasps else None,
            "hold_time": float(sum(holds)),
            "longest_hold": max(holds, default=0.0),
            "held_path": self._held_path,
            "slips": self._slips,
            "hold_drift_max": drift,
            "hold_human_offset_max": human,
            "off_plane_max": self._off_plane,
            "hold_human_force_rms": (
                math.sqrt(sum(g["force_sq"] for g in self._grasps) / n_held) if n_held else None
            ),
            "hold_human_force_max": max((g["force_max"] for g in self._grasps), default=None),
            "tracking_error_rms": (
                math.sqrt(self._track_sq / self._track_n) if self._track_n else None
            ),
            "hand_parts_touched": sorted(self._touched),
        }
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
        if why:
            out["success"] = False
            out["reason"] = "; ".join(why)
        return out
