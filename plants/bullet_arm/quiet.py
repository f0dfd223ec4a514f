"""PyBullet's C code prints to the process's stdout/stderr (a build banner at import, "argv[0]="
at connect): keep that off the command line's output."""

from __future__ import annotations

import os
import sys
from contextlib import contextmanager


@contextmanager
def quiet_c_output():
    """Send what C code writes to file descriptors 1 and 2 to /dev/null meanwhile."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        for fd, copy in zip((1, 2), saved):
            os.dup2(copy, fd)
            os.close(copy)
        os.close(devnull)
