"""The viewer's camera panel: each logged camera image (``/camera/SENSOR/VIEW``, ``foxglove.RawImage``:
docs/foxglove.md) at the shown time, with the centroid the vision measured in it drawn as a red
ring (stereo: ``/vision/object`` ``features.centroids``; the vision chip: the recognition's
``/grasping/object`` ``xi``), matched to the image by its capture time. The mark is a ring
around the centroid, so the blob it was measured from stays visible."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from replay.foxglove.image import pixels
from replay.foxglove.schemas import decode
from replay.limits import LimitError, check, limit
from replay.log import LogReader
from replay.messages import TOPIC_GRASP_OBJECT, TOPIC_VISION_OBJECT
from replay.viewer.errors import ViewerError

CAMERA_PREFIX = "/camera/"
SIZE = 256  # px: the panel's image width (nearest-neighbour up, area-averaged down)
MARK = (230, 40, 40)  # RGB


def mark_radius(scale: float) -> int:
    """The ring's radius (panel px) on an image shown at ``scale`` panel px per pixel."""
    return max(6, round(1.5 * scale))


@dataclass
class ImageTrack:
    topic: str
    sensor: str
    view: str
    t_ns: np.ndarray  # capture times
    images: list[np.ndarray]  # (h, w) uint8
    marks: dict[int, tuple[float, float]] = field(default_factory=dict)  # t_ns -> (u, v) px

    def index(self, t: float) -> int | None:
        """The last image captured at or before ``t`` (s), or None before the first."""
        k = int(np.searchsorted(self.t_ns, int(round(t * 1e9)), side="right")) - 1
        return k if k >= 0 else None

    def frame(self, k: int) -> np.ndarray:
        """Image ``k`` as RGB, scaled to :data:`SIZE` px wide, its centroid marked."""
        grey = self.images[k]
        h, w = grey.shape
        s = SIZE / w
        interp = cv2.INTER_NEAREST if s >= 1 else cv2.INTER_AREA
        big = cv2.resize(grey, (SIZE, max(1, round(h * s))), interpolation=interp)
        rgb = cv2.cvtColor(big, cv2.COLOR_GRAY2RGB)
        mark = self.marks.get(int(self.t_ns[k]))
        if mark is not None:  # pixel (u, v) centre is at ((u + 0.5) s, (v + 0.5) s)
            x, y = ((c + 0.5) * s - 0.5 for c in mark)
            cv2.circle(rgb, (round(x), round(y)), mark_radius(s), MARK, 1, cv2.LINE_8)
        return rgb


def _marks(reader: LogReader, sensor_type: str, sensor: dict, view: str, times: set) -> dict:
    """The measured centroid of each frame of one camera view, by capture time (``times``:
    the frames', so no more are kept than frames)."""
    out: dict[int, tuple[float, float]] = {}
    if sensor_type == "stereo_ball":
        params = sensor.get("params")
        topic = str(
            (params if isinstance(params, dict) else {}).get("topic") or TOPIC_VISION_OBJECT
        )
        i = int(view[-1]) if view[-1:].isdigit() else 0
        for m in reader.messages(topic):
            c = (m.data.get("features") or {}).get("centroids")
            if isinstance(c, list) and len(c) > i and m.t_ns in times:
                out[m.t_ns] = (float(c[i][0]), float(c[i][1]))
    elif sensor_type == "vision_chip":
        for m in reader.messages(TOPIC_GRASP_OBJECT):
            xi = m.data.get("xi")
            if m.data.get("found") and isinstance(xi, list) and len(xi) == 2:
                t_ns = int(round(float(m.data["t"]) * 1e9))
                if t_ns in times:
                    out[t_ns] = (float(xi[0]), float(xi[1]))
    return out


def load_image_tracks(path: str | Path, sensors: dict) -> list[ImageTrack]:
    """Every camera view's images in the log at ``path`` (``sensors``: the scenario's), at
    most ``viewer_bytes`` of them as stored (each image is a view of its stored bytes):
    :class:`LimitError` past it."""
    reader = LogReader(path)
    found: dict[str, tuple[list, list]] = {}
    cap, kept = limit("viewer_bytes"), 0
    for m in reader.raw():
        if m.topic.startswith(CAMERA_PREFIX) and m.schema == "foxglove.RawImage":
            kept += len(m.data)
            if kept > cap:
                try:
                    check("viewer_bytes", kept, f"{path}: its camera images (read so far)")
                except LimitError as exc:
                    raise ViewerError(str(exc)) from None
            ts, images = found.setdefault(m.topic, ([], []))
            ts.append(m.t_ns)
            images.append(pixels(decode(m.schema, m.data)))
    tracks = []
    for topic, (ts, images) in sorted(found.items()):
        sensor, _, view = topic[len(CAMERA_PREFIX) :].partition("/")
        spec = sensors.get(sensor) or {}
        tr = ImageTrack(topic, sensor, view, np.asarray(ts, np.int64), images)
        tr.marks = _marks(reader, str(spec.get("type", "")), spec, view, set(ts))
        tracks.append(tr)
    return tracks


class ImagePanel:
    """One GUI image per camera view, showing the frame at the viewer's time."""

    def __init__(self, server, tracks: list[ImageTrack]) -> None:
        self.tracks = tracks
        self.handles = []
        self.shown: list[int | None] = []
        for tr in tracks:
            blank = np.zeros((SIZE, SIZE, 3), np.uint8)
            self.handles.append(server.gui.add_image(blank, label=tr.topic, format="png"))
            self.shown.append(None)

    def show(self, t: float) -> None:
        for i, (tr, handle) in enumerate(zip(self.tracks, self.handles)):
            k = tr.index(t)
            if k is not None and k != self.shown[i]:
                handle.image = tr.frame(k)
                self.shown[i] = k
