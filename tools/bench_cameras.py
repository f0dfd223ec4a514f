"""The cameras alone (not part of the suite): CPU time of each camera sensor's ``measure`` on the
very scenes it sees in a real run of a scenario.

One run of each scenario records every (t, scene) its camera sensors are given; then a fresh
sensor (same params, same seed) measures them all again, ``--repeats`` times, and the fastest
pass is reported: CPU us per frame (``time.process_time``, which other users of a shared machine
inflate far less than wall time) and CPU ms per simulated second at the camera's rate. Inside a
whole run the same frames cost more (caches shared with the engine and the controller):
``make bench`` shows that breakdown.

    .venv/bin/python tools/bench_cameras.py [SCENARIO ...]   (default: the three benchmarks)
"""

from __future__ import annotations

import argparse
import copy
import tempfile
import time
from pathlib import Path

import numpy as np

from replay.resources import scenario_dir
from replay.runner import Runner
from replay.scenario import load_scenario

CAMERAS = ("StickCamera", "StereoBallCamera", "VisionChipSensor")


def record(path: str) -> list[tuple[str, object, float, list]]:
    """(name, sensor, rate, frames) of each camera of one run of the scenario."""
    sc = load_scenario(path)
    runner = Runner(sc)
    out = []
    for name, sensor, _, _ in runner.sensors:
        if type(sensor).__name__ in CAMERAS:
            frames: list = []
            measure = sensor.measure

            def recorded(t, scene, measure=measure, frames=frames):
                frames.append((t, copy.deepcopy(scene)))
                return measure(t, scene)

            sensor.measure = recorded  # type: ignore[method-assign]
            out.append((name, sensor, float(sc.sensors[name].rate), frames))
    with tempfile.TemporaryDirectory() as tmp:
        runner.run(Path(tmp) / "run.mcap")
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument(
        "scenarios",
        nargs="*",
        default=[
            str(scenario_dir() / f"{n}.yaml")
            for n in ("stick_3step", "catch_optimised", "grasp_hexahedron")
        ],
    )
    ap.add_argument("--repeats", type=int, default=5)
    args = ap.parse_args()
    for path in args.scenarios:
        for name, sensor, rate, frames in record(path):
            best = float("inf")
            for _ in range(args.repeats):
                fresh = type(sensor)(sensor.params, rng=np.random.default_rng(0), spec=sensor.spec)
                c0 = time.process_time()
                for t, scene in frames:
                    fresh.measure(t, scene)
                best = min(best, (time.process_time() - c0) / max(len(frames), 1))
            print(
                f"{Path(path).stem} {name} ({type(sensor).__name__}): {len(frames)} frames, "
                f"{best * 1e6:.0f} us CPU a frame = {best * rate * 1e3:.0f} ms CPU per "
                f"simulated s at {rate:g} Hz"
            )


if __name__ == "__main__":
    main()
