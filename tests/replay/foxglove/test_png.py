"""The compiled PNG encoder (replay/foxglove/_png.c through png.py) against the reference it
replaced: zlib's level-1 deflate of the same filtered rows (kept here). Every PNG decodes to the
same pixels with zlib, OpenCV (libpng) and PIL; a window in the background gives the same bytes
as its whole frame; the sensors' frames are their images."""

from __future__ import annotations

import io
import struct
import zlib

import cv2
import numpy as np
import pytest
from PIL import Image

from replay.foxglove.png import WindowedImage, encode_png
from replay.scene import Scene, Sphere
from replay.sensors.stereo import StereoBallCamera, StereoBallCameraParams


def _chunk(tag: bytes, data: bytes) -> bytes:
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))


def reference_png(img: np.ndarray) -> bytes:
    """The Python encoder the compiled one replaced: filter 0 rows, zlib.compress level 1."""
    if img.dtype == bool:
        img = img.astype(np.uint8) * np.uint8(255)
    h, w = img.shape
    rows = np.zeros((h, w + 1), np.uint8)
    rows[:, 1:] = img
    return (
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 0, 0, 0, 0))
        + _chunk(b"IDAT", zlib.compress(rows.tobytes(), 1))
        + _chunk(b"IEND", b"")
    )


def idat(data: bytes) -> bytes:
    """The IDAT payload of a PNG (one IDAT chunk), its CRC checked."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, out = 8, b""
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos : pos + 4])
        tag, body = data[pos + 4 : pos + 8], data[pos + 8 : pos + 8 + n]
        assert struct.unpack(">I", data[pos + 8 + n : pos + 12 + n])[0] == zlib.crc32(tag + body)
        if tag == b"IDAT":
            out += body
        pos += 12 + n
    return out


def decoders(data: bytes) -> list[np.ndarray]:
    """The image as zlib (the raw rows), OpenCV and PIL read it."""
    w, h = struct.unpack(">II", data[16:24])
    raw = np.frombuffer(zlib.decompress(idat(data)), np.uint8).reshape(h, w + 1)
    assert not raw[:, 0].any()  # filter type 0 on every row
    return [
        raw[:, 1:],
        cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED),
        np.asarray(Image.open(io.BytesIO(data))),
    ]


def random_window(rng) -> WindowedImage:
    """A frame of random size with a random window: noise, flat rows, repeated rows or mostly
    background inside it."""
    h, w = int(rng.integers(1, 260)), int(rng.integers(1, 260))
    bg = 0 if rng.random() < 0.2 else int(rng.integers(0, 256))  # (0: the rows' filter byte)
    x0, x1 = sorted(int(v) for v in rng.integers(0, w + 1, 2))
    y0, y1 = sorted(int(v) for v in rng.integers(0, h + 1, 2))
    pix = rng.integers(0, 256, (y1 - y0, x1 - x0)).astype(np.uint8)
    kind = rng.integers(0, 4)
    if kind == 1:  # mostly background, as the cameras' windows are
        pix[rng.random(pix.shape) < 0.8] = bg
    elif kind == 2:  # flat rows (runs)
        pix[:] = pix[:, :1]
    elif kind == 3 and pix.shape[0]:  # the same row again and again
        pix[:] = pix[:1]
    return WindowedImage(h, w, bg, (x0, y0, x1, y1), pix)


def test_compiled_png_decodes_to_the_reference_pixels_everywhere():
    rng = np.random.default_rng(10)
    n, agree, smaller = 300, 0, 0
    for _ in range(n):
        win = random_window(rng)
        full = win.full()
        data = encode_png(win)
        ref = reference_png(full)
        assert encode_png(full) == data  # the bytes depend on the pixels, not on the window
        assert encode_png(WindowedImage(*full.shape, 0, (0, 0, *full.shape[::-1]), full)) == data
        agree += all(np.array_equal(d, full) for d in decoders(data) + decoders(ref))
        assert data[:33] == ref[:33] and data[-12:] == ref[-12:]  # IHDR, IEND as the reference
        smaller += len(data) <= len(ref)
    print(f"compiled PNG = reference pixels for {agree}/{n} images ({smaller} no bigger)")
    assert agree == n


def test_png_of_bool_images_and_bad_input():
    rng = np.random.default_rng(11)
    for _ in range(30):
        bits = rng.random((16, 16)) < rng.uniform(0.0, 0.6)
        data = encode_png(bits)
        assert data == encode_png(bits.astype(np.uint8) * np.uint8(255))
        for d in decoders(data):
            assert set(np.unique(d)) <= {0, 255} and np.array_equal(d == 255, bits)
    for bad in (np.zeros((4, 4, 3), np.uint8), np.zeros((4, 4), np.float32), np.zeros((0, 4))):
        with pytest.raises(ValueError):
            encode_png(bad)
    with pytest.raises(ValueError):  # pixels that do not fill their window
        encode_png(WindowedImage(8, 8, 0, (0, 0, 4, 4), np.zeros((3, 4), np.uint8)))
    with pytest.raises(ValueError):  # a window's pixels are uint8
        encode_png(WindowedImage(8, 8, 0, (0, 0, 4, 4), np.zeros((4, 4), bool)))


def test_strided_pixels_give_the_bytes_of_their_contiguous_copy():
    rng = np.random.default_rng(13)
    for _ in range(50):
        win = random_window(rng)
        full = win.full()
        data = encode_png(full)
        wide = np.zeros((full.shape[0], 2 * full.shape[1]), np.uint8)
        wide[:, ::2] = full
        assert encode_png(wide[:, ::2]) == data  # strided columns
        assert encode_png(np.asfortranarray(full)) == data
        x0, y0, x1, y1 = win.window
        tall = np.zeros((2 * (y1 - y0), x1 - x0), np.uint8)
        tall[::2] = win.pixels
        assert encode_png(win._replace(pixels=tall[::2])) == data  # strided rows of a window


def test_stereo_frames_are_its_whole_images():
    s = StereoBallCamera(StereoBallCameraParams(), rng=np.random.default_rng(0))
    rng = np.random.default_rng(12)
    for _ in range(20):
        X = (rng.uniform(0.8, 2.3), rng.uniform(-0.1, 0.1), rng.uniform(0.5, 1.0))
        s.measure(0.0, Scene([Sphere("ball", X, 0.0175, albedo=1.0)]))
        frames = s.frame_images()
        assert [v for v, _ in frames] == ["cam0", "cam1"]
        for (_, win), whole in zip(frames, s.last_images):
            assert whole is not None
            np.testing.assert_array_equal(win.full(), whole)
            assert encode_png(win) == encode_png(whole)


def test_a_frames_images_in_one_call_are_the_messages_one_at_a_time(tmp_path):
    """FoxgloveTopics.images (compiled: _png.messages) writes the file that writing each
    image's png_message by write_raw writes, new views' channels made in the same order."""
    from foxglove_schemas_protobuf.CompressedImage_pb2 import CompressedImage

    from replay.foxglove import wire
    from replay.foxglove.png import png_message
    from replay.foxglove.topics import FoxgloveTopics, camera_topic
    from replay.log import LogWriter

    rng = np.random.default_rng(14)
    frames = []
    for k in range(60):
        views = ["cam0", "cam1", "cam2"][: int(rng.integers(1, 4))]
        bits = rng.random((8, 8)) < 0.3
        frames.append(
            (
                ["a", "b"][k % 2],
                [(v, random_window(rng) if v != "cam2" else bits) for v in views],
                1_000_000 * k,
            )
        )
    with LogWriter(tmp_path / "one_call.mcap", chunk_size=2048) as log:
        out = FoxgloveTopics(log)
        for sensor, views, t_ns in frames:
            out.images(sensor, views, t_ns)
    with LogWriter(tmp_path / "each.mcap", chunk_size=2048) as log:
        ref = FoxgloveTopics(log)
        channels: dict = {}
        for sensor, views, t_ns in frames:
            for view, image in views:
                if (sensor, view) not in channels:
                    channels[sensor, view] = ref._wire(camera_topic(sensor, view), CompressedImage)
                tail = wire.image_tail(f"{sensor}/{view}", "png")
                log.write_raw(
                    channels[sensor, view], png_message(wire._timestamp(t_ns), tail, image), t_ns
                )
    data = (tmp_path / "one_call.mcap").read_bytes()
    assert data == (tmp_path / "each.mcap").read_bytes() and len(data) > 10_000
