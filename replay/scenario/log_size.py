"""A run's projected log size, from its scenario alone: the ``log_bytes`` limit is checked before
the plug-ins are built, so ``replay validate --static`` refuses what ``replay run`` would.

Uncompressed bytes (an upper bound: the log's zstd makes most of it smaller). Camera images
dominate: a sensor whose params say ``log_images`` writes ``images_per_frame`` (its class's, else
1) mono8 images of ``width x height`` bytes each capture. Everything else is budgeted from what
the shipped scenarios' logs hold (``data/golden``, at most ~1 KiB a message and ~7 KiB a
physics step of the grasping rig's ~15 topics), rounded up.
"""

from __future__ import annotations

from replay import registry
from replay.limits import check

MESSAGE_BYTES = 1024  # a sensor's own message (besides its images)
STEP_BYTES = 8192  # a logged physics step: the plant's state, the controller's telemetry
FRAME_BYTES = 4096  # a 3-D viewer frame: /tf, /scene, /joint_states


def projected_log_bytes(sc) -> tuple[float, str]:
    """(bytes, what dominates) of a run of ``sc`` to its ``timing.duration``; ``sc``'s plug-in
    params resolved (the loader's ``_resolve_plugins``)."""
    t = sc.timing
    total = biggest = t.duration * (
        (t.state_log_rate or t.physics_rate) * STEP_BYTES + t.frame_rate * FRAME_BYTES
    )
    what = "the plant's state"
    for name, s in sc.sensors.items():
        p = s.params
        images = 0
        if getattr(p, "log_images", False) and hasattr(p, "width") and hasattr(p, "height"):
            per = getattr(registry.load("sensor", s.type), "images_per_frame", 1)
            images = per * int(p.width) * int(p.height)
        size = t.duration * s.rate * (images + MESSAGE_BYTES)
        total += size
        if images and size > biggest:
            biggest = size
            what = f"sensors.{name}'s {p.width} x {p.height} images at {s.rate:g} Hz"
    return total, what


def check_log_size(sc) -> None:
    """Raise :class:`~replay.limits.LimitError` when a run of ``sc`` would write a log over the
    ``log_bytes`` limit."""
    size, what = projected_log_bytes(sc)
    check(
        "log_bytes",
        size,
        f"a {sc.timing.duration:g} s run's log ({what} dominate{'' if 'images' in what else 's'})",
    )
