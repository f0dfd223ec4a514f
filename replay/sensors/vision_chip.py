"""The SPE-256 vision chip on the active-vision head (Namiki et al. 1999, Sec. 3.2): a 16 x 16
array of photodetectors, each with its own processing element, read as a **binary** image at
1 kHz.

Each frame: the camera's pose comes from the head's joint angles (``Scene.readings["head"]``,
the plant's ``replay.robot.head.camera_pose``); the scene's silhouettes are rendered through that
pinhole camera (:func:`replay.sensors.silhouette.render`: exact projected outlines, each pixel's
exact coverage), Gaussian grey-level noise is
added, and each pixel is thresholded into one bit. What happens to the bits (Self Windowing,
moments) is the method's (``replay.control.grasping``): the chip's PEs run the paper's
algorithm, so it is not part of this sensor.

Published on ``/vision/chip``: ``VisionChip(t, width, height, rows, count)``, ``rows[v]`` an
int whose bit ``u`` is pixel (u, v) (u right, v down, OpenCV's image axes), ``t`` the capture
time. Cost: ~30 us a frame (was ~0.5-0.7 ms), the frames bit-equal.

The field of view is not in the paper: 12 deg (a scenario's assumption) makes the 16 pixels span
~0.17 m at 0.8 m, so a 10 cm box covers ~9 x 5 pixels and a 7 cm ball ~7 pixels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from replay.messages import TOPIC_VISION_CHIP, VisionChip, pack_rows
from replay.interfaces import Sensor
from replay.params import param
from replay.scene import Scene
from replay.sensors.pinhole import Intrinsics, PinholeCamera, check_image_size
from replay.accel import accelerator
from replay.sensors.silhouette import render

_pixels = accelerator("replay.sensors._pixels")


@dataclass
class VisionChipParams:
    fov: float = param(
        math.radians(12.0),
        unit="rad",
        gt=0.0,
        lt=math.pi,
        doc="full horizontal field of view (square pixels); the paper gives none: 12 deg assumed",
    )
    width: int = param(16, unit="px", ge=2, doc="photodetectors per row; SPE-256: 16")
    height: int = param(16, unit="px", ge=2, doc="rows; SPE-256: 16")
    threshold: float = param(
        0.5,
        unit="1",
        gt=0.0,
        lt=1.0,
        doc="a pixel is 1 when its grey level is above background + "
        "threshold * (object - background): ~half covered",
    )
    object_albedo: float = param(
        0.9, unit="1", gt=0.0, le=1.0, doc="albedo the threshold is set for (the object's)"
    )
    background: float = param(0.1, unit="1", ge=0.0, lt=1.0, doc="albedo of the background")
    noise_sigma: float = param(
        0.0, unit="grey level", ge=0.0, doc="Gaussian grey-level noise before thresholding (0..255)"
    )
    reading: str = param("head", doc="the plant's reading with the camera pose")
    log_images: bool = param(
        True,
        doc="write the binary image to the log (RawImage mono8, 0/255, /camera/SENSOR/image) at the "
        "camera rate",
    )

    def __post_init__(self) -> None:
        check_image_size(self.width, self.height)


class VisionChipSensor(Sensor):
    """16 x 16 binary images from the head's camera: ``/vision/chip``."""

    Params = VisionChipParams
    topic = TOPIC_VISION_CHIP
    spec_type = None
    description = "SPE-256 vision chip: 16x16 binary image at 1 kHz from the pan/tilt head"

    def __init__(self, params: VisionChipParams, *, rng: np.random.Generator, spec=None) -> None:
        super().__init__(params, rng=rng, spec=spec)
        p = params
        self.intrinsics = Intrinsics.from_fov(p.width, p.height, p.fov)
        self.level = 255.0 * (p.background + p.threshold * (p.object_albedo - p.background))
        self.last_image: np.ndarray | None = None
        self._camera = PinholeCamera(self.intrinsics)

    def camera(self, scene: Scene) -> PinholeCamera:
        """The chip's camera at this frame's pose (one object, its pose replaced each frame: the
        head model's rotation is orthonormal by construction, so it is not re-validated)."""
        r = scene.readings[self.params.reading]
        self._camera.rotation = np.ascontiguousarray(r["camera_rotation"], float)
        self._camera.position = np.asarray(r["camera_position"], float)
        return self._camera

    def image(self, scene: Scene) -> np.ndarray:
        """The binary (h, w) bool image of this frame."""
        p = self.params
        img = render(self.camera(scene), scene, background=p.background)
        if p.noise_sigma > 0.0:
            img += np.float32(p.noise_sigma) * self.rng.standard_normal(img.shape, dtype=np.float32)
        return img > self.level

    def frame_images(self) -> list[tuple[str, np.ndarray]]:
        """The last frame: ``[("image", bool HxW)]`` (its RawImage is 0 / 255)."""
        return [] if self.last_image is None else [("image", self.last_image)]

    def measure(self, t: float, scene: Scene) -> VisionChip | None:
        bits = self.image(scene)
        self.last_image = bits
        h, w = bits.shape
        if w <= 63 and _pixels is not None:  # pack_rows, by the accelerator
            rows, count = _pixels.pack_rows(bits, w, h)
        else:
            rows, count = pack_rows(bits), int(bits.sum())
        return VisionChip(t, int(w), int(h), rows, int(count))
