"""Scene builders, one per kind of experiment: handles created once, moved to a time ``t``.

A builder owns the scene nodes of one run under ``/runK``. A run alone is drawn in its natural
colours; overlaid runs are each drawn in their own colour (``run_color``; later runs also
see-through), so that near-identical runs stay told apart. It draws from the run's tracks and
the scenario's geometry only, and says in ``notes`` what it could not draw and why.

The camera fits the run's moving parts at load (``focus_points``: for an arm, the hand and the
object near it, not the whole static scene) and can follow the object (``focus``). A builder
may expose extra bodies (``bodies``: e.g. the human hand moving a grasped object); the base
class draws and moves them, and the framing counts them.

Builders are plug-ins: a subclass of :class:`RunScene`, found through the entry-point group
``paper_replay.viewer_scenes`` under the plant type it draws (``replay.registry``, kind
``"viewer_scene"``), e.g. ``plants/airtable/viewer_scene.py``. This module holds what every
builder shares; it imports no plug-in (docs/viewer.md says how to add one).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

import numpy as np
import viser

from replay import registry
from replay.scenario import ScenarioError, params_from_data
from replay.viewer.data import RunData
from replay.viewer.errors import ViewerError
from replay.viewer.geometry import cameras
from replay.viewer.markup import clean

RUN_COLORS = [(225, 95, 30), (35, 110, 220), (40, 160, 70), (150, 60, 180), (200, 160, 20)]
PATH_POINTS = 600  # a path so far is drawn with at most this many points
FIT_MARGIN = 0.08  # m added around the moving parts when the camera is fitted
FIT_MIN_SIZE = 0.3  # m: the smallest scene the camera fits (a still object is not a speck)
FIT_SAMPLES = 200  # times at which the extra bodies' poses are sampled for the fit


def fit_bounds(
    points: np.ndarray, margin: float = FIT_MARGIN, min_size: float = FIT_MIN_SIZE
) -> tuple[np.ndarray, np.ndarray]:
    """The box (lo, hi) the camera fits: the finite ``points`` (n, 3) with ``margin`` around,
    each side at least ``min_size`` long (about the same centre)."""
    p = np.asarray(points, float).reshape(-1, 3)
    p = p[np.all(np.isfinite(p), axis=1)]
    if len(p) == 0:
        p = np.zeros((1, 3))
    lo, hi = p.min(axis=0) - margin, p.max(axis=0) + margin
    c, half = (lo + hi) / 2.0, np.maximum((hi - lo) / 2.0, min_size / 2.0)
    return c - half, c + half


def run_color(k: int) -> tuple[int, int, int]:
    return RUN_COLORS[k % len(RUN_COLORS)]


@dataclass
class Body:
    """A body a scene draws besides its own (e.g. the human hand that moves the grasped object).

    ``shape``: "box" (``size`` = its three dimensions), "sphere" (``size`` = (radius,)) or
    "cylinder" (``size`` = (radius, height), along its z). ``pose(run, t)``: its (position xyz,
    orientation wxyz) at simulated time t, or None where it is not shown."""

    name: str
    shape: str
    size: tuple[float, ...]
    pose: Callable[[RunData, float], tuple[Sequence[float], Sequence[float]] | None]
    color: tuple[int, int, int] = (225, 180, 150)
    label: str = ""


@dataclass
class PlotSeries:
    label: str
    signal: Callable[[RunData], tuple[np.ndarray, np.ndarray] | None]  # run -> (t, y)


@dataclass
class PlotSpec:
    title: str
    series: list[PlotSeries]


class RunScene:
    """Base of the per-experiment builders."""

    kind = "?"
    needs: tuple[str, ...] = ()  # any one of these topics makes the run drawable
    optional: tuple[str, ...] = ()
    view_direction = (0.0, -0.62, 0.8)  # initial camera: centre + this * the scene's size

    def __init__(self, server: viser.ViserServer, run: RunData, index: int, **options) -> None:
        self.server = server
        self.scene = server.scene
        self.run = run
        self.k = index
        self.root = f"/run{index}"
        self.root_frame: Any = None  # the run's frame in the scene (the viewer makes it)
        self.color = run_color(index)
        self.ghost = index > 0  # see-through
        self.tint = bool(options.get("overlaid", index > 0))  # drawn in self.color
        self.options = options
        self.notes: list[str] = []
        self.handles: list = []
        self.dynamic: dict = {}  # nodes re-added as they change (lines), by role
        self._path: Any = None
        self._path_len = -1
        self._path_thickness = 2.0

    # -- helpers ----------------------------------------------------------------------------
    def _add(self, handle):
        self.handles.append(handle)
        return handle

    def plant_params(self, cls: type):
        """The plant's typed ``Params`` (``cls``) rebuilt from the run's resolved scenario by the
        scenario loader: every default is the plant's own. Defaults (and a note) if the log has
        no scenario or its params do not fit ``cls``."""
        try:
            return params_from_data(cls, self.run.plant_params, "plant.params")
        except ScenarioError as exc:
            self.notes.append(f"plant params unreadable ({exc}); the plant's defaults drawn")
            return cls()

    @classmethod
    def drawable(cls, run: RunData) -> bool:
        return any(run.track(t) is not None for t in cls.needs)

    @classmethod
    def suits(cls, run: RunData) -> bool:
        """For a variant (registered as ``PLANT.VARIANT``, e.g. ``arm_rig.grasp``): whether it
        should draw this run of plant type PLANT instead of that plant's own scene (e.g. by
        ``run.scenario["paper"]`` or ``run.plant_params``)."""
        return True

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
            f"{self.root}/path",
            segs,
            self.color,
            thickness=self._path_thickness,
            thickness_units="screen",
        )
        self.dynamic["path"] = self._path

    def _cameras(self, scale: float) -> None:
        cams, missing = cameras(self.run.sensors)
        for i, c in enumerate(cams):
            self._add(
                self.scene.add_camera_frustum(
                    f"{self.root}/cameras/{i}",
                    fov=c.fov_y,
                    aspect=c.aspect,
                    scale=scale,
                    color=(60, 60, 60) if not self.ghost else self.color,
                    wxyz=c.wxyz,
                    position=c.position,
                    thickness=2.0,
                    thickness_units="screen",
                )
            )
            self._add(
                self.scene.add_label(
                    f"{self.root}/cameras/{i}/label", c.name, position=(0.0, 0.0, 0.0)
                )
            )
        for name in missing:
            self.notes.append(f"camera '{name}': no pose in its scenario params; frustum not drawn")

    def _make_body(self, b: Body):
        name, opacity = f"{self.root}/bodies/{b.name}", 0.55 if self.ghost else None
        color = self.color if self.tint else b.color
        if b.shape == "box":
            return self.scene.add_box(
                name,
                color=color,
                dimensions=np.asarray(b.size, float),
                opacity=opacity,
                visible=False,
            )
        if b.shape == "sphere":
            return self.scene.add_icosphere(
                name, radius=b.size[0], color=color, opacity=opacity, visible=False
            )
        if b.shape == "cylinder":
            return self.scene.add_cylinder(
                name,
                radius=b.size[0],
                height=b.size[1],
                color=color,
                opacity=opacity,
                visible=False,
            )
        raise ValueError(f"body {b.name!r}: unknown shape {b.shape!r}")

    def setup(self) -> None:
        """``build`` the scene, then its extra ``bodies``."""
        self.build()
        self._bodies = []
        for b in self.bodies():
            try:
                h = self._add(self._make_body(b))
            except ValueError as exc:
                self.notes.append(f"{exc}: not drawn")
                continue
            if b.label:
                self._add(self.scene.add_label(f"{self.root}/bodies/{b.name}/label", b.label))
            self._bodies.append((b, h))

    def draw(self, run: RunData, t: float) -> None:
        """Show time ``t``: ``update`` the scene, then move its extra bodies."""
        self.update(run, t)
        for b, h in getattr(self, "_bodies", ()):
            pose = b.pose(run, t)
            ok = pose is not None and bool(np.all(np.isfinite(np.r_[pose[0], pose[1]])))
            h.visible = ok
            if pose is not None and ok:
                h.position = tuple(float(v) for v in pose[0])
                h.wxyz = tuple(float(v) for v in pose[1])

    def body_points(self) -> np.ndarray:
        """The extra bodies' positions at up to ``FIT_SAMPLES`` of the run's frame times."""
        times = self.frame_times()
        if len(times) > FIT_SAMPLES:
            times = times[np.linspace(0, len(times) - 1, FIT_SAMPLES).astype(int)]
        pts = []
        for b in self.bodies():
            for t in times:
                pose = b.pose(self.run, float(t))
                if pose is not None:
                    pts.append(np.asarray(pose[0], float)[:3])
        return np.asarray(pts, float).reshape(-1, 3)

    def fit(self) -> tuple[np.ndarray, np.ndarray]:
        """The box the camera fits at load: the moving parts (``focus_points``) and the extra
        bodies; the scene's ``bounds`` when it names no moving part."""
        pts = self.focus_points()
        if pts is None or not len(pts):
            lo, hi = self.bounds()
            pts = np.array([lo, hi], float)
        return fit_bounds(np.concatenate([np.asarray(pts, float), self.body_points()]))

    # -- interface --------------------------------------------------------------------------
    def build(self) -> None:
        raise NotImplementedError

    def update(self, run: RunData, t: float) -> None:
        raise NotImplementedError

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def plots(self) -> list[PlotSpec]:
        return []

    def bodies(self) -> list[Body]:
        """Extra bodies to draw (none by default); see :class:`Body`."""
        return []

    def focus_points(self) -> np.ndarray | None:
        """Points (n, 3) of the parts the experiment is about (the hand, the object), which the
        camera fits at load; None: the whole ``bounds``."""
        return None

    def focus(self, run: RunData, t: float) -> np.ndarray | None:
        """The point the camera follows (the object) at time t, or None."""
        return None

    def frame_times(self) -> np.ndarray:
        for topic in self.needs:
            tr = self.run.track(topic)
            if tr is not None:
                return tr.t
        return np.zeros(0)

    def remove(self) -> None:
        import warnings

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # children of removed parents
            for h in [*self.handles, *self.dynamic.values()]:
                try:
                    h.remove()
                except Exception:  # noqa: BLE001 - already removed
                    pass
        self.handles, self.dynamic = [], {}


def scene_classes() -> dict[str, type[RunScene]]:
    """The installed builders by plant type (entry points ``paper_replay.viewer_scenes``, and
    those registered in this process with ``registry.register("viewer_scene", ...)``)."""
    return {name: registry.load("viewer_scene", name) for name in registry.names("viewer_scene")}


def scene_class(run: RunData) -> type[RunScene]:
    """The builder for a run: a variant of its plant type (``PLANT.VARIANT``) that ``suits`` it,
    else the one registered under its plant type, else the first whose topics it holds."""
    scenes = scene_classes()
    for key, cls in scenes.items():
        if key.startswith(f"{run.plant_type}.") and cls.suits(run) and cls.drawable(run):
            return cls
    own = scenes.get(run.plant_type)
    if own is not None and own.drawable(run):
        return own
    for cls in scenes.values():
        if cls.drawable(run):
            return cls
    where = run.path if run.path is not None else run.label
    need = " or ".join(dict.fromkeys(t for c in scenes.values() for t in c.needs))
    topics = sorted(run.tracks)
    have = ", ".join(clean(t, 80) for t in topics[:10]) or "none"
    have += f" and {len(topics) - 10:,} more" if len(topics) > 10 else ""
    raise ViewerError(
        f"{where}: nothing the viewer can draw: needs {need} (topics in the log: {have})"
    )
