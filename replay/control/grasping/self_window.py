"""Self Windowing (Ishii, Nakabo & Ishikawa 1996, ref. [5] of Namiki et al. 1999): target
tracking on a binary vision chip, pure NumPy.

    W_k = dilate_4(T_{k-1})          the previous target image grown by one pixel (4-neighbours)
    T_k = W_k AND I_k                the new binary image inside that window

A target that moves by at most one pixel a frame stays whole: every pixel of its new image
touches (4-neighbourhood) a pixel of its old one. Moving by s > 1 pixels a frame along an axis,
only the part of the new image within one pixel of the old target survives: the target loses
s - 1 pixels a frame on its leading side... and the window then follows only what is left, so the
target shrinks every frame and is lost after about ``width / (s - 1)`` frames (measured in
tests/replay/control/grasping/test_grasping_vision.py and stated in docs/grasping.md). At 1 kHz that bound is what
makes the algorithm work: 1 pixel a millisecond is fast (here ~13 mrad/ms, 10 m/s at 0.8 m).

When the window holds nothing (the target lost, or the first frame), the whole image is the
window: the algorithm re-acquires whatever is bright.

:func:`track_rows` runs it on the chip's packed rows (``rows[v]`` an int whose bit ``u`` is
pixel (u, v), as ``/vision/chip`` carries them): a row's dilation is a few shifts and ORs, like
the PEs' neighbour exchange. (The same in NumPy arrays, as the equations above read, is the
tests' oracle: tests/replay/control/grasping/oracles.py.)
"""

from __future__ import annotations


def track_rows(previous: list[int] | None, rows: list[int], width: int) -> tuple[list[int], bool]:
    """(target rows, reacquired): Self Windowing on packed rows (bit u of ``rows[v]`` = pixel
    (u, v)), or the whole image when there is no previous target (``reacquired`` then True)."""
    if not previous or not any(previous):
        return list(rows), True
    mask = (1 << width) - 1
    above, below = [0, *previous[:-1]], [*previous[1:], 0]
    return [
        (p | p << 1 | p >> 1 | a | b) & mask & r for p, a, b, r in zip(previous, above, below, rows)
    ], False
