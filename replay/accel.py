"""Optional compiled accelerators (setup.py builds them where a C compiler is found; a wheel
or checkout without them runs the pure-Python path, the same algorithm, which is the reference
their tests hold them to). ``REPLAY_NO_ACCEL=1`` runs the pure-Python path even where they are
built (CI runs the cameras' tests and the golden runs both ways: ``make test-pure``)."""

from __future__ import annotations

import importlib
import os
from types import ModuleType

DISABLED = os.environ.get("REPLAY_NO_ACCEL", "") not in ("", "0")


def accelerator(module: str) -> ModuleType | None:
    """The compiled module ``module``, or None when it is not built or accelerators are off."""
    if DISABLED:
        return None
    try:
        return importlib.import_module(module)
    except ImportError:
        return None
