"""Server lifecycle: a Viser server on 127.0.0.1, the runs' scenes, the timeline and plots.

``Viewer`` shows finished logs (``replay view``); ``LiveSession`` feeds it from a running
``Runner`` (``replay run --view``) and turns into a replay of the log when the run ends.
"""

from __future__ import annotations

import contextlib
import errno
import io
import ipaddress
import socket
import threading
import time
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

from replay.viewer.data import RunAccumulator, RunData, distinct_labels, load_run
from replay.viewer import guard
from replay.viewer.errors import ViewerError
from replay.viewer.images import ImagePanel, load_image_tracks
from replay.viewer.markup import plain
from replay.viewer.plots import PlotPanel
from replay.viewer.scenes import RunScene, run_color, scene_class
from replay.viewer.timeline import DEFAULT_SPEED, Timeline

DEFAULT_HOST = "127.0.0.1"
DEFAULT_PORT = 8080
PORT_TRIES = 50
PLOT_PERIOD = 0.1  # s between plot-cursor updates while playing
FIT_DISTANCE = 1.1  # the camera's distance from the fitted box's centre, in box sizes


def _can_bind(host: str, port: int) -> OSError | None:
    """Why asyncio's ``create_server`` (viser's) could not listen on ``host:port``, or None: it
    binds every address the name resolves to, IPv6 ones IPv6-only (so ``::ffff:0.0.0.0``, an
    IPv4-mapped address, cannot be bound; viser would retry 1000 ports and hang)."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror as exc:
        return exc
    for family, _, _, _, addr in dict.fromkeys(infos):
        with socket.socket(family, socket.SOCK_STREAM) as s:
            s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)  # as asyncio's server does
            if family == socket.AF_INET6:
                s.setsockopt(socket.IPPROTO_IPV6, socket.IPV6_V6ONLY, 1)
            try:
                s.bind(addr)
            except OSError as exc:
                return exc
    return None


def free_port(host: str, port: int) -> tuple[int, str]:
    """``port`` if it is free on ``host``, else the next free one (and a note saying so).
    Port 0 lets the system choose. Raises :class:`ViewerError` for a host we cannot bind."""
    err = _can_bind(host, 0)
    if err is not None:
        hint = ""
        with contextlib.suppress(ValueError):
            ip = ipaddress.ip_address(host.strip("[]"))
            if isinstance(ip, ipaddress.IPv6Address) and ip.ipv4_mapped is not None:
                hint = f" (an IPv4-mapped address: give {ip.ipv4_mapped} instead)"
        raise ViewerError(f"cannot listen on host {host!r}: {err.strerror or err}{hint}")
    if port == 0:
        return 0, ""
    for p in range(port, min(port + PORT_TRIES, 65536)):
        err = _can_bind(host, p)
        if err is None:
            return p, ("" if p == port else f"port {port} is in use; serving on port {p}")
        if err.errno not in (errno.EADDRINUSE, errno.EACCES):
            raise ViewerError(f"cannot listen on {host}:{p}: {err.strerror or err}")
    raise ViewerError(
        f"ports {port}-{port + PORT_TRIES - 1} on {host} are all in use "
        "(choose another with --port)"
    )


def start_server(host: str = DEFAULT_HOST, port: int = DEFAULT_PORT):
    """A Viser server bound to ``host`` (127.0.0.1 unless told otherwise): (server, note)."""
    import viser

    port, note = free_port(host, port)
    with guard.guarded_serve(host) as guarded:
        with contextlib.redirect_stdout(io.StringIO()):  # viser's banner: we print the URL
            server = viser.ViserServer(host=host, port=port, label="paper-replay", verbose=False)
    if not guarded:  # fail closed: this viser starts its websocket some other way
        with contextlib.redirect_stdout(io.StringIO()):
            server.stop()
        raise ViewerError(
            f"viser {viser.__version__}: cannot check who connects to its server (this viewer "
            "knows how viser 1.1.1 starts it); not serving"
        )
    return server, note


def _shows(scene) -> Callable[[Any], None]:
    """A run's "show" checkbox handler: its whole frame shown or hidden."""

    def show(ev) -> None:
        scene.root_frame.visible = ev.target.value

    return show


class Viewer:
    """A browser replay of one or more runs, overlaid and in step on one timeline."""

    def __init__(
        self,
        runs: Iterable[RunData] = (),
        *,
        host: str = DEFAULT_HOST,
        port: int | None = None,
        speed: str = DEFAULT_SPEED,
        urdf_for: Callable[[dict], Path] | None = None,
    ) -> None:
        self.server, self.port_note = start_server(host, DEFAULT_PORT if port is None else port)
        self.host = host
        self.speed = speed
        self.urdf_for = urdf_for
        self.runs: list[RunData] = []
        self.scenes: list[RunScene] = []
        self.timeline: Timeline | None = None
        self.plots: PlotPanel | None = None
        self.images: ImagePanel | None = None
        self.notes: list[str] = []
        self.run_toggles: list = []
        self.follow: Any = None  # the "follow object" checkbox
        self.camera_home: tuple = ((1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
        self.time = 0.0
        self._lock = threading.RLock()
        self._last_plot = 0.0
        self._stopped = threading.Event()
        self._status: Any = None  # the live run's status line
        self.server.scene.set_up_direction("+z")
        runs = list(runs)
        if runs:
            self.load(runs)

    @classmethod
    def open(cls, paths: Iterable[str | Path], **kw) -> "Viewer":
        """Load the logs (one-line :class:`ViewerError` if one cannot be shown), then serve."""
        runs = distinct_labels([load_run(p) for p in paths])
        for run in runs:
            scene_class(run)  # fail before starting a server
        viewer = cls(**kw)
        try:
            viewer.load(runs)
        except ViewerError:
            viewer.stop()
            raise
        except (LookupError, TypeError, ValueError, AttributeError) as exc:
            # a log of the right topics with the wrong fields (a scene plug-in read a field
            # the log does not hold, or of another shape): one line, not a traceback
            viewer.stop()
            where = ", ".join(str(r.path or r.label) for r in runs)
            raise ViewerError(f"{where}: cannot draw it ({guard.describe(exc)})") from None
        return viewer

    @property
    def port(self) -> int:
        return self.server.get_port()

    @property
    def url(self) -> str:
        host = self.host if ":" not in self.host else f"[{self.host}]"
        return f"http://{host}:{self.port}"

    # -- building ---------------------------------------------------------------------------
    def _clear(self) -> None:
        if self.timeline is not None:
            self.timeline.close()
        self.server.scene.reset()  # every node, the runs' and the shared ones
        self.server.gui.reset()
        self.scenes, self.timeline, self.plots, self._status = [], None, None, None
        self.images = self.follow = None

    def _build_scenes(self, runs: list[RunData]) -> None:
        self.runs = list(runs)
        self.notes = []
        for k, run in enumerate(self.runs):
            cls = scene_class(run)
            s = cls(self.server, run, k, urdf_for=self.urdf_for, overlaid=len(self.runs) > 1)
            s.root_frame = self.server.scene.add_frame(s.root, show_axes=False)
            s.setup()
            self.scenes.append(s)
            prefix = f"{run.label}: " if len(self.runs) > 1 else ""
            self.notes += [f"{prefix}{n}" for n in run.notes + s.notes]
        self._frame_camera()

    def fitted(self) -> tuple[np.ndarray, np.ndarray]:
        """The box the camera fits at load: every run's moving parts (``RunScene.fit``)."""
        boxes = [s.fit() for s in self.scenes]
        return np.min([b[0] for b in boxes], axis=0), np.max([b[1] for b in boxes], axis=0)

    def _frame_camera(self) -> None:
        lo, hi = self.fitted()
        c = (lo + hi) / 2.0
        size = float(max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 0.2))
        d = np.array(self.scenes[0].view_direction, float)
        cam = self.server.initial_camera
        cam.position = tuple(c + d / np.linalg.norm(d) * size * FIT_DISTANCE)
        cam.look_at = tuple(c)
        cam.up = (0.0, 0.0, 1.0)
        self.camera_home = (tuple(cam.position), tuple(cam.look_at))

    def follow_point(self, t: float) -> np.ndarray | None:
        """Where the camera looks when following: the first run's object at ``t``."""
        for s in self.scenes:
            p = s.focus(s.run, t)
            if p is not None and np.all(np.isfinite(p)):
                return np.asarray(p, float)
        return None

    def _follow(self, t: float) -> None:
        """Keep every browser's camera on the object: look at it, keep the camera's offset."""
        p = self.follow_point(t)
        if p is None:
            return
        for client in self.server.get_clients().values():
            cam = client.camera
            offset = np.asarray(cam.position, float) - np.asarray(cam.look_at, float)
            with client.atomic():  # viser: position moves look_at along; then look_at
                cam.position = tuple(p + offset)
                cam.look_at = tuple(p)

    def _home(self) -> None:
        pos, look = self.camera_home
        for client in self.server.get_clients().values():
            with client.atomic():
                client.camera.position = pos  # moves look_at along: set it after
                client.camera.look_at = look
                client.camera.up_direction = (0.0, 0.0, 1.0)

    def load(self, runs: list[RunData]) -> None:
        """Show ``runs`` (replacing what is shown): scenes, timeline, events, plots."""
        with self._lock:
            self._clear()
            self._build_scenes(runs)
            gui = self.server.gui
            t0 = min(r.time_range()[0] for r in self.runs)
            t1 = max(r.time_range()[1] for r in self.runs)
            title = " vs ".join(f"**{plain(r.label)}**" for r in self.runs)
            papers = sorted({plain(r.scenario.get("paper", "")) for r in self.runs} - {""})
            gui.add_markdown(
                f"{title}  \n{', '.join(papers) or 'no scenario'} · {t1 - t0:.3f} s simulated"
            )
            if len(self.runs) > 1:
                gui.add_markdown(self.legend())
            if self.notes:
                gui.add_markdown("\n".join(f"- ⚠ {plain(n)}" for n in self.notes))
            frames = np.unique(np.concatenate([s.frame_times() for s in self.scenes]))
            events = [(r.label, e) for r in self.runs for e in r.events if "t" in e]
            events.sort(key=lambda le: le[1]["t"])
            self.timeline = Timeline(
                self.server, (t0, t1), frames, events, self.show, speed=self.speed
            )
            with gui.add_folder("Camera"):
                if self.follow_point(t0) is not None or any(
                    s.focus(s.run, t1) is not None for s in self.scenes
                ):
                    follow = self.follow = gui.add_checkbox(
                        "follow object", False, hint="keep the camera on the object"
                    )
                    follow.on_update(guard.safe(lambda _: self.show(self.time)))
                home = gui.add_button("fit view", hint="back to the fitted view at load")
                home.on_click(guard.safe(lambda _: self._home()))
            self.run_toggles = []
            if len(self.runs) > 1:
                with gui.add_folder("Runs"):
                    for s in self.scenes:
                        cb = gui.add_checkbox(f"show {s.run.label}", True)
                        cb.on_update(guard.safe(_shows(s)))
                        self.run_toggles.append(cb)
            run0 = self.runs[0]  # its cameras' images (the first run's, when overlaid)
            tracks = load_image_tracks(run0.path, run0.sensors) if run0.path else []
            if tracks:
                with gui.add_folder("Cameras"):
                    self.images = ImagePanel(self.server, tracks)
            specs = self.scenes[0].plots()
            if specs:
                with gui.add_folder("Plots"):
                    self.plots = PlotPanel(self.server, specs, self.runs, (t0, t1))
            self.show(t0)

    def legend(self) -> str:
        """Overlaid runs: each run's colour (its arm or stick, object and path) and label."""
        return "  \n".join(
            f"<span style='color:rgb{run_color(k)}'>■</span> {plain(r.label)}"
            for k, r in enumerate(self.runs)
        )

    # -- showing a time -----------------------------------------------------------------------
    def show(self, t: float) -> None:
        with self._lock:
            self.time = float(t)
            with self.server.atomic():
                for s in self.scenes:
                    s.draw(s.run, t)
            if self.follow is not None and self.follow.value:
                self._follow(t)
            tl = self.timeline
            playing = tl is not None and tl.playing
            now = time.perf_counter()
            if not playing or now - self._last_plot >= PLOT_PERIOD:
                self._last_plot = now
                if self.plots is not None:
                    self.plots.set_cursor(t)
                if self.images is not None:
                    self.images.show(t)
            if tl is not None:
                k = int(np.searchsorted(tl.frames, t + 1e-9, side="right"))
                tl.status.content = (
                    f"t = {t:.4f} s · frame {max(k, 1)}/{len(tl.frames)} · "
                    f"speed {plain(tl.speed.value)}"
                )

    def seek(self, t: float) -> None:
        if self.timeline is not None:
            self.timeline.seek(t)
        else:
            self.show(t)

    # -- lifecycle ----------------------------------------------------------------------------
    def wait(self, timeout: float | None = None) -> None:
        """Serve until Ctrl-C or ``timeout`` seconds, then stop."""
        deadline = None if timeout is None else time.monotonic() + timeout
        try:
            while not self._stopped.is_set():
                left = 0.25 if deadline is None else min(0.25, deadline - time.monotonic())
                if left <= 0:
                    break
                self._stopped.wait(left)
        except KeyboardInterrupt:
            pass
        finally:
            self.stop()

    def stop(self) -> None:
        if self._stopped.is_set():
            return
        self._stopped.set()
        if self.timeline is not None:
            self.timeline.close()
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()

    def __enter__(self) -> "Viewer":
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


class LiveSession:
    """``Runner(..., observers=(session.observe,))``: the run drawn as it is computed (at most
    ``rate`` times per wall-clock second), then ``finish(log)`` replays the written log."""

    def __init__(
        self,
        *,
        host: str = DEFAULT_HOST,
        port: int | None = None,
        speed: str = DEFAULT_SPEED,
        rate: float = 20.0,
        urdf_for: Callable[[dict], Path] | None = None,
    ) -> None:
        self.viewer = Viewer(host=host, port=port, speed=speed, urdf_for=urdf_for)
        self.acc = RunAccumulator()
        self.period = 1.0 / rate
        self._next = 0.0
        self.error = ""
        self.refreshes = 0
        self._md = self.viewer.server.gui.add_markdown("waiting for the run's first message…")

    @property
    def url(self) -> str:
        return self.viewer.url

    def observe(self, topic: str, payload, t_ns: int) -> None:
        self.acc.observe(topic, payload, t_ns)
        now = time.perf_counter()
        if now >= self._next:
            self._next = now + self.period
            self.refresh()

    def refresh(self) -> None:
        """Draw the latest state; a drawing failure is noted, never raised into the run."""
        v = self.viewer
        try:
            run = self.acc.snapshot()
            t = self.acc.t_last
            with v._lock:
                if not v.scenes:
                    try:
                        scene_class(run)
                    except ViewerError:
                        return  # nothing drawable yet
                    v._build_scenes([run])
                    v._status = v.server.gui.add_markdown("")
                with v.server.atomic():
                    for s in v.scenes:
                        s.draw(run, t)
                v._status.content = f"**live** · {plain(run.label)} · t = {t:.4f} s (running)"
                self.refreshes += 1
        except Exception as exc:  # noqa: BLE001
            self.error = f"live view stopped: {exc.__class__.__name__}: {exc}"
            self.period = float("inf")

    def finish(self, log: str | Path) -> None:
        """The run is over: replay its log (one-line :class:`ViewerError` if it cannot)."""
        self.refresh()
        self.viewer.load([load_run(log)])

    def wait(self, timeout: float | None = None) -> None:
        self.viewer.wait(timeout)

    def stop(self) -> None:
        self.viewer.stop()
