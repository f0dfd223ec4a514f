"""The ``replay`` executable: Ctrl-C at any moment exits 130 quietly, even while Python is still
importing the command line (numpy, PyBullet, ... take a while)."""

import os
import signal
import sys


def _while_importing(signum, frame) -> None:
    sys.stderr.write("interrupted\n")
    sys.stderr.flush()
    os._exit(130)  # nothing is written yet: nothing to keep


def main() -> None:
    signal.signal(signal.SIGINT, _while_importing)
    from replay.cli import main as cli

    signal.signal(signal.SIGINT, signal.default_int_handler)
    cli()


if __name__ == "__main__":
    main()
