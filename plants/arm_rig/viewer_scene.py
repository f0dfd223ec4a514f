"""The arm plant in the browser viewer: arm and hand from the plant's own URDF, the free object.

Registered under the plant's type in its paper's registration (analysis/catching/paper.py,
``viewer_scenes``: ``arm_rig``). Sizes and the URDF
come from the plant's typed ``Params``, rebuilt from the run's resolved scenario, through the
plant's resolver (``plants.arm_rig.settings``): no default is retyped here. No simulator is
imported (the URDF is built by ``plants.models``, pure NumPy).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np
import viser

from plants.arm_rig.params import Params
from plants.arm_rig.settings import resolve
from replay.messages import (
    TOPIC_ARM_JOINT_STATE,
    TOPIC_EFFECTOR_STATE,
    TOPIC_HAND_JOINT_STATE,
    TOPIC_OBJECT_STATE,
    TOPIC_VISION_OBJECT,
)
from replay.scenario import params_from_data
from replay.spatial import rpy_to_wxyz, xyzw_to_wxyz
from replay.viewer.data import RunData, Track
from replay.viewer.errors import ViewerError
from replay.viewer.scenes import PlotSeries, PlotSpec, RunScene


def _xyz(v) -> tuple[float, float, float]:
    """A 3-vector as three floats (viser's positions and sizes)."""
    x, y, z = v
    return float(x), float(y), float(z)


def plant_models_urdf(p: dict, params_cls: type = Params) -> Path:
    """The arm plant's URDF for these ``plant.params`` (as logged), built by the plant's own
    resolver, so it is the very file (same cached path) the plant loads. ``params_cls``: the
    plant's ``Params`` (this one's, or a subclass for a plant built on it)."""
    return Path(resolve(params_from_data(params_cls, p, "plant.params")).arm_model().write())


# Where an arm run's URDF comes from: ``plant.params`` -> path; None = the plant's own
# (plant_models_urdf). Tests and other plants may point this elsewhere (``Viewer(urdf_for=...)``
# takes precedence).
URDF_FOR: Callable[[dict], Path] | None = None


def arm_urdf(
    p: dict, urdf_for: Callable[[dict], Path] | None = None, params_cls: type = Params
) -> Path:
    fn = urdf_for or URDF_FOR or (lambda d: plant_models_urdf(d, params_cls))
    try:
        path = Path(fn(p))
    except Exception as exc:  # noqa: BLE001 - any failure is one line in the view
        raise ViewerError(
            f"cannot build the arm's URDF ({exc.__class__.__name__}: {exc})"
        ) from None
    if not path.is_file():
        raise ViewerError(f"arm URDF {path} not found")
    return path


FOCUS_REACH = 0.2  # m: the object this near the hand's path is framed with it


class ArmScene(RunScene):
    """Namiki & Ishikawa 2003 (catching), Namiki et al. 1999 (grasping): arm and hand from the
    plant's URDF, the free object (ball / hexahedron) and its path, cameras."""

    kind = "arm"
    view_direction = (0.3, -1.05, 0.4)
    Params: type = Params  # the plant's params; a scene for a plant built on this one
    # (e.g. with Params(Params) subclassed) sets its own
    needs = (TOPIC_ARM_JOINT_STATE, TOPIC_OBJECT_STATE)
    optional = (
        TOPIC_ARM_JOINT_STATE,
        TOPIC_HAND_JOINT_STATE,
        TOPIC_OBJECT_STATE,
        TOPIC_VISION_OBJECT,
    )

    def expected(self):
        p = self.params
        skip = set()
        if p.object == "none":
            skip.add(TOPIC_OBJECT_STATE)
        if p.hand == "none":
            skip.add(TOPIC_HAND_JOINT_STATE)
        if not self.run.sensors:
            skip.add(TOPIC_VISION_OBJECT)
        return tuple(t for t in self.optional if t not in skip)

    def build(self) -> None:
        p = self.params = self.plant_params(self.Params)
        self.check_topics()
        self._path_thickness = 3.0
        if self.k == 0:
            self._add_floor()
        self._add_arm(p)
        self._add_object(p)
        self._add_event_markers()
        self._cameras(scale=0.12)

    def _add_floor(self) -> None:
        """A floor grid under every run's moving parts (the first run's scene only)."""
        lo, hi = self.bounds()
        span = float(max(hi[0] - lo[0], hi[1] - lo[1], 2.0)) + 1.0
        self._add(
            self.scene.add_grid(
                "/floor",
                width=span,
                height=span,
                cell_size=0.25,
                section_size=1.0,
                position=((lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0, 0.0),
            )
        )

    def _add_arm(self, p) -> None:
        """The base plate's frame and the arm's URDF hung from it (a note, not the arm, when
        its URDF cannot be had or read)."""
        from viser.extras import ViserUrdf

        r = self.root
        self.urdf = None
        self.urdf_color: tuple[float, float, float, float] | None = (
            None  # the arm's colour (RGBA, 0-1)
        )
        self._names: tuple[str, ...] = ()
        self._maps: dict[str, tuple[np.ndarray, np.ndarray]] = {}
        self._add(
            self.scene.add_frame(  # the base plate's pose; the URDF hangs here
                f"{r}/arm",
                show_axes=False,
                position=_xyz(p.base_position),
                wxyz=rpy_to_wxyz(p.base_rpy),
            )
        )
        if self.run.track(TOPIC_ARM_JOINT_STATE) is None and not self.run.plant_type:
            return
        try:
            path = arm_urdf(self.run.plant_params, self.options.get("urdf_for"), self.Params)
            opacity = 0.5 if self.ghost else 1.0  # overlaid: every run in its colour
            red, green, blue = (c / 255 for c in self.color)
            override = None if not self.tint else (red, green, blue, opacity)
            self.urdf_color = override
            self.urdf = ViserUrdf(
                self.server, path, root_node_name=f"{r}/arm", mesh_color_override=override
            )
            self._names = self.urdf.get_actuated_joint_names()
            self._cfg = np.zeros(len(self._names))
        except ViewerError as exc:
            self.notes.append(f"arm not drawn: {exc}")
        except Exception as exc:  # noqa: BLE001 - a URDF yourdfpy cannot read
            self.notes.append(f"arm not drawn: URDF unreadable ({exc.__class__.__name__}: {exc})")

    def _add_object(self, p) -> None:
        """The object (a box or a ball), where vision saw it and the effector's target (all
        hidden until the log places them)."""
        sc, r = self.scene, self.root
        color = (240, 120, 30) if not self.tint else self.color
        if p.object == "box":
            self.body = self._add(
                sc.add_box(
                    f"{r}/object",
                    color=color,
                    dimensions=_xyz(p.object_size),
                    opacity=0.6 if self.ghost else None,
                    visible=False,
                )
            )
        else:
            self.body = self._add(
                sc.add_icosphere(
                    f"{r}/object",
                    radius=p.object_radius,
                    color=color,
                    subdivisions=3,
                    opacity=0.6 if self.ghost else None,
                    visible=False,
                )
            )
        self.seen = self._add(
            sc.add_icosphere(f"{r}/vision", radius=0.008, color=(20, 170, 90), visible=False)
        )
        self.target = self._add(
            sc.add_icosphere(
                f"{r}/effector_target",
                radius=0.012,
                color=(30, 120, 230),
                opacity=0.6,
                visible=False,
            )
        )

    def _add_event_markers(self) -> None:
        """A dot at each logged event's position (green a catch, red any other), shown from
        its time."""
        self.markers: list[tuple[float, viser.IcosphereHandle]] = []  # (time, marker)
        for e in self.run.events:
            pos = (e.get("data") or {}).get("position")
            if isinstance(pos, list) and len(pos) == 3:
                h = self._add(
                    self.scene.add_icosphere(
                        f"{self.root}/events/{len(self.markers)}",
                        radius=0.012,
                        color=(220, 30, 30) if e.get("kind") != "catch" else (30, 180, 60),
                        opacity=0.7,
                        position=_xyz(pos),
                        visible=False,
                    )
                )
                self.markers.append((float(e["t"]), h))

    def bounds(self):
        pts = [np.zeros((1, 3)), np.array([[0.0, 0.0, 1.2]])]
        pts.append(np.asarray([self.params.base_position], float))
        ob = self.run.track(TOPIC_OBJECT_STATE)
        if ob is not None and ob.has("position"):
            pts.append(ob.fields["position"])
        p = np.concatenate(pts)
        p = p[np.all(np.isfinite(p), axis=1)]
        return p.min(axis=0) - 0.2, p.max(axis=0) + 0.2

    def hand_path(self) -> np.ndarray | None:
        """The hand's logged positions (n, 3): the effector (``/effector/state``, else
        ``/effector/motion``), else the grasping task's x^a; None if the log has none."""
        for topic, field in (
            (TOPIC_EFFECTOR_STATE, "position"),
            ("/effector/motion", "position"),
            ("/grasping/arm", "x_a"),
        ):
            tr = self.run.track(topic)
            if tr is not None and tr.has(field) and tr.fields[field].shape[1:2] >= (3,):
                return np.asarray(tr.fields[field][:, :3], float)
        return None

    def focus_points(self):
        """The hand and the object where it comes near the hand (within ``FOCUS_REACH`` of the
        hand's path's box): a thrown ball's far flight is left out, so that the hand and the
        ball fill the view. Without a logged hand: the object's whole path."""
        ob = self.run.track(TOPIC_OBJECT_STATE)
        obj = ob.fields["position"] if ob is not None and ob.has("position") else np.zeros((0, 3))
        obj = obj[np.all(np.isfinite(obj), axis=1)]
        hand = self.hand_path()
        if hand is None:
            return obj if len(obj) else None
        hand = hand[np.all(np.isfinite(hand), axis=1)]
        if not len(hand):
            return obj if len(obj) else None
        lo, hi = hand.min(axis=0) - FOCUS_REACH, hand.max(axis=0) + FOCUS_REACH
        near = obj[np.all((obj >= lo) & (obj <= hi), axis=1)]
        return np.concatenate([hand, near])

    def focus(self, run: RunData, t: float):
        ob = run.track(TOPIC_OBJECT_STATE)
        if ob is None or not ob.has("position") or ob.index(t) < 0:
            return None
        return np.asarray(ob.at("position", t), float)

    def _map(self, track: Track) -> tuple[np.ndarray, np.ndarray]:
        """(columns in the track, slots in the URDF configuration) for joints in both."""
        names = track.labels.get("name") or []
        cols, slots = [], []
        for c, n in enumerate(names):
            if n in self._names:
                cols.append(c)
                slots.append(self._names.index(n))
        return np.array(cols, dtype=int), np.array(slots, dtype=int)

    @staticmethod
    def _goal(ef: Track | None, t: float) -> tuple[float, float, float] | None:
        """The effector's commanded position at ``t`` (finite, 3-D), or None."""
        if ef is None or not ef.has("desired_position"):
            return None
        j = ef.index(t)
        goal = ef.fields["desired_position"]
        if j < 0 or goal.shape[1:] != (3,) or not np.all(np.isfinite(goal[j])):
            return None
        return _xyz(goal[j])

    def update(self, run: RunData, t: float) -> None:
        if self.urdf is not None:
            changed = False
            for topic in (TOPIC_ARM_JOINT_STATE, TOPIC_HAND_JOINT_STATE):
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
        ob = run.track(TOPIC_OBJECT_STATE)
        i = ob.index(t) if ob is not None and ob.has("position") else -1
        self.body.visible = i >= 0
        if ob is not None and i >= 0:
            self.body.position = tuple(float(v) for v in ob.fields["position"][i])
            if ob.has("orientation"):
                self.body.wxyz = xyzw_to_wxyz(ob.fields["orientation"][i])
            self._update_path(ob.fields["position"], i)
        else:
            self._update_path(None, -1)
        vo = run.track(TOPIC_VISION_OBJECT)
        j = vo.index(t) if vo is not None and vo.has("position") else -1
        self.seen.visible = j >= 0
        if vo is not None and j >= 0:
            self.seen.position = tuple(float(v) for v in vo.fields["position"][j])
        goal = self._goal(run.track(TOPIC_EFFECTOR_STATE), t)
        self.target.visible = goal is not None
        if goal is not None:
            self.target.position = goal
        for te, h in self.markers:
            h.visible = t >= te

    def plots(self) -> list[PlotSpec]:
        def joint(field: str, k: int):
            def signal(run):
                tr = run.track(TOPIC_ARM_JOINT_STATE)
                if tr is None or not tr.has(field) or tr.fields[field].shape[1] <= k:
                    return None
                return tr.t, tr.fields[field][:, k]

            return signal

        tr = self.run.track(TOPIC_ARM_JOINT_STATE)
        if tr is None:
            return []
        names = list(
            tr.labels.get("name") or [f"q{k + 1}" for k in range(tr.fields["position"].shape[1])]
        )
        specs = []
        for field, title in (
            ("position", "joint angles (rad)"),
            ("velocity", "joint velocities (rad/s)"),
            ("effort", "joint torques (N·m)"),
        ):
            if tr.has(field):
                specs.append(
                    PlotSpec(title, [PlotSeries(n, joint(field, k)) for k, n in enumerate(names)])
                )
        return specs
