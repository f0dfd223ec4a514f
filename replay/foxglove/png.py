"""A grey-level PNG encoder of our own: same pixels, same bytes, and cheap.

``cv2.imencode(".png", ...)`` of a 128 x 128 image costs ~250 us, zlib's level 1 on the whole
filtered frame ~30 us. A camera frame is mostly background, often the same row many times, so
the PNG is written by a small compiled encoder (``_png.c``): its image data one deflate block of
fixed Huffman codes (RFC 1951) in which a row equal to the row above is one copy of it and a run of
equal bytes is one copy at distance 1; no zlib, no per-image allocation of its state. A
:class:`WindowedImage` (the sensor's rendered window and the background level around it) is
encoded without building the whole frame in Python: the encoder takes the image itself (a
WindowedImage's fields or an array's buffer), its codes from tables made at import (each fixed
Huffman code, each match length's code), the CRC eight bytes a step. It reads the rows, not the
window: the bytes depend only on the pixels (a whole array and the same pixels as a window give
the same PNG). Every decoder reads them (zlib, libpng through OpenCV, PIL: tests, which keep zlib's
encoder of the same rows as the reference).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from replay.foxglove import _png


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

    def full(self) -> np.ndarray:
        """The whole frame as a (height, width) uint8 array."""
        out = np.full((self.height, self.width), self.background, np.uint8)
        x0, y0, x1, y1 = self.window
        out[y0:y1, x0:x1] = self.pixels
        return out


def encode_png(image: np.ndarray | WindowedImage) -> bytes:
    """An (h, w) image as an 8-bit grey PNG: uint8 as is, bool as 0 / 255; a
    :class:`WindowedImage` (its pixels uint8, (y1 - y0, x1 - x0)) as its whole frame. ValueError
    for an image it does not take (not 2-D, another dtype, pixels that do not fill the window,
    an empty frame). The compiled encoder reads the image itself (its fields, the pixels'
    buffer, strided pixels copied to rows)."""
    return _png.png(image)


# png_message(prefix, suffix, image): ``prefix``, the image's PNG as protobuf field 2
# (length-delimited), ``suffix``: a ``foxglove.CompressedImage`` in one compiled call
# (replay/foxglove/wire.py's fields), called straight (no Python frame an image)
png_message = _png.message

# png_messages(message, views, frames, start, prefix, t_ns): a camera frame's images, each as
# png_message(prefix, views[view][1], image) to message(views[view][0], t_ns, t_ns, data), in
# one compiled call; -1, or the index of the first frame whose view has no channel yet
png_messages = _png.messages
