"""``make bench``: speed of whole runs, reported as ratios measured in one run.

For each benchmarked scenario: the real-time factor of a full run (vision, controller and full
logging), the same number of bare simulator steps, and their ratio; the interpreter's start-up
and import time separately. Nothing here is a test: it prints, it does not judge.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from replay.runner import Runner
from replay.scenario import load_scenario

DEFAULT = ["scenarios/stick_3step.yaml", "scenarios/catch_optimised.yaml"]


def _bare_stepper(runner: Runner):
    """One bare simulator step of a fresh plant, with no runner, sensors, control or logging."""
    plant = type(runner.plant)(runner.sc.plant.params, dt=runner.dt, rng=runner.plant.rng)
    if hasattr(plant, "space"):                      # Pymunk
        space, dt = plant.space, plant.dt
        return lambda: space.step(dt)
    if hasattr(plant, "client"):                     # PyBullet
        import pybullet as p
        client = plant.client
        return lambda: p.stepSimulation(physicsClientId=client)
    return plant.step


def _startup(modules: list[str]) -> tuple[float, float]:
    def wall(code: str) -> float:
        best = float("inf")
        for _ in range(3):
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True)
            best = min(best, time.perf_counter() - t0)
        return best
    bare = wall("pass")
    return bare, wall("import " + ", ".join(modules)) - bare


def bench(path: str, repeat: int = 3) -> dict:
    sc = load_scenario(path)
    best, result = float("inf"), None
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            runner = Runner(sc)
            t0 = time.perf_counter()
            result = runner.run(Path(tmp) / f"run{i}.mcap")
            best = min(best, time.perf_counter() - t0)
    step = _bare_stepper(Runner(sc))
    bare = float("inf")
    for _ in range(repeat):
        t0 = time.perf_counter()
        for _ in range(result.steps):
            step()
        bare = min(bare, time.perf_counter() - t0)
    modules = sorted({type(runner.plant).__module__, type(runner.controller).__module__,
                      *(type(s).__module__ for _, s, _, _ in runner.sensors), "replay.runner"})
    optimiser = None
    problem = getattr(runner.controller, "problem", None)      # an offline optimisation (eq. 25)
    if problem is not None and hasattr(problem, "solve"):
        t0 = time.perf_counter()
        solved = problem.solve()
        optimiser = (time.perf_counter() - t0, len(solved.history) - 1)
    return {"optimiser": optimiser,"scenario": sc.name, "sim_time": result.t_end, "steps": result.steps,
            "messages": result.messages, "wall": best, "bare": bare,
            "rtf": result.t_end / best, "ratio": best / bare, "startup": _startup(modules)}


GRASP = "scenarios/grasp_hexahedron.yaml"


def bench_grasp(path: str = GRASP, repeat: int = 2) -> dict:
    """The grasping scenario (Namiki et al. 1999): CPU time of a full run (every task of Fig. 4,
    the vision chip, the wrist and hand-torque sensors, full logging) against bare
    ``stepSimulation`` calls, as many, on a fresh client holding the same bodies (arm, hand,
    object; the plant's Python servo and bookkeeping excluded). CPU time (``process_time``) so
    that other processes on the machine do not count; PyBullet runs in this process (DIRECT)."""
    sc = load_scenario(path)
    best = float("inf")
    with tempfile.TemporaryDirectory() as tmp:
        for i in range(repeat):
            runner = Runner(sc)
            c0 = time.process_time()
            result = runner.run(Path(tmp) / f"grasp{i}.mcap")
            best = min(best, time.process_time() - c0)
    plant = type(runner.plant)(sc.plant.params, dt=runner.dt, rng=runner.plant.rng)
    bc = plant.bc                                    # the plant's pybullet BulletClient
    bodies = bc.getNumBodies()
    bare = float("inf")
    for _ in range(repeat):
        c0 = time.process_time()
        for _ in range(result.steps):
            bc.stepSimulation()
        bare = min(bare, time.process_time() - c0)
    plant.close()
    return {"scenario": sc.name, "sim_time": result.t_end, "steps": result.steps,
            "messages": result.messages, "cpu": best, "bare": bare, "bodies": bodies,
            "rtf": result.t_end / best, "bare_rtf": result.t_end / bare, "ratio": best / bare}


def print_grasp(r: dict) -> None:
    print(f"{r['scenario']}: {r['sim_time']:.3f} s simulated, {r['steps']} physics steps, "
          f"{r['messages']} log messages (CPU time)")
    print(f"  full run (all tasks, vision chip, sensors, logging): {r['cpu']:.3f} s "
          f"= {r['rtf']:.2f}x real time")
    print(f"  bare stepSimulation, same {r['bodies']} bodies:         {r['bare']:.3f} s "
          f"= {r['bare_rtf']:.1f}x real time; full run / bare = {r['ratio']:.1f}x")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    args = ap.parse_args(argv)
    for path in args.scenarios:
        r = bench(path)
        py, imports = r["startup"]
        print(f"{r['scenario']}: {r['sim_time']:.3f} s simulated, {r['steps']} physics steps, "
              f"{r['messages']} log messages")
        print(f"  full run (vision + control + logging): {r['wall']:.3f} s wall "
              f"= {r['rtf']:.1f}x real time")
        print(f"  bare simulator steps:                  {r['bare']:.4f} s wall; "
              f"full run / bare = {r['ratio']:.1f}x")
        print(f"  not counted above: interpreter start-up {py:.3f} s, imports {imports:.3f} s")
        if r["optimiser"] is not None:
            wall, iterations = r["optimiser"]
            print(f"  offline optimisation from scratch: {wall:.2f} s wall, {iterations} "
                  "iterations (the runs read its result from a file)")
    if not args.scenarios or args.scenarios == DEFAULT:
        print_grasp(bench_grasp())


if __name__ == "__main__":
    main()
