"""The browser replay viewer (Viser): ``replay view LOG [LOG2 …]`` and ``replay run --view``.

- :mod:`~replay.viewer.data` — a log into compact NumPy arrays (``load_run``);
- :mod:`~replay.viewer.geometry` — sizes, URDFs and cameras from the run's scenario;
- :mod:`~replay.viewer.scenes` — one scene builder per kind of experiment;
- :mod:`~replay.viewer.timeline`, :mod:`~replay.viewer.plots` — the GUI;
- :mod:`~replay.viewer.app` — the server's lifecycle (``Viewer``, ``LiveSession``).

Nothing here imports a simulator: the viewer draws from the log and from URDF files.
"""

from replay.viewer.data import RunData, Track, load_run
from replay.viewer.errors import ViewerError
from replay.viewer.timeline import DEFAULT_SPEED, SPEEDS

__all__ = ["DEFAULT_SPEED", "LiveSession", "RunData", "SPEEDS", "Track", "Viewer", "ViewerError",
           "load_run"]


def __getattr__(name):        # Viewer/LiveSession import viser: only when asked for
    if name in ("Viewer", "LiveSession"):
        from replay.viewer import app
        return getattr(app, name)
    raise AttributeError(name)
