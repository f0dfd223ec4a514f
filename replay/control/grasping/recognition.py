"""Object recognition by visual information (Namiki et al. 1999, Sec. 4.1.1).

Each chip frame: Self Windowing extracts the target (``self_window``); its moments give the image
centre xi and rotation phi (``features``); the viewing ray through xi, from the camera pose at
the frame's capture (the head's encoders then, through the head model ``replay.robot.head``),
meets the constraint plane given beforehand at the object's 3-D position; a second ray along
the principal axis gives the roll about the plane's normal, so ``x_o = (x, y, z, roll, pitch,
yaw)`` with pitch and yaw those of the plane (0 here: the plane's normal is the reference). The
pixel extents at that depth give the size; the fill of the smallest bounding box the shape
(rectangle vs circle: :func:`shape_of`), decided by a vote over the first ``shape_frames`` whole views (not cut by
the image border) and then kept. The image Jacobian of the head (d xi / d(pan, tilt), for eq. 1)
is that of the same model at the estimated point. Nothing here predicts motion.

Per frame the task runs ``self_window``'s Self Windowing and ``features``' moments on the packed
rows, and :class:`Camera`'s plane geometry.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.control.grasping.features import blob_rows
from replay.control.grasping.payloads import GraspObject
from replay.control.grasping.self_window import track_rows
from replay.interfaces import Controller, Occurrence
from replay.messages import TOPIC_GRASP_OBJECT, TOPIC_HEAD_ENCODERS, TOPIC_VISION_CHIP
from replay.params import param
from replay.robot.arm_types import GraspSpec, ServoCommand
from replay.robot.head import HeadSpec
from replay.spatial import wrap_half_pi

HEAD_READINGS = 1024  # the head encoder readings kept at most: a chip latency up to ~1 s at 1 kHz


@dataclass
class RecognitionParams:
    fov: float = param(
        math.radians(12.0),
        unit="rad",
        gt=0.0,
        lt=math.pi,
        doc="the chip's calibrated horizontal field of view (= the sensor's)",
    )
    width: int = param(16, unit="px", ge=2, doc="chip width (= the sensor's)")
    height: int = param(16, unit="px", ge=2, doc="chip height (= the sensor's)")
    rectangle_fill: float = param(
        0.9,
        unit="1",
        gt=0.0,
        lt=1.0,
        doc="fill of the smallest bounding box above which the shape "
        "is a rectangle (an axis-aligned rectangle ~1, a disc "
        "pi/4 = 0.79; a rolled one's jagged 16 x 16 edges ~0.75)",
    )
    rectangle_elongation: float = param(
        1.3,
        unit="1",
        ge=1.0,
        doc="elongation above which the shape is a rectangle "
        "(a disc's is 1; measured 1.01-1.11 on the chip)",
    )
    min_area: int = param(6, unit="px", ge=1, doc="smallest target used to judge the shape")
    shape_frames: int = param(20, ge=1, doc="whole views voted on before the shape is decided")
    axis_elongation: float = param(
        1.25, unit="1", ge=1.0, doc="elongation above which the target's axis (roll) is used"
    )


def shape_of(b, params: RecognitionParams) -> str:
    """Rectangle or circle from one target's features (Fig. 5(b)): a rectangle is elongated or
    fills its bounding box; a circle neither. (A square face is told from a disc only by the
    fill, i.e. when its edges line up with the pixels: at 16 x 16 a rolled square's jagged
    outline fills ~0.75 of its box, like a disc.)"""
    if b.elongation >= params.rectangle_elongation or b.fill >= params.rectangle_fill:
        return "rectangle"
    return "circle"


def plane_basis(normal) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(u, v, n): in-plane axes (u horizontal) of a plane with this normal."""
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    u = np.cross([0.0, 0.0, 1.0], n)
    if np.linalg.norm(u) < 1e-9:
        u = np.array([0.0, 1.0, 0.0])
    u /= np.linalg.norm(u)
    return u, np.cross(n, u), n


class Camera:
    """The chip's pinhole model on the head: focal length ``f`` (pixels) and centre ``c``. (Its
    rays, projections and image Jacobian in NumPy are the tests' oracle,
    tests/replay/control/grasping/oracles.py; the task writes them out in floats.)"""

    def __init__(self, head: HeadSpec, fov: float, width: int, height: int) -> None:
        self.head = head
        self.f = (width / 2.0) / math.tan(fov / 2.0)
        self.c = np.array([(width - 1) / 2.0, (height - 1) / 2.0])


class RecognitionTask(Controller):
    """Self Windowing, moments, 3-D pose on the constraint plane, shape: ``/grasping/object``."""

    Params = RecognitionParams
    spec_type = GraspSpec
    command_type = ServoCommand
    reads = (TOPIC_VISION_CHIP, TOPIC_HEAD_ENCODERS)
    description = "Sec. 4.1.1: Self Windowing, moments, x_o from the constraint plane, shape"

    def __init__(self, params: RecognitionParams, *, spec: GraspSpec) -> None:
        super().__init__(params, spec=spec)
        if spec.head is None or spec.plane is None:
            raise ValueError("recognition needs a plant with a head and a constraint plane")
        self.camera = Camera(spec.head, params.fov, params.width, params.height)
        self.plane_point = np.asarray(spec.plane.point, float)
        self.pu, self.pv, self.pn = plane_basis(spec.plane.normal)
        self._head: dict[float, tuple[float, float]] = {}
        self._target: list[int] | None = None  # packed rows (self_window.track_rows)
        # the same constants as floats for the per-frame plane geometry
        self._c = (float(self.camera.c[0]), float(self.camera.c[1]))
        self._head_position = tuple(float(x) for x in spec.head.position)
        self._plane_point = tuple(float(x) for x in self.plane_point)
        self._pu, self._pv, self._pn = (
            tuple(float(x) for x in v) for v in (self.pu, self.pv, self.pn)
        )
        self._had_target = False
        self._votes = {"rectangle": 0, "circle": 0}
        self.shape = "unknown"
        self._events: list[Occurrence] = []
        self._out: GraspObject | None = None
        self.frames = 0
        self.lost_frames = 0

    def update(self, t: float, measurements) -> None:
        self._out = None
        chip = None
        for topic, m in measurements:
            if topic == TOPIC_HEAD_ENCODERS:
                self._head[round(m.t, 9)] = (m.position[0], m.position[1])
            elif topic == TOPIC_VISION_CHIP:
                chip = m
        while len(self._head) > HEAD_READINGS:
            del self._head[min(self._head)]
        if chip is not None:
            self._out = self._frame(chip)
            # frames come in time order: the readings before the one this frame used serve no
            # later frame (a fixed 16 kept lost every frame at a chip latency above 16 ms)
            key = round(chip.t, 9)
            used = max((k for k in self._head if k <= key), default=None)
            for k in [k for k in self._head if used is not None and k < used]:
                del self._head[k]
        return None

    def _angles_at(self, t: float):
        key = round(t, 9)
        if key in self._head:
            return self._head[key]
        older = [k for k in self._head if k <= key]
        return self._head[max(older)] if older else None

    def _frame(self, chip) -> GraspObject | None:
        angles = self._angles_at(chip.t)
        if angles is None:
            return None
        fill = self.shape == "unknown"
        target, reacquired = track_rows(self._target, chip.rows, chip.width)
        b = blob_rows(target, chip.width, fill=fill)
        self._target = target
        self.frames += 1
        window = int(chip.count) if reacquired else (b.area if b is not None else 0)
        if b is None:
            self.lost_frames += 1
            if self._had_target:
                self._events.append(Occurrence("lost", {"t_image": chip.t}))
                self._had_target = False
            return GraspObject(
                chip.t,
                False,
                [],
                0.0,
                0,
                window,
                [],
                None,
                [],
                [],
                self.shape,
                0.0,
                0.0,
                [],
                list(angles),
            )
        if reacquired and self.frames > 1:
            self._events.append(Occurrence("reacquired", {"t_image": chip.t, "area": b.area}))
        self._had_target = True
        # x_o on the constraint plane, the target's axis there and the image Jacobian, from the
        # camera pose at capture
        g = self._plane_geometry(angles, b)
        if g is None:
            return None
        X0, X1, X2, axis, dist, J00, J01, J10, J11 = g
        roll = None
        if axis == axis and b.elongation >= self.params.axis_elongation:
            roll = wrap_half_pi(axis)
        scale = dist / self.camera.f  # m per px at the object
        if self.shape == "unknown" and not b.touches_border and b.area >= self.params.min_area:
            self._vote(b)  # (once decided, the shape is kept: later votes would change nothing)
        return GraspObject(
            chip.t,
            True,
            [b.u, b.v],
            b.phi,
            b.area,
            window,
            [X0, X1, X2],
            roll,
            [X0, X1, X2, roll if roll is not None else 0.0, 0.0, 0.0],
            [b.length * scale, b.width * scale],
            self.shape,
            b.fill if b.fill == b.fill else None,
            b.elongation,
            [[J00, J01], [J10, J11]],
            list(angles),
        )

    def _plane_geometry(self, angles, b) -> tuple[float, ...] | None:
        """None (the ray through the target's centre misses the plane) or (X0, X1, X2, axis,
        distance, J00, J01, J10, J11): X where that ray meets the constraint plane, axis =
        atan2(e . pv, e . pu) of e = X' - X, X' that of (u + cos phi, v + sin phi) (NaN if it
        misses), distance = |X - o|, J = d (u, v) / d (pan, tilt) of X. In floats, per frame:
        the pinhole ray, its meeting with the plane and the image Jacobian, with camera_pose's
        R and o written out (a seeded test holds them to the NumPy forms)."""
        cam, h = self.camera, self._head_position
        f, (cx, cy) = cam.f, self._c
        a = cam.head.yaw + angles[0]
        ca, sa, ct, st = math.cos(a), math.sin(a), math.cos(angles[1]), math.sin(angles[1])
        R = (sa, -st * ca, ca * ct, -ca, -st * sa, sa * ct, 0.0, -ct, -st)  # camera_pose's
        k = cam.head.camera_offset
        o = (h[0] + k * ca * ct, h[1] + k * sa * ct, h[2] - k * st)
        (P0, P1, P2), n = self._plane_point, self._pn
        po = (P0 - o[0]) * n[0] + (P1 - o[1]) * n[1] + (P2 - o[2]) * n[2]

        def on_plane(x: float, y: float) -> tuple[float, float, float] | None:
            x, y = (x - cx) / f, (y - cy) / f  # the ray R (x, y, 1) from o meets the plane
            d0, d1, d2 = (
                R[0] * x + R[1] * y + R[2],
                R[3] * x + R[4] * y + R[5],
                R[6] * x + R[7] * y + R[8],
            )
            denom = d0 * n[0] + d1 * n[1] + d2 * n[2]
            if abs(denom) < 1e-12:
                return None
            s = po / denom
            return (o[0] + s * d0, o[1] + s * d1, o[2] + s * d2) if s > 0.0 else None

        X = on_plane(b.u, b.v)
        if X is None:
            return None
        axis = math.nan
        X2 = on_plane(b.u + math.cos(b.phi), b.v + math.sin(b.phi))
        if X2 is not None:
            e0, e1, e2 = X2[0] - X[0], X2[1] - X[1], X2[2] - X[2]
            pu, pv = self._pu, self._pv
            axis = math.atan2(
                e0 * pv[0] + e1 * pv[1] + e2 * pv[2], e0 * pu[0] + e1 * pu[1] + e2 * pu[2]
            )
        w0, w1, w2 = X[0] - o[0], X[1] - o[1], X[2] - o[2]
        pc = [R[i] * w0 + R[3 + i] * w1 + R[6 + i] * w2 for i in range(3)]  # R^T (X - o)
        r0, r1, r2 = X[0] - h[0], X[1] - h[1], X[2] - h[2]
        z2 = pc[2] * pc[2]
        J = []
        for k0, k1, k2 in ((0.0, 0.0, 1.0), (-sa, ca, 0.0)):  # about z (pan), the tilt axis
            kx = (k1 * r2 - k2 * r1, k2 * r0 - k0 * r2, k0 * r1 - k1 * r0)
            d = [-(R[j] * kx[0] + R[3 + j] * kx[1] + R[6 + j] * kx[2]) for j in range(3)]
            J.append(
                (f * (d[0] * pc[2] - pc[0] * d[2]) / z2, f * (d[1] * pc[2] - pc[1] * d[2]) / z2)
            )
        dist = math.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        return (*X, axis, dist, J[0][0], J[1][0], J[0][1], J[1][1])

    def _vote(self, b) -> None:
        kind = shape_of(b, self.params)
        self._votes[kind] += 1
        if self.shape == "unknown" and sum(self._votes.values()) >= self.params.shape_frames:
            self.shape = max(self._votes, key=lambda k: (self._votes[k], k))
            self._events.append(
                Occurrence(
                    "shape",
                    {
                        "shape": self.shape,
                        "votes": dict(self._votes),
                        "fill": b.fill,
                        "elongation": b.elongation,
                    },
                )
            )

    def telemetry(self, t: float) -> dict:
        return {TOPIC_GRASP_OBJECT: self._out} if self._out is not None else {}

    def pop_events(self) -> list[Occurrence]:
        ev, self._events = self._events, []
        return ev

    def outcome(self, t: float) -> dict:
        out = {
            "shape": self.shape,
            "vision_frames": self.frames,
            "vision_lost_frames": self.lost_frames,
        }
        if self.shape == "unknown":
            out.update(
                success=False,
                reason="the object's shape was never recognised "
                f"({sum(self._votes.values())} whole views of "
                f"{self.params.shape_frames} needed)",
            )
        return out
