"""Types of the PNG encoder's compiled kernel (replay/foxglove/_png.c documents it)."""

from typing import Any, Callable, Sequence

Image = Any  # a WindowedImage (its pixels uint8) or an (h, w) uint8 or bool array

def png(image: Image, /) -> bytes: ...
def message(prefix: bytes, suffix: bytes, image: Image, /) -> bytes: ...
def messages(
    message: Callable[[int, int, int, bytes], Any],
    views: dict[str, tuple[int, bytes]],
    frames: Sequence[tuple[str, Image]],
    start: int,
    prefix: bytes,
    t_ns: int,
    /,
) -> int: ...
