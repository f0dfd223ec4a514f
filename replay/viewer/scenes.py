"""Scene builders, one per kind of experiment: handles created once, moved to a time ``t``.

A builder owns the scene nodes of one run under ``/runK`` (several runs overlay: run 0 in its
natural colours, later runs tinted and see-through). It draws from the run's tracks and the
scenario's geometry only, and says in ``notes`` what it could not draw and why.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np
import viser

from replay.viewer.data import RunData, Track
from replay.viewer.errors import ViewerError
from replay.viewer.geometry import (StickGeometry, arm_urdf, cameras, free_object,
                                    rpy_to_wxyz)

RUN_COLORS = [(225, 95, 30), (35, 110, 220), (40, 160, 70), (150, 60, 180), (200, 160, 20)]
PATH_POINTS = 600          # a path so far is drawn with at most this many points


def run_color(k: int) -> tuple[int, int, int]:
    return RUN_COLORS[k % len(RUN_COLORS)]


def yaw_wxyz(theta: float) -> tuple[float, float, float, float]:
    return (math.cos(theta / 2.0), 0.0, 0.0, math.sin(theta / 2.0))


def xyzw_to_wxyz(q) -> tuple[float, float, float, float]:
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(w * w + x * x + y * y + z * z) or 1.0
    return (w / n, x / n, y / n, z / n)


@dataclass
class PlotSeries:
    label: str
    signal: Callable[[RunData], tuple[np.ndarray, np.ndarray] | None]   # run -> (t, y)


@dataclass
class PlotSpec:
    title: str
    series: list[PlotSeries]


class RunScene:
    """Base of the per-experiment builders."""
    kind = "?"
    needs: tuple[str, ...] = ()         # any one of these topics makes the run drawable
    optional: tuple[str, ...] = ()

    def __init__(self, server: viser.ViserServer, run: RunData, index: int, **options) -> None:
        self.server = server
        self.scene = server.scene
        self.run = run
        self.k = index
        self.root = f"/run{index}"
        self.color = run_color(index)
        self.ghost = index > 0
        self.options = options
        self.notes: list[str] = []
        self.handles: list = []
        self.dynamic: dict = {}         # nodes re-added as they change (lines), by role
        self._path = None
        self._path_len = -1
        self._path_thickness = 2.0

    # -- helpers ----------------------------------------------------------------------------
    def _add(self, handle):
        self.handles.append(handle)
        return handle

    @classmethod
    def drawable(cls, run: RunData) -> bool:
        return any(run.track(t) is not None for t in cls.needs)

    def expected(self) -> tuple[str, ...]:
        """Topics this run's scenario implies (besides ``needs``)."""
        return self.optional

    def check_topics(self) -> None:
        for topic in self.expected():
            if self.run.track(topic) is None:
                self.notes.append(f"no {topic} in the log: not drawn")

    def _update_path(self, xyz: np.ndarray | None, i: int) -> None:
        """The path so far (points 0..i) as a line."""
        if xyz is None or i < 1:
            if self._path is not None:
                self._path.visible = False
            return
        if i == self._path_len and self._path is not None:
            return
        self._path_len = i
        stride = max(1, len(xyz) // PATH_POINTS)
        idx = np.unique(np.append(np.arange(0, i + 1, stride), i))
        pts = xyz[idx].astype(np.float32)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if len(pts) < 2:
            return
        segs = np.stack([pts[:-1], pts[1:]], axis=1)
        self._path = self.scene.add_line_segments(
            f"{self.root}/path", segs, self.color, thickness=self._path_thickness,
            thickness_units="screen")
        self.dynamic["path"] = self._path

    def _cameras(self, scale: float) -> None:
        cams, missing = cameras(self.run.sensors)
        for i, c in enumerate(cams):
            self._add(self.scene.add_camera_frustum(
                f"{self.root}/cameras/{i}", fov=c.fov_y, aspect=c.aspect, scale=scale,
                color=(60, 60, 60) if not self.ghost else self.color, wxyz=c.wxyz,
                position=c.position, thickness=2.0, thickness_units="screen"))
            self._add(self.scene.add_label(f"{self.root}/cameras/{i}/label", c.name,
                                           position=(0.0, 0.0, 0.0)))
        for name in missing:
            self.notes.append(f"camera '{name}': no pose in its scenario params; frustum not "
                              "drawn")

    # -- interface --------------------------------------------------------------------------
    def build(self) -> None:
        raise NotImplementedError

    def update(self, run: RunData, t: float) -> None:
        raise NotImplementedError

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def plots(self) -> list[PlotSpec]:
        return []

    def frame_times(self) -> np.ndarray:
        for topic in self.needs:
            tr = self.run.track(topic)
            if tr is not None:
                return tr.t
        return np.zeros(0)

    def remove(self) -> None:
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")          # children of removed parents
            for h in [*self.handles, *self.dynamic.values()]:
                try:
                    h.remove()
                except Exception:  # noqa: BLE001 - already removed
                    pass
        self.handles, self.dynamic = [], {}


# ----------------------------------------------------------------------------- air table
class AirTableScene(RunScene):
    """Higashimori et al. 2007: stick (with its marker), fingertips and fingers, camera."""
    kind = "air table"
    needs = ("/stick/state",)
    optional = ("/fingers/state", "/hand/state", "/vision/stick")

    def expected(self):
        return tuple(t for t in self.optional if t != "/vision/stick" or self.run.sensors)

    def build(self) -> None:
        g = self.geo = StickGeometry.from_params(self.run.plant_params)
        self._path_thickness = 2.5
        self.check_topics()
        sc, r = self.scene, self.root
        opacity = 0.55 if self.ghost else None
        if self.k == 0:
            lo, hi = self.bounds()
            size = np.maximum(hi - lo, 0.3)[:2] + 0.1
            centre = (lo + hi) / 2.0
            self._add(sc.add_grid("/table", width=float(size[0]), height=float(size[1]),
                                  cell_size=0.05, section_size=0.1, plane="xy",
                                  position=(float(centre[0]), float(centre[1]), -0.0002),
                                  plane_color=(238, 242, 246), plane_opacity=1.0,
                                  cell_color=(205, 210, 220), section_color=(170, 178, 190),
                                  shadow_opacity=0.2))
        self.stick = self._add(sc.add_frame(f"{r}/stick", show_axes=False))
        body_color = (55, 55, 60) if not self.ghost else self.color
        self._add(sc.add_box(f"{r}/stick/body", color=body_color, opacity=opacity,
                             dimensions=(g.length, g.visual_width, g.thickness),
                             position=(0.0, 0.0, g.thickness / 2.0)))
        self._add(sc.add_box(f"{r}/stick/marker", color=(250, 250, 250), opacity=opacity,
                             dimensions=(g.marker_length, g.marker_width, 0.0005),
                             position=(0.0, 0.0, g.thickness + 0.00025)))
        self.vision = self._add(sc.add_box(
            f"{r}/vision", color=(20, 170, 90), wireframe=True,
            dimensions=(g.length, g.visual_width, g.thickness), visible=False))
        tip_color = (30, 30, 30) if not self.ghost else self.color
        self.tips = [self._add(sc.add_cylinder(f"{r}/tip{i}", radius=g.tip_radius,
                                               height=g.tip_height, color=tip_color,
                                               opacity=opacity, visible=False))
                     for i in range(2)]
        self.base = self._add(sc.add_box(f"{r}/hand_base", color=(120, 120, 130),
                                         dimensions=(0.08, 0.02, 0.01), opacity=opacity,
                                         visible=False))
        self.fingers = None
        self.markers = []
        for e in self.run.events:
            c = (e.get("data") or {}).get("contact")
            if e.get("kind") == "collision" and isinstance(c, list) and len(c) == 2:
                h = self._add(sc.add_icosphere(
                    f"{r}/events/{len(self.markers)}", radius=0.003, color=(220, 30, 30),
                    position=(float(c[0]), float(c[1]), g.thickness), visible=False))
                self.markers.append((float(e["t"]), h))
        self._cameras(scale=0.05)

    def bounds(self):
        pts = []
        st = self.run.track("/stick/state")
        if st is not None:
            pts.append(np.column_stack([st.fields["x"], st.fields["y"]]))
        fi = self.run.track("/fingers/state")
        if fi is not None and fi.has("tips"):
            pts.append(fi.fields["tips"].reshape(-1, 2))
        hs = self.run.track("/hand/state")
        if hs is not None and hs.has("base"):
            pts.append(hs.fields["base"].reshape(-1, 2))
        if not pts:
            return np.array([-0.2, -0.2, 0.0]), np.array([0.2, 0.2, 0.0])
        p = np.concatenate(pts)
        p = p[np.all(np.isfinite(p), axis=1)]
        lo, hi = p.min(axis=0) - 0.06, p.max(axis=0) + 0.06
        return np.append(lo, 0.0), np.append(hi, 0.02)

    def update(self, run: RunData, t: float) -> None:
        g = self.geo
        st = run.track("/stick/state")
        i = st.index(t) if st is not None else -1
        self.stick.visible = i >= 0
        if i >= 0:
            x, y, th = (float(st.fields[k][i]) for k in ("x", "y", "theta"))
            self.stick.position = (x, y, 0.0)
            self.stick.wxyz = yaw_wxyz(th)
            xyz = np.column_stack([st.fields["x"], st.fields["y"],
                                   np.full(len(st), g.thickness + 0.001)])
            self._update_path(xyz, i)
        else:
            self._update_path(None, -1)
        vs = run.track("/vision/stick")
        j = vs.index(t) if vs is not None else -1
        self.vision.visible = j >= 0
        if j >= 0:
            self.vision.position = (float(vs.fields["x"][j]), float(vs.fields["y"][j]),
                                    g.thickness / 2.0 + 0.0003)
            self.vision.wxyz = yaw_wxyz(float(vs.fields["theta"][j]))
        fi = run.track("/fingers/state")
        j = fi.index(t) if fi is not None and fi.has("tips") else -1
        for k, tip in enumerate(self.tips):
            tip.visible = j >= 0
            if j >= 0:
                x, y = fi.fields["tips"][j, k]
                tip.position = (float(x), float(y), g.tip_height / 2.0)
        hs = run.track("/hand/state")
        j = hs.index(t) if hs is not None and hs.has("base") and hs.has("joints") else -1
        self.base.visible = j >= 0
        if j >= 0:
            base = hs.fields["base"][j]
            pts = g.finger_points(base, hs.fields["joints"][j])
            z = g.tip_height
            segs = [[(*pts[f, s], z), (*pts[f, s + 1], z)] for f in range(2) for s in range(2)]
            segs.append([(*pts[0, 0], z), (*pts[1, 0], z)])          # the palm
            self.base.position = (float(base[0]), float(base[1]), 0.005)
            color = (90, 90, 100) if not self.ghost else self.color
            self.fingers = self.scene.add_line_segments(
                f"{self.root}/fingers", np.asarray(segs, dtype=np.float32), color,
                thickness=4.0, thickness_units="screen")
            self.dynamic["fingers"] = self.fingers
        elif self.fingers is not None:
            self.fingers.visible = False
        for te, h in self.markers:
            h.visible = t >= te

    def plots(self) -> list[PlotSpec]:
        def speed(run):
            st = run.track("/stick/state")
            return None if st is None else (st.t, np.hypot(st.fields["vx"], st.fields["vy"]))

        def omega(run):
            st = run.track("/stick/state")
            return None if st is None else (st.t, st.fields["omega"])
        return [PlotSpec("stick speed |v| (m/s)", [PlotSeries("|v|", speed)]),
                PlotSpec("stick angular velocity ω (rad/s)", [PlotSeries("ω", omega)])]


# ----------------------------------------------------------------------------- arms
class ArmScene(RunScene):
    """Namiki & Ishikawa 2003 (catching), Namiki et al. 1999 (grasping): arm and hand from the
    plant's URDF, the free object (ball / hexahedron) and its path, cameras."""
    kind = "arm"
    needs = ("/arm/joint_state", "/object/state")
    optional = ("/arm/joint_state", "/hand/joint_state", "/object/state", "/vision/object")

    def expected(self):
        p = self.run.plant_params
        skip = set()
        if p.get("object") == "none":
            skip.add("/object/state")
        if p.get("hand") == "none":
            skip.add("/hand/joint_state")
        if not self.run.sensors:
            skip.add("/vision/object")
        return tuple(t for t in self.optional if t not in skip)

    def build(self) -> None:
        from viser.extras import ViserUrdf
        p = self.run.plant_params
        self.check_topics()
        self._path_thickness = 3.0
        sc, r = self.scene, self.root
        if self.k == 0:
            lo, hi = self.bounds()
            span = float(max(hi[0] - lo[0], hi[1] - lo[1], 2.0)) + 1.0
            self._add(sc.add_grid("/floor", width=span, height=span, cell_size=0.25,
                                  section_size=1.0, position=((lo[0] + hi[0]) / 2.0,
                                                              (lo[1] + hi[1]) / 2.0, 0.0)))
        self.urdf = None
        self._names: tuple[str, ...] = ()
        self._maps: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._add(sc.add_frame(                 # the base plate's pose; the URDF hangs here
            f"{r}/arm", show_axes=False,
            position=tuple(float(v) for v in p.get("base_position", [0.0, 0.0, 0.0])),
            wxyz=rpy_to_wxyz(p.get("base_rpy", [0.0, 0.0, 0.0]))))
        if self.run.track("/arm/joint_state") is not None or self.run.plant_type:
            try:
                path = arm_urdf(p, self.options.get("urdf_for"))
                override = None if not self.ghost else (*(c / 255 for c in self.color), 0.45)
                self.urdf = ViserUrdf(self.server, path, root_node_name=f"{r}/arm",
                                      mesh_color_override=override)
                self._names = self.urdf.get_actuated_joint_names()
                self._cfg = np.zeros(len(self._names))
            except ViewerError as exc:
                self.notes.append(f"arm not drawn: {exc}")
            except Exception as exc:  # noqa: BLE001 - a URDF yourdfpy cannot read
                self.notes.append(f"arm not drawn: URDF unreadable ({exc.__class__.__name__}: "
                                  f"{exc})")
        obj = self.obj = free_object(p)
        color = (240, 120, 30) if not self.ghost else self.color
        if obj.kind == "box":
            self.body = self._add(sc.add_box(f"{r}/object", color=color, dimensions=obj.size,
                                             opacity=0.6 if self.ghost else None,
                                             visible=False))
        else:
            self.body = self._add(sc.add_icosphere(f"{r}/object", radius=obj.radius,
                                                   color=color, subdivisions=3,
                                                   opacity=0.6 if self.ghost else None,
                                                   visible=False))
        self.seen = self._add(sc.add_icosphere(f"{r}/vision", radius=0.008, color=(20, 170, 90),
                                               visible=False))
        self.target = self._add(sc.add_icosphere(f"{r}/effector_target", radius=0.012,
                                                 color=(30, 120, 230), opacity=0.6,
                                                 visible=False))
        self.markers = []
        for e in self.run.events:
            pos = (e.get("data") or {}).get("position")
            if isinstance(pos, list) and len(pos) == 3:
                h = self._add(sc.add_icosphere(
                    f"{r}/events/{len(self.markers)}", radius=0.012,
                    color=(220, 30, 30) if e.get("kind") != "catch" else (30, 180, 60),
                    opacity=0.7, position=tuple(float(v) for v in pos), visible=False))
                self.markers.append((float(e["t"]), h))
        self._cameras(scale=0.12)

    def bounds(self):
        pts = [np.zeros((1, 3)), np.array([[0.0, 0.0, 1.2]])]
        base = self.run.plant_params.get("base_position")
        if isinstance(base, list) and len(base) == 3:
            pts.append(np.asarray([base], float))
        ob = self.run.track("/object/state")
        if ob is not None and ob.has("position"):
            pts.append(ob.fields["position"])
        p = np.concatenate(pts)
        p = p[np.all(np.isfinite(p), axis=1)]
        return p.min(axis=0) - 0.2, p.max(axis=0) + 0.2

    def _map(self, track: Track) -> tuple[np.ndarray, np.ndarray]:
        """(columns in the track, slots in the URDF configuration) for joints in both."""
        names = track.labels.get("name") or []
        cols, slots = [], []
        for c, n in enumerate(names):
            if n in self._names:
                cols.append(c)
                slots.append(self._names.index(n))
        return np.array(cols, dtype=int), np.array(slots, dtype=int)

    def update(self, run: RunData, t: float) -> None:
        if self.urdf is not None:
            changed = False
            for topic in ("/arm/joint_state", "/hand/joint_state"):
                tr = run.track(topic)
                if tr is None or not tr.has("position"):
                    continue
                if topic not in self._maps:
                    self._maps[topic] = self._map(tr)
                cols, slots = self._maps[topic]
                i = tr.index(t)
                if i >= 0 and len(cols):
                    q = tr.fields["position"][i]
                    if q.shape[0] > cols.max():
                        self._cfg[slots] = q[cols]
                        changed = True
            if changed:
                self.urdf.update_cfg(self._cfg)
        ob = run.track("/object/state")
        i = ob.index(t) if ob is not None and ob.has("position") else -1
        self.body.visible = i >= 0
        if i >= 0:
            self.body.position = tuple(float(v) for v in ob.fields["position"][i])
            if ob.has("orientation"):
                self.body.wxyz = xyzw_to_wxyz(ob.fields["orientation"][i])
            self._update_path(ob.fields["position"], i)
        else:
            self._update_path(None, -1)
        vo = run.track("/vision/object")
        j = vo.index(t) if vo is not None and vo.has("position") else -1
        self.seen.visible = j >= 0
        if j >= 0:
            self.seen.position = tuple(float(v) for v in vo.fields["position"][j])
        ef = run.track("/effector/state")
        j = ef.index(t) if ef is not None and ef.has("desired_position") else -1
        ok = j >= 0 and ef.fields["desired_position"].shape[1:] == (3,) and \
            bool(np.all(np.isfinite(ef.fields["desired_position"][j])))
        self.target.visible = ok
        if ok:
            self.target.position = tuple(float(v) for v in ef.fields["desired_position"][j])
        for te, h in self.markers:
            h.visible = t >= te

    def plots(self) -> list[PlotSpec]:
        def joint(field: str, k: int):
            def signal(run):
                tr = run.track("/arm/joint_state")
                if tr is None or not tr.has(field) or tr.fields[field].shape[1] <= k:
                    return None
                return tr.t, tr.fields[field][:, k]
            return signal
        tr = self.run.track("/arm/joint_state")
        if tr is None:
            return []
        names = list(tr.labels.get("name") or
                     [f"q{k + 1}" for k in range(tr.fields["position"].shape[1])])
        specs = []
        for field, title in (("position", "joint angles (rad)"),
                             ("velocity", "joint velocities (rad/s)"),
                             ("effort", "joint torques (N·m)")):
            if tr.has(field):
                specs.append(PlotSpec(title, [PlotSeries(n, joint(field, k))
                                              for k, n in enumerate(names)]))
        return specs


SCENES: dict[str, type[RunScene]] = {"airtable": AirTableScene, "bullet_arm": ArmScene}
from replay.viewer.scene_grasp import GraspScene  # noqa: E402  (its own module; builds on ArmScene)
SCENES["bullet_grasp"] = GraspScene


def scene_class(run: RunData) -> type[RunScene]:
    """The builder for a run: by the scenario's plant type, else by the topics it holds."""
    cls = SCENES.get(run.plant_type)
    if cls is not None and cls.drawable(run):
        return cls
    for cls in SCENES.values():
        if cls.drawable(run):
            return cls
    where = run.path if run.path is not None else run.label
    need = " or ".join(t for c in SCENES.values() for t in c.needs)
    have = ", ".join(sorted(run.tracks)) or "none"
    raise ViewerError(f"{where}: nothing the viewer can draw: needs {need} "
                      f"(topics in the log: {have})")
