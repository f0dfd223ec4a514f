"""The air table in the browser viewer (Higashimori et al. 2007): stick, fingers, camera.

Registered under the plant's type in ``pyproject.toml``
(``[project.entry-points."paper_replay.viewer_scenes"] airtable = ...``). The sizes are the
plant's typed ``Params``, rebuilt from the run's resolved scenario: no default is copied here.
No simulator is imported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import viser

from plants.airtable.params import Params
from plants.airtable.settings import hand_spec
from replay.messages import (
    TOPIC_FINGERS_STATE,
    TOPIC_HAND_STATE,
    TOPIC_STICK_STATE,
    TOPIC_VISION_STICK,
)
from replay.robot.hand2d import finger_chain
from replay.spatial import yaw_wxyz
from replay.viewer.data import RunData
from replay.viewer.scenes import PlotSeries, PlotSpec, RunScene


@dataclass(frozen=True)
class StickGeometry:
    """What the viewer draws of the air table (m), from the plant's ``Params``."""

    length: float
    visual_width: float
    thickness: float
    marker_length: float
    marker_width: float
    tip_radius: float
    tip_height: float
    link_lengths: tuple[float, float]
    root_offsets: tuple[tuple[float, float], tuple[float, float]]

    @classmethod
    def of(cls, p: Params) -> StickGeometry:
        st, hand = p.stick, hand_spec(p)
        return cls(
            length=float(st.length),
            visual_width=float(st.visual_width),
            thickness=float(st.thickness),
            marker_length=float(st.marker_length),
            marker_width=float(st.marker_width),
            tip_radius=hand.tip_radius,
            tip_height=float(p.hand.tip_height),
            link_lengths=hand.link_lengths,
            root_offsets=hand.root_offsets,
        )

    def finger_points(self, base, joints) -> np.ndarray:
        """(2 fingers, 3 points: root, elbow, tip, 2) from the slider base and (q1, q2) per
        finger, by ``replay.robot.hand2d``'s kinematics."""
        return np.array(
            [
                finger_chain(base, self.root_offsets[k], self.link_lengths, joints[k])
                for k in range(2)
            ]
        )


class AirTableScene(RunScene):
    """Higashimori et al. 2007: stick (with its marker), fingertips and fingers, camera."""

    kind = "air table"
    needs = (TOPIC_STICK_STATE,)
    optional = (TOPIC_FINGERS_STATE, TOPIC_HAND_STATE, TOPIC_VISION_STICK)

    def expected(self):
        return tuple(t for t in self.optional if t != TOPIC_VISION_STICK or self.run.sensors)

    def build(self) -> None:
        g = self.geo = StickGeometry.of(self.plant_params(Params))
        self._path_thickness = 2.5
        self.check_topics()
        opacity = 0.55 if self.ghost else None
        if self.k == 0:
            self._add_table()
        self._add_stick(g, opacity)
        self._add_hand(g, opacity)
        self._add_event_markers(g)
        self._cameras(scale=0.05)

    def _add_table(self) -> None:
        """The air table: a grid under every run's moving parts (the first run's scene only)."""
        lo, hi = self.bounds()
        size = np.maximum(hi - lo, 0.3)[:2] + 0.1
        centre = (lo + hi) / 2.0
        self._add(
            self.scene.add_grid(
                "/table",
                width=float(size[0]),
                height=float(size[1]),
                cell_size=0.05,
                section_size=0.1,
                plane="xy",
                position=(float(centre[0]), float(centre[1]), -0.0002),
                plane_color=(238, 242, 246),
                plane_opacity=1.0,
                cell_color=(205, 210, 220),
                section_color=(170, 178, 190),
                shadow_opacity=0.2,
            )
        )

    def _add_stick(self, g: StickGeometry, opacity) -> None:
        """The stick with its marker, and the box of the stick as seen (hidden until seen)."""
        sc, r = self.scene, self.root
        self.stick = self._add(sc.add_frame(f"{r}/stick", show_axes=False))
        body_color = (55, 55, 60) if not self.tint else self.color
        self._add(
            sc.add_box(
                f"{r}/stick/body",
                color=body_color,
                opacity=opacity,
                dimensions=(g.length, g.visual_width, g.thickness),
                position=(0.0, 0.0, g.thickness / 2.0),
            )
        )
        self._add(
            sc.add_box(
                f"{r}/stick/marker",
                color=(250, 250, 250),
                opacity=opacity,
                dimensions=(g.marker_length, g.marker_width, 0.0005),
                position=(0.0, 0.0, g.thickness + 0.00025),
            )
        )
        self.vision = self._add(
            sc.add_box(
                f"{r}/vision",
                color=(20, 170, 90),
                wireframe=True,
                dimensions=(g.length, g.visual_width, g.thickness),
                visible=False,
            )
        )

    def _add_hand(self, g: StickGeometry, opacity) -> None:
        """The two fingertips and the slider's base (hidden until the log places them)."""
        sc, r = self.scene, self.root
        tip_color = (30, 30, 30) if not self.tint else self.color
        self.tips = [
            self._add(
                sc.add_cylinder(
                    f"{r}/tip{i}",
                    radius=g.tip_radius,
                    height=g.tip_height,
                    color=tip_color,
                    opacity=opacity,
                    visible=False,
                )
            )
            for i in range(2)
        ]
        self.base = self._add(
            sc.add_box(
                f"{r}/hand_base",
                color=(120, 120, 130),
                dimensions=(0.08, 0.02, 0.01),
                opacity=opacity,
                visible=False,
            )
        )
        self.fingers: viser.LineSegmentsHandle | None = None

    def _add_event_markers(self, g: StickGeometry) -> None:
        """A red dot at each logged collision's contact point (shown from its time)."""
        self.markers: list[tuple[float, viser.IcosphereHandle]] = []  # (time, marker)
        for e in self.run.events:
            c = (e.get("data") or {}).get("contact")
            if e.get("kind") == "collision" and isinstance(c, list) and len(c) == 2:
                h = self._add(
                    self.scene.add_icosphere(
                        f"{self.root}/events/{len(self.markers)}",
                        radius=0.003,
                        color=(220, 30, 30),
                        position=(float(c[0]), float(c[1]), g.thickness),
                        visible=False,
                    )
                )
                self.markers.append((float(e["t"]), h))

    def bounds(self):
        pts = []
        st = self.run.track(TOPIC_STICK_STATE)
        if st is not None:
            pts.append(np.column_stack([st.fields["x"], st.fields["y"]]))
        fi = self.run.track(TOPIC_FINGERS_STATE)
        if fi is not None and fi.has("tips"):
            pts.append(fi.fields["tips"].reshape(-1, 2))
        hs = self.run.track(TOPIC_HAND_STATE)
        if hs is not None and hs.has("base"):
            pts.append(hs.fields["base"].reshape(-1, 2))
        if not pts:
            return np.array([-0.2, -0.2, 0.0]), np.array([0.2, 0.2, 0.0])
        p = np.concatenate(pts)
        p = p[np.all(np.isfinite(p), axis=1)]
        lo, hi = p.min(axis=0) - 0.06, p.max(axis=0) + 0.06
        return np.append(lo, 0.0), np.append(hi, 0.02)

    def focus(self, run: RunData, t: float):
        st = run.track(TOPIC_STICK_STATE)
        if st is None or st.index(t) < 0:
            return None
        return np.array([st.at("x", t), st.at("y", t), 0.0], float)

    def update(self, run: RunData, t: float) -> None:
        g = self.geo
        st = run.track(TOPIC_STICK_STATE)
        i = st.index(t) if st is not None else -1
        self.stick.visible = i >= 0
        if st is not None and i >= 0:
            x, y, th = (float(st.fields[k][i]) for k in ("x", "y", "theta"))
            self.stick.position = (x, y, 0.0)
            self.stick.wxyz = yaw_wxyz(th)
            xyz = np.column_stack(
                [st.fields["x"], st.fields["y"], np.full(len(st), g.thickness + 0.001)]
            )
            self._update_path(xyz, i)
        else:
            self._update_path(None, -1)
        vs = run.track(TOPIC_VISION_STICK)
        j = vs.index(t) if vs is not None else -1
        self.vision.visible = j >= 0
        if vs is not None and j >= 0:
            self.vision.position = (
                float(vs.fields["x"][j]),
                float(vs.fields["y"][j]),
                g.thickness / 2.0 + 0.0003,
            )
            self.vision.wxyz = yaw_wxyz(float(vs.fields["theta"][j]))
        fi = run.track(TOPIC_FINGERS_STATE)
        j = fi.index(t) if fi is not None and fi.has("tips") else -1
        for k, tip in enumerate(self.tips):
            tip.visible = j >= 0
            if fi is not None and j >= 0:
                x, y = fi.fields["tips"][j, k]
                tip.position = (float(x), float(y), g.tip_height / 2.0)
        hs = run.track(TOPIC_HAND_STATE)
        j = hs.index(t) if hs is not None and hs.has("base") and hs.has("joints") else -1
        self.base.visible = j >= 0
        if hs is not None and j >= 0:
            base = hs.fields["base"][j]
            pts = g.finger_points(base, hs.fields["joints"][j])
            z = g.tip_height
            segs = [[(*pts[f, s], z), (*pts[f, s + 1], z)] for f in range(2) for s in range(2)]
            segs.append([(*pts[0, 0], z), (*pts[1, 0], z)])  # the palm
            self.base.position = (float(base[0]), float(base[1]), 0.005)
            color = (90, 90, 100) if not self.tint else self.color
            self.fingers = self.scene.add_line_segments(
                f"{self.root}/fingers",
                np.asarray(segs, dtype=np.float32),
                color,
                thickness=4.0,
                thickness_units="screen",
            )
            self.dynamic["fingers"] = self.fingers
        elif self.fingers is not None:
            self.fingers.visible = False
        for te, h in self.markers:
            h.visible = t >= te

    def plots(self) -> list[PlotSpec]:
        def speed(run):
            st = run.track(TOPIC_STICK_STATE)
            return None if st is None else (st.t, np.hypot(st.fields["vx"], st.fields["vy"]))

        def omega(run):
            st = run.track(TOPIC_STICK_STATE)
            return None if st is None else (st.t, st.fields["omega"])

        return [
            PlotSpec("stick speed |v| (m/s)", [PlotSeries("|v|", speed)]),
            PlotSpec("stick angular velocity ω (rad/s)", [PlotSeries("ω", omega)]),
        ]
