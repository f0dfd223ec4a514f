"""Why PyBullet's step costs more inside a catch run than bare (not part of the suite).

Two measurements (CPU time, medians): (1) every ``stepSimulation`` of an unmodified run, grouped
by the number of object-robot contact points after it; (2) a fresh plant stepped bare (its
initial scene), once back to back and once with ~1 ms of plain Python and small NumPy work
between steps (what a run does between two engine steps: vision, control, logging), which
leaves the CPU caches cold for the engine.

    .venv/bin/python tools/arm_engine_probe.py [scenarios/catch_optimised.yaml]

Measured on this 2-core machine (catch_optimised, busy, 20:50 UTC): in the run 155 us a step
with no contact (268 steps), 250 us with the ball in the hand (3-4 contact points, 199 steps);
bare back to back 28 us, bare with ~1 ms of Python between steps 116 us. So the in-run cost is
cold caches after the run's Python (~4x) and the contacts (~1.6x more), not motor calls (they
are outside the engine's timer) nor the hand's velocity motors (stepping back to back with
the plant's motor calls set costs about the same as bare).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path
from tempfile import TemporaryDirectory

import numpy as np

from replay.runner import Runner
from replay.scenario import load_scenario


def _python_work() -> None:
    """~1 ms of what a run does between engine steps: interpreter loops, small arrays."""
    s = 0
    for i in range(20000):
        s += i
    x = np.zeros((128, 128))
    x[10:20, 10:20] = 1.0
    np.einsum("ij,ij->", x, x)


def main(path: str) -> None:
    sc = load_scenario(path)
    runner = Runner(sc)
    plant = runner.plant
    bc = plant.bc
    step = bc.stepSimulation  # the BulletClient's partial, bound once
    clock = time.process_time
    rows: dict[int, list[float]] = {}

    def timed() -> None:
        c0 = clock()
        step()
        dt = clock() - c0
        n = len(bc.getContactPoints(bodyA=plant.obj, bodyB=plant.robot)) if plant.obj else 0
        rows.setdefault(n, []).append(dt)

    bc.stepSimulation = timed
    with TemporaryDirectory() as tmp:
        result = runner.run(Path(tmp) / "probe.mcap")
    print(f"{sc.name} ({result.outcome.get('reason')}): engine step in the run, CPU us (median)")
    print("  contact points  steps  us")
    for n in sorted(rows):
        print(f"  {n:14d}  {len(rows[n]):5d}  {1e6 * statistics.median(rows[n]):6.1f}")
    for label, between in (("back to back", None), ("~1 ms of Python between", _python_work)):
        bare_plant = type(plant)(sc.plant.params, dt=runner.dt, rng=plant.rng)
        bare_step, ts = bare_plant.bc.stepSimulation, []
        for _ in range(200):
            if between:
                between()
            c0 = clock()
            bare_step()
            ts.append(clock() - c0)
        bare_plant.close()
        print(f"  bare (initial scene), {label}: {1e6 * statistics.median(ts):.1f} us")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scenarios/catch_optimised.yaml")
