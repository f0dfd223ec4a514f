"""A grey-level PNG encoder of our own: same pixels, same bytes, and cheap.

``cv2.imencode(".png", ...)`` of a 128 x 128 image costs ~250 us; this one (filter type 0,
zlib level 1) ~30 us, and its bytes depend only on the pixels and zlib's level-1 deflate.
"""

from __future__ import annotations

import struct
import zlib

import numpy as np

_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_IEND = struct.pack(">I", 0) + b"IEND" + struct.pack(">I", zlib.crc32(b"IEND"))


def _chunk(tag: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))


def encode_png(image: np.ndarray) -> bytes:
    """An (h, w) image as an 8-bit grey PNG: uint8 as is, bool as 0 / 255."""
    img = np.asarray(image)
    if img.ndim != 2:
        raise ValueError(f"expected an (h, w) grey image, got shape {img.shape}")
    if img.dtype == bool:
        img = img.astype(np.uint8) * np.uint8(255)
    elif img.dtype != np.uint8:
        raise ValueError(f"expected a uint8 or bool image, got {img.dtype}")
    h, w = img.shape
    rows = np.empty((h, w + 1), np.uint8)
    rows[:, 0] = 0  # filter type 0 (None) on every row
    rows[:, 1:] = img
    header = struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0)  # 8-bit grey, no interlace
    return (
        _SIGNATURE
        + _chunk(b"IHDR", header)
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 1))
        + _IEND
    )
