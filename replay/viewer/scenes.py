"""Scene builders, one per kind of experiment: handles created once, moved to a time ``t``.

A builder owns the scene nodes of one run under ``/runK`` (several runs overlay: run 0 in its
natural colours, later runs tinted and see-through). It draws from the run's tracks and the
scenario's geometry only, and says in ``notes`` what it could not draw and why.

Builders are plug-ins: a subclass of :class:`RunScene`, found through the entry-point group
``paper_replay.viewer_scenes`` under the plant type it draws (``replay.registry``, kind
``"viewer_scene"``), e.g. ``plants/airtable/viewer_scene.py``. This module holds what every
builder shares; it imports no plug-in (docs/viewer.md says how to add one).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import viser

from replay import registry
from replay.scenario import ScenarioError, params_from_data
from replay.viewer.data import RunData
from replay.viewer.errors import ViewerError
from replay.viewer.geometry import cameras

RUN_COLORS = [(225, 95, 30), (35, 110, 220), (40, 160, 70), (150, 60, 180), (200, 160, 20)]
PATH_POINTS = 600  # a path so far is drawn with at most this many points


def run_color(k: int) -> tuple[int, int, int]:
    return RUN_COLORS[k % len(RUN_COLORS)]


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
        self.color = run_color(index)
        self.ghost = index > 0
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
        """For a variant (registered as ``PLANT.VARIANT``, e.g. ``bullet_arm.grasp``): whether it
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
    need = " or ".join(t for c in scenes.values() for t in c.needs)
    have = ", ".join(sorted(run.tracks)) or "none"
    raise ViewerError(
        f"{where}: nothing the viewer can draw: needs {need} (topics in the log: {have})"
    )
