"""Camera frames as Foxglove ``RawImage`` messages (``mono8``): the pixels as they are, left to
the log's zstd chunks to compress (a stereo frame of 128 x 128, mostly background, compresses
to a few dozen bytes there), read by Foxglove's Image panel, ``rerun mcap convert`` and the
viewer's Cameras panel (:func:`pixels`)."""

from __future__ import annotations

from typing import NamedTuple

import foxglove.messages as fm
import numpy as np
from foxglove_schemas_protobuf.RawImage_pb2 import RawImage

ENCODING = "mono8"  # 8-bit grey, one byte a pixel (Foxglove's RawImage encodings)


class WindowedImage(NamedTuple):  # (a tuple: ~5x cheaper to make than a frozen dataclass)
    """An (height, width) grey frame that is ``background`` outside ``window`` = (x0, y0, x1,
    y1), where it is ``pixels`` (uint8, (y1 - y0, x1 - x0)): what a windowed camera renders."""

    height: int
    width: int
    background: int
    window: tuple[int, int, int, int]
    pixels: np.ndarray

    @property
    def shape(self) -> tuple[int, int]:
        return (self.height, self.width)

    def full(self, out: np.ndarray | None = None) -> np.ndarray:
        """The whole frame as a (height, width) uint8 array: ``out`` (such an array, e.g. the
        last frame's, refilled: no new array a frame) or a new one."""
        if out is None or out.shape != (self.height, self.width):
            out = np.empty((self.height, self.width), np.uint8)
        out.fill(self.background)  # (np.empty + fill: cheaper than np.full)
        x0, y0, x1, y1 = self.window
        out[y0:y1, x0:x1] = self.pixels
        return out


def grey(image: np.ndarray | WindowedImage, out: np.ndarray | None = None) -> np.ndarray:
    """An (h, w) image as 8-bit grey pixels: uint8 as is, bool as 0 / 255, a
    :class:`WindowedImage` as its whole frame (in ``out``: :meth:`WindowedImage.full`). ValueError for an image it does not take (not
    2-D, another dtype, pixels that do not fill the window, an empty frame)."""
    if isinstance(image, WindowedImage):
        x0, y0, x1, y1 = image.window
        if image.pixels.dtype != np.uint8 or image.pixels.shape != (y1 - y0, x1 - x0):
            raise ValueError(f"window {image.window}: pixels {image.pixels.shape}")
        image = image.full(out)
    image = np.asarray(image)
    if image.ndim != 2 or image.size == 0:
        raise ValueError(f"a grey image is 2-D and not empty, not of shape {image.shape}")
    if image.dtype == np.bool_:
        return image.astype(np.uint8) * np.uint8(255)
    if image.dtype != np.uint8:
        raise ValueError(f"a grey image is uint8 or bool, not {image.dtype}")
    return image


def raw_image(
    image: np.ndarray | WindowedImage, frame_id: str, t_ns: int, out: np.ndarray | None = None
) -> bytes:
    """``foxglove.RawImage`` (mono8) of an image (:func:`grey`, a windowed one's frame built in
    ``out`` when given) captured at ``t_ns``: built and encoded by foxglove-sdk (the bytes the
    ``RawImage`` class below serialises, in half the time: 3.8 -> 1.8 us for 128 x 128)."""
    pixels = grey(image, out)
    h, w = pixels.shape
    sec, nsec = divmod(t_ns, 1_000_000_000)
    return fm.RawImage(
        timestamp=fm.Timestamp(sec, nsec),
        frame_id=frame_id,
        width=w,
        height=h,
        encoding=ENCODING,
        step=w,
        data=pixels.tobytes(),
    ).encode()


def pixels(message: RawImage) -> np.ndarray:
    """The (height, width) uint8 pixels of a mono8 ``RawImage``; ValueError for another
    encoding or data that do not fill the image."""
    if message.encoding != ENCODING:
        raise ValueError(f"RawImage encoding {message.encoding!r}: only {ENCODING} is read")
    h, w, step = message.height, message.width, message.step
    if w < 1 or h < 1 or step < w or len(message.data) < h * step:
        raise ValueError(f"RawImage {w} x {h}, step {step}: {len(message.data)} bytes of data")
    return np.frombuffer(message.data, np.uint8, h * step).reshape(h, step)[:, :w]
