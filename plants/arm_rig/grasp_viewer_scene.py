"""The grasping rig (``grasp_rig``) in the browser viewer (Namiki, Nakabo, Ishii & Ishikawa 1999):
what ``ArmScene`` draws (the WAM-7 and the 14-joint hand from the plant's URDF at the logged joint
angles, the object at its pose, its path) plus the pan/tilt head with the vision chip's camera frustum, showing the chip's
16 x 16 binary image, at the logged camera pose (``/head/state``), the constraint plane, the
object as recognised (``/grasping/object``), the reaching target x_d^a (``/grasping/arm``), and the
schedule's phase (``phase`` events). Plots: the hand and the object along Y, the hand and the
reaching target along X (Fig. 9).

Registered under the plant's type in its paper's registration (analysis/grasping/paper.py,
``grasp_rig``). The URDF is the plant's own: ``ArmScene`` builds it from the rig's typed
``GraspParams`` through the plant's resolver. No simulator is imported.
"""

from __future__ import annotations

import math
import numpy as np

from plants.arm_rig.params import GraspParams
from plants.arm_rig.viewer_scene import ArmScene
from replay.spatial import xyzw_to_wxyz
from replay.viewer.data import RunData
from replay.viewer.scenes import Body, PlotSeries, PlotSpec

T_HEAD = "/head/state"
T_CHIP = "/vision/chip"
T_RECOGNISED = "/grasping/object"
T_ARM_TASK = "/grasping/arm"
T_HUMAN = "/human/state"  # where the human hand holds the object (its target on the path)
HUMAN_HAND = (0.03, 0.09, 0.10)  # m: a palm drawn behind the object (thickness along the normal)
# the topics a grasping run has (a missing one is noted in the view)
EXPECTED = (
    "/arm/joint_state",
    "/hand/joint_state",
    "/object/state",
    T_HEAD,
    T_RECOGNISED,
    T_ARM_TASK,
)
DEFAULT_FOV = math.radians(30.0)  # when the chip sensor's params give none


def chip_fov(sensors: dict) -> tuple[float, int, int]:
    """The vision chip camera's vertical field of view (rad) and its pixels, from the scenario's
    ``vision_chip`` sensor (``fov`` full angle, or ``fov_deg``; ``width``, ``height``)."""
    for spec in (sensors or {}).values():
        if not isinstance(spec, dict) or spec.get("type") != "vision_chip":
            continue
        p = spec.get("params") or {}
        fov = p.get("fov")
        if fov is None and p.get("fov_deg") is not None:
            fov = math.radians(float(p["fov_deg"]))
        return (
            float(fov) if fov else DEFAULT_FOV,
            int(p.get("width", 16)),
            int(p.get("height", 16)),
        )
    return DEFAULT_FOV, 16, 16


def chip_image(rows, width: int, height: int) -> np.ndarray:
    """``/vision/chip`` rows (bit u of rows[v] = pixel (u, v)) as a grey RGB image, upscaled so
    the browser shows sharp pixels."""
    bits = np.array(
        [[(int(r) >> u) & 1 for u in range(width)] for r in rows[:height]], dtype=np.uint8
    )
    img = np.where(bits[..., None] > 0, 235, 30).astype(np.uint8).repeat(3, axis=2)
    return img.repeat(8, axis=0).repeat(8, axis=1)


def _xyz(v) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def _row(run: RunData, topic: str, t: float, *fields: str) -> list | None:
    """``fields`` of ``topic``'s last message at or before t, or None (no such topic, field, or
    message yet)."""
    tr = run.track(topic)
    if tr is None or not all(tr.has(f) for f in fields):
        return None
    i = tr.index(t)
    return None if i < 0 else [tr.fields[f][i] for f in fields]


class GraspScene(ArmScene):
    kind = "grasping"
    Params = GraspParams  # ArmScene rebuilds these from the log and the URDF through them
    needs = ("/arm/joint_state", "/object/state")

    def expected(self):
        return EXPECTED

    def _cameras(self, scale: float) -> None:
        """The only camera is the head's, drawn on the head at its logged pose."""

    def build(self) -> None:
        super().build()
        sc, r = self.scene, self.root
        p = self.params
        self.seen.visible = False  # ArmScene's /vision/object marker: not used here
        if p.object_position:  # the constraint plane through it
            _, wxyz = _x_to(p.plane_normal)
            self._add(
                sc.add_box(
                    f"{r}/plane",
                    color=(120, 160, 220),
                    opacity=0.15,
                    dimensions=(0.002, 0.5, 0.5),
                    wxyz=wxyz,
                    position=_xyz(p.object_position),
                )
            )
        self.fov, self.chip_w, self.chip_h = chip_fov(self.run.sensors)
        color = (60, 60, 60) if not self.tint else self.color
        self.head = self._add(sc.add_frame(f"{r}/head", show_axes=False, visible=False))
        self._add(
            sc.add_box(
                f"{r}/head/body",
                color=color,
                dimensions=(0.06, 0.06, 0.05),
                position=(0.0, 0.0, -0.03),
            )
        )
        self.frustum = self._add(
            sc.add_camera_frustum(
                f"{r}/head/frustum",
                fov=self.fov,
                aspect=self.chip_w / max(self.chip_h, 1),
                scale=0.15,
                color=color,
                thickness=2.0,
                thickness_units="screen",
            )
        )
        self._add(sc.add_label(f"{r}/head/label", "vision chip", position=(0.0, -0.05, 0.0)))
        self.recognised = self._add(
            sc.add_icosphere(f"{r}/recognised", radius=0.01, color=(20, 170, 90), visible=False)
        )
        self.reach = self._add(
            sc.add_icosphere(
                f"{r}/reaching_target",
                radius=0.01,
                color=(30, 120, 230),
                opacity=0.7,
                visible=False,
            )
        )
        self.phases = [
            (float(e["t"]), str((e.get("data") or {}).get("phase", "")))
            for e in self.run.events
            if e.get("kind") == "phase"
        ]
        self.phase_label = self._add(sc.add_label(f"{r}/phase", "", visible=False))
        self._chip_i = -1

    def bodies(self) -> list[Body]:
        """The human hand that moves the object: a palm on the far side of the object from the
        robot, at the hand's logged target (``/human/state``), facing along the plane normal."""
        p = self.params
        n, wxyz = _x_to(p.plane_normal)
        depth = max(p.object_size) if p.object_size else 2.0 * p.object_radius
        behind = 0.5 * float(depth) + 0.5 * HUMAN_HAND[0] + 0.01

        def pose(run: RunData, t: float):
            target = _row(run, T_HUMAN, t, "target")
            if target is None or not np.all(np.isfinite(target[0])):
                return None
            x = np.asarray(target[0], float)
            side = 1.0 if float(np.dot(n, x)) >= 0 else -1.0  # away from the arm's base
            return tuple(x + side * behind * n), wxyz

        return [Body("human_hand", "box", HUMAN_HAND, pose, label="human hand")]

    def update(self, run: RunData, t: float) -> None:
        super().update(run, t)
        self.seen.visible = False
        cam = _row(run, T_HEAD, t, "camera_position", "camera_orientation")
        self.head.visible = cam is not None
        if cam is not None:
            self.head.position = _xyz(cam[0])
            self.head.wxyz = xyzw_to_wxyz(cam[1])
        chip = run.track(T_CHIP)
        j = chip.index(t) if chip is not None and chip.has("rows") else -1
        if chip is not None and j >= 0 and j != self._chip_i:
            self._chip_i = j
            self.frustum.image = chip_image(chip.fields["rows"][j], self.chip_w, self.chip_h)
        rec = _row(run, T_RECOGNISED, t, "position", "found")
        ok = rec is not None and bool(np.all(np.isfinite(rec[0]))) and bool(rec[1])
        self.recognised.visible = ok
        if rec is not None and ok:
            self.recognised.position = _xyz(rec[0])
        xd = _row(run, T_ARM_TASK, t, "x_d")
        ok = xd is not None and bool(np.all(np.isfinite(xd[0][:3])))
        self.reach.visible = ok
        if xd is not None and ok:
            self.reach.position = _xyz(xd[0][:3])
        phase = next((name for te, name in reversed(self.phases) if te <= t + 1e-12), None)
        self.phase_label.visible = phase is not None and self.body.visible
        if phase is not None and self.body.visible:
            self.phase_label.text = f"{phase}"
            x, y, z = self.body.position
            self.phase_label.position = (float(x), float(y), float(z) + 0.06)

    def plots(self) -> list[PlotSpec]:
        def column(topic: str, field: str, k: int):
            def signal(run):
                tr = run.track(topic)
                if tr is None or not tr.has(field):
                    return None
                return tr.t, tr.fields[field][:, k]

            return signal

        return [
            PlotSpec(
                "Y (m): hand x^a and object (tracking, Fig. 9)",
                [
                    PlotSeries("hand", column(T_ARM_TASK, "x_a", 1)),
                    PlotSeries("object", column("/object/state", "position", 1)),
                ],
            ),
            PlotSpec(
                "X (m): hand x^a and reaching target x_d^a (Fig. 9)",
                [
                    PlotSeries("hand", column(T_ARM_TASK, "x_a", 0)),
                    PlotSeries("x_d", column(T_ARM_TASK, "x_d", 0)),
                ],
            ),
            *super().plots(),
        ]


def _x_to(normal) -> tuple[np.ndarray, tuple]:
    """(the unit ``normal``, the rotation (w, x, y, z) turning the x axis onto it)."""
    n = np.asarray(normal, float)
    n /= np.linalg.norm(n) or 1.0
    axis = np.cross([1.0, 0.0, 0.0], n)
    angle = math.atan2(np.linalg.norm(axis), n[0])
    axis = axis / (np.linalg.norm(axis) or 1.0)
    return n, (math.cos(angle / 2), *(math.sin(angle / 2) * axis))
