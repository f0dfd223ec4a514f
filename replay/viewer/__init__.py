"""The browser replay viewer (Viser): ``replay view LOG [LOG2 …]`` and ``replay run --view``.

- :mod:`~replay.viewer.data` — a log into compact NumPy arrays (``load_run``);
- :mod:`~replay.viewer.geometry` — cameras from the run's scenario;
- :mod:`~replay.viewer.scenes` — what scene builders share; the builders themselves are plug-ins
  (entry points ``paper_replay.viewer_scenes``, by plant type: ``plants/*/viewer_scene.py``);
- :mod:`~replay.viewer.timeline`, :mod:`~replay.viewer.plots` — the GUI;
- :mod:`~replay.viewer.app` — the server's lifecycle (``Viewer``, ``LiveSession``).

Nothing here imports a simulator or a plug-in: the viewer draws from the log and from URDF files.
"""

from replay.viewer.data import RunData, Track, load_run
from replay.viewer.errors import ViewerError
from replay.viewer.timeline import DEFAULT_SPEED, SPEEDS

__all__ = [
    "DEFAULT_SPEED",
    "LiveSession",
    "RunData",
    "SPEEDS",
    "Track",
    "Viewer",
    "ViewerError",
    "load_run",
]


def __getattr__(name):  # Viewer/LiveSession import viser: only when asked for
    if name in ("Viewer", "LiveSession"):
        from replay.viewer import app

        return getattr(app, name)
    raise AttributeError(name)
