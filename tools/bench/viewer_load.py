"""``python -m tools.bench.viewer_load``: how long the viewer takes to open a 2-s, 1 kHz log.

Writes synthetic logs (air table; arm with hand and ball) of that size, then times reading
them into arrays (``load_run``) and the whole open (arrays, server start, scene, URDF, GUI,
plots) without a browser. It prints; it does not judge.
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from tests.synthetic_logs import write_arm_log, write_stick_log


def _best(fn, repeat: int) -> float:
    best = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=2.0)
    ap.add_argument("--rate", type=int, default=1000)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    from replay.log import LogReader
    from replay.viewer import Viewer, load_run

    with tempfile.TemporaryDirectory() as tmp:
        logs = {
            "air table": write_stick_log(
                Path(tmp) / "stick.mcap", duration=args.duration, rate=args.rate
            ),
            "arm": write_arm_log(Path(tmp) / "arm.mcap", duration=args.duration, rate=args.rate),
        }
        for kind, path in logs.items():
            n = sum(LogReader(path).topic_counts().values())
            size = path.stat().st_size / 1024
            load = _best(lambda path=path: load_run(path), args.repeat)

            def open_view(path=path):
                Viewer.open([path], port=0).stop()

            whole = _best(open_view, args.repeat)
            print(f"{kind}: {args.duration:g} s at {args.rate} Hz, {n} messages, {size:.0f} KiB")
            print(f"  log -> arrays (load_run):             {load:.3f} s")
            print(f"  open (arrays + server + scene + GUI): {whole:.3f} s")


if __name__ == "__main__":
    main()
