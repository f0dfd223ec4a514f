"""Test oracles of the cameras' pixel conventions (replay/sensors/pinhole.py)."""

from __future__ import annotations

import numpy as np


def in_image(camera, pixels) -> np.ndarray:
    """Whether pixels lie on ``camera``'s sensor: integer pixels are centres, so the image
    covers ``-0.5 <= u < width - 0.5``, likewise v; NaN is off it."""
    uv = np.asarray(pixels, dtype=float)
    w, h = camera.intrinsics.width, camera.intrinsics.height
    with np.errstate(invalid="ignore"):
        return (
            (uv[..., 0] >= -0.5)
            & (uv[..., 0] < w - 0.5)
            & (uv[..., 1] >= -0.5)
            & (uv[..., 1] < h - 0.5)
        )
