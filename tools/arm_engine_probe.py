"""Why PyBullet's step costs more inside a catch run than bare (not part of the suite).

One unmodified run records every motor call the plant makes and the commands it is given, and
times each ``stepSimulation`` (CPU); the same calls are then replayed into fresh plants with one
thing added at a time. Rows: mean CPU us of the engine's step over the whole run, the flight
(before the first contact) and the hold (contact to the end), medians of a few replays.

    .venv/bin/python tools/arm_engine_probe.py [scenarios/catch_optimised.yaml]

Measured on this 2-core machine (catch_optimised, 470 steps, first contact at step 267; busy,
02:40 UTC, the bench's bare initial scene stepping in 20-28 us):

- in the run 82 us a step (46 in flight, 130 in the hold);
- the run's own motor calls replayed back to back, nothing else between: 59 (30 in flight, 97
  in the hold). So the hold is most of it: the ball resting in the closed hand on 3-4 contact
  points, each a multibody contact row with two friction rows through the solver's 50
  iterations (Bullet's setupMultiBodyContactConstraint, resolveSingleConstraintRowGeneric and
  resolveConeFrictionConstraintRows lead its profile). Bare stepping never has a contact;
- the motors cost ~4 us a step: with no motor call at all the flight steps in 25 (the arm's
  torques are joint forces, the hand's three velocity motors rows of the same solve);
- the rest is cold caches: the plant's own per-step Python between the steps adds ~3 us a step,
  the whole run ~23 (noisy: 10-45 over the session; ~1 ms of plain Python and NumPy between
  steps makes it 138). Each PyBullet state query (getJointStates, getLinkStates,
  getBasePositionAndOrientation, getBaseVelocity) copies PyBullet's whole ~30 KB actual-state
  block (SendActualStateSharedMemoryStorage; valgrind: ~30 k instructions of memcpy a query,
  ~35-55 k a query in all), so the plant reads each once a step and asks for contacts only
  while the ball is within the robot's reach (plants/bullet_arm/reach.py).

Solver settings, time step and physical parameters are the scenario's: not touched here.
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


def _row(label: str, us: list[float], touch: int) -> None:
    a = np.asarray(us)
    print(
        f"  {label:52s} {a.mean():6.1f} | {a[:touch].mean():6.1f} {a[touch:].mean():6.1f}"
        if touch < len(a)
        else f"  {label:52s} {a.mean():6.1f}"
    )


def main(path: str, reps: int = 5) -> None:
    sc = load_scenario(path)
    clock = time.process_time
    runner = Runner(sc)
    plant = runner.plant
    motor_calls: list[list] = []
    pending: list = []
    commands: dict[int, list] = {}
    run_us: list[float] = []
    touch = [None]
    set_motors, apply, step = plant.engine.set_motors, plant.apply, plant.engine.bc.stepSimulation

    def record_motors(*a, **kw):
        pending.append((a, kw))
        return set_motors(*a, **kw)

    def record_apply(command):
        commands.setdefault(plant._steps, []).append(command)
        apply(command)

    def timed_step():
        motor_calls.append(list(pending))
        pending.clear()
        c0 = clock()
        step()
        run_us.append(1e6 * (clock() - c0))
        if touch[0] is None and plant.engine.obj is not None:
            if plant.engine.bc.getContactPoints(bodyA=plant.engine.obj, bodyB=plant.engine.robot):
                touch[0] = len(run_us)

    plant.engine.set_motors, plant.apply, plant.engine.bc.stepSimulation = (
        record_motors,
        record_apply,
        timed_step,
    )
    with TemporaryDirectory() as tmp:
        result = runner.run(Path(tmp) / "probe.mcap")
    n, k = len(run_us), touch[0] or len(run_us)
    print(f"{sc.name} ({result.outcome.get('reason')}): {n} steps, first contact at step {k}")
    print(f"  engine step, CPU us (mean | flight, hold){'':20s}")
    _row("in the run", run_us, k)

    def replay(between=None, motors=True, plant_too=False) -> list[float]:
        rows = []
        for _ in range(reps):
            fresh = type(plant)(sc.plant.params, dt=runner.dt, rng=np.random.default_rng(0))
            st, sm, us = fresh.engine.bc.stepSimulation, fresh.engine.set_motors, []
            if plant_too:  # the plant's own per-step work around the engine's step

                def timed(st=st, us=us):
                    c0 = clock()
                    st()
                    us.append(1e6 * (clock() - c0))

                fresh.engine.bc.stepSimulation = timed
                for i in range(n):
                    for c in commands.get(i, ()):
                        fresh.apply(c)
                    fresh.scene()
                    fresh.truth(i * runner.dt)
                    if i % 10 == 0:
                        fresh.frames()
                    fresh.step()
                    fresh.pop_events()
            else:
                for i in range(n):
                    for a, kw in motor_calls[i] if motors else ():
                        sm(*a, **kw)
                    if between is not None:
                        between()
                    c0 = clock()
                    st()
                    us.append(1e6 * (clock() - c0))
            fresh.close()
            rows.append(us)
        return [statistics.median(x) for x in zip(*rows)]

    _row("the run's motor calls replayed back to back", replay(), k)
    _row("the same, no motor call at all (no catch: no hold)", replay(motors=False), k)
    _row("the run's commands through the plant (its Python)", replay(plant_too=True), k)
    _row("the run's motor calls, ~1 ms of Python between", replay(between=_python_work), k)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scenarios/catch_optimised.yaml")
