"""The arm rig's physical verdict on a free object and the hand: caught or not, and why.

Physics only (no method): :class:`CatchWatch` follows the object and the palm frame (the arm's tool
frame: z is the palm normal, the contact face at z = palm_thickness, see replay/robot/hand.py)
every step, keeps the state just before the first touch and the closest approach, and turns them
into the run's ``outcome`` data (replay/runner.py ``_verdict``):

- success: ``caught`` (the plant's ``catch`` event and still held at the end);
- failures say why: ``<object> dropped after the catch``, ``<object> bounced off the palm rim``
  (first touch on the palm with the object's centre outside the palm disc), ``... off the palm
  face``, ``... off finger f2``, ``<object> hit the arm``, ``<object> passed below / above / beside
  the hand`` (no touch at all; the direction of the closest approach from the palm centre),
  ``<object> touched the hand but was not held``, ``the run ended before the <object> reached the
  hand``;
- metrics: ``catch_time``; ``first_contact_time``, ``contact_part``, ``contact_speed`` (object
  relative to the palm, m/s, the step before the touch), ``contact_offset`` (object centre from the
  palm axis, m), ``approach_angle`` (deg between the relative velocity and the palm's inward
  normal: 0 = straight down the palm axis); without a touch ``closest_distance`` (m, object centre
  to the palm face centre) and ``closest_time``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np


@dataclass
class PalmSample:
    t: float
    offset: float  # m: object centre from the palm axis
    height: float  # m: object centre above the palm face (palm z)
    rel_speed: float  # m/s: object velocity relative to the palm point under it
    approach_angle: float  # deg: relative velocity vs the palm's inward normal (-z)
    world_offset: tuple  # object centre - palm face centre (world, m)


class CatchWatch:
    def __init__(self, *, kind: str, palm_radius: float, palm_thickness: float) -> None:
        self.kind = kind
        self.palm_radius = float(palm_radius)
        self.palm_thickness = float(palm_thickness)
        # the last and the closest sample as PalmSample's fields (a tuple: made every step; the
        # dataclass only when asked for)
        self._last: tuple | None = None
        self._closest: tuple | None = None
        self.first_contact: tuple[PalmSample, list] | None = None
        self.catch_time: float | None = None
        self.approaching = True
        self._closest_d2 = math.inf  # |world_offset|^2 of ``closest``

    @property
    def last(self) -> PalmSample | None:
        """The last step's sample."""
        return None if self._last is None else PalmSample(*self._last)

    @property
    def closest(self) -> PalmSample | None:
        """The sample of the closest approach (object centre to the palm face centre)."""
        return None if self._closest is None else PalmSample(*self._closest)

    def observe(
        self,
        t: float,
        obj_pos,
        obj_vel,
        palm_pos,
        palm_quat,
        palm_vel,
        palm_omega,
        parts: Sequence[str],
        caught: bool,
    ) -> None:
        """One step: the object's and the palm's state (world) and the parts touching now.
        The geometry: :func:`palm_frame`."""
        lx, ly, lz, speed, angle, d, dist2 = palm_frame(
            obj_pos, obj_vel, palm_pos, palm_quat, palm_vel, palm_omega, self.palm_thickness
        )
        sample = (t, math.hypot(lx, ly), lz, speed, angle, d)  # PalmSample's fields
        # still closing in at the last step: this sample is the closest so far
        self.approaching = self._closest is None or dist2 < self._closest_d2
        if self.approaching:
            self._closest, self._closest_d2 = sample, dist2
        if parts and self.first_contact is None:
            before = self._last or sample
            self.first_contact = (
                PalmSample(t, sample[1], sample[2], before[3], before[4], d),
                sorted(parts),
            )
        if caught and self.catch_time is None:
            self.catch_time = t
        self._last = sample

    def verdict(self, *, caught: bool, ever_caught: bool) -> dict:
        k = self.kind
        out: dict = {}
        if self.first_contact is not None:
            c, parts = self.first_contact
            part = _first_part(parts)
            out.update(
                first_contact_time=round(c.t, 6),
                contact_part=part,
                contact_speed=c.rel_speed,
                contact_offset=c.offset,
                approach_angle=c.approach_angle,
            )
        if self.catch_time is not None:
            out["catch_time"] = round(self.catch_time, 6)
        if caught:
            return {"success": True, "reason": "caught", **out}
        if ever_caught:
            return {"success": False, "reason": f"{k} dropped after the catch", **out}
        if self.first_contact is not None:
            c, parts = self.first_contact
            part = _first_part(parts)
            if (
                self.last is not None
                and self.last.t - c.t < 0.06
                and np.linalg.norm(self.last.world_offset) < 2 * self.palm_radius
            ):
                return {"success": False, "reason": f"{k} touched the hand but was not held", **out}
            if part == "palm":
                where = "rim" if c.offset > self.palm_radius else "face"
                return {"success": False, "reason": f"{k} bounced off the palm {where}", **out}
            if part == "arm":
                return {"success": False, "reason": f"{k} hit the arm", **out}
            return {"success": False, "reason": f"{k} bounced off finger {part}", **out}
        if self.closest is None:
            return {"success": False, "reason": f"the run ended before the {k} reached the hand"}
        cl = self.closest
        out.update(
            closest_distance=float(np.linalg.norm(cl.world_offset)), closest_time=round(cl.t, 6)
        )
        if self.approaching:
            return {
                "success": False,
                "reason": f"the run ended before the {k} reached the hand",
                **out,
            }
        dy, dz = abs(cl.world_offset[1]), cl.world_offset[2]
        side = ("below" if dz < 0 else "above") if abs(dz) >= dy else "beside"
        return {"success": False, "reason": f"{k} passed {side} the hand", **out}


def _first_part(parts: list) -> str:
    """The part a first touch is attributed to: the palm if it is among them, else the first."""
    return "palm" if "palm" in parts else (parts[0] if parts else "arm")


def palm_frame(obj_pos, obj_vel, palm_pos, palm_quat, palm_vel, palm_omega, th: float) -> tuple:
    """(lx, ly, lz, speed, angle, d, |d|^2): the object centre from the palm face centre d
    (world) and in the palm frame, its speed relative to the palm point under it and that
    velocity's angle (deg) from the palm's inward normal; in floats (3-vectors as tuples)."""
    qx, qy, qz, qw = palm_quat  # the palm frame's z axis and in-plane axes (world)
    n = qx * qx + qy * qy + qz * qz + qw * qw
    k = 2.0 / n  # (quaternion_matrix's columns, normalised there too)
    X = (1 - k * (qy * qy + qz * qz), k * (qx * qy + qz * qw), k * (qx * qz - qy * qw))
    Y = (k * (qx * qy - qz * qw), 1 - k * (qx * qx + qz * qz), k * (qy * qz + qx * qw))
    Z = (k * (qx * qz + qy * qw), k * (qy * qz - qx * qw), 1 - k * (qx * qx + qy * qy))
    ox, oy, oz = obj_pos
    px, py, pz = palm_pos
    d = (ox - px - Z[0] * th, oy - py - Z[1] * th, oz - pz - Z[2] * th)
    lx = X[0] * d[0] + X[1] * d[1] + X[2] * d[2]
    ly = Y[0] * d[0] + Y[1] * d[1] + Y[2] * d[2]
    lz = Z[0] * d[0] + Z[1] * d[1] + Z[2] * d[2]
    wx, wy, wz = palm_omega
    ax, ay, az = ox - px, oy - py, oz - pz
    vx, vy, vz = palm_vel
    ux, uy, uz = obj_vel
    rel = (
        ux - vx - (wy * az - wz * ay),
        uy - vy - (wz * ax - wx * az),
        uz - vz - (wx * ay - wy * ax),
    )
    speed = math.sqrt(rel[0] * rel[0] + rel[1] * rel[1] + rel[2] * rel[2])
    inward = -(Z[0] * rel[0] + Z[1] * rel[1] + Z[2] * rel[2])  # towards the palm face
    angle = math.degrees(math.acos(max(-1.0, min(1.0, inward / speed)))) if speed > 0 else 0.0
    dist2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
    return lx, ly, lz, speed, angle, d, dist2
