"""What makes PyBullet's step cost more inside a grasp run than bare (not part of the suite).

One unmodified run records every call that changes the world (motor commands, the human's
constraint moves) and times each ``stepSimulation`` (CPU); the recorded calls are then replayed
into fresh plants, open loop and with nothing else between the steps, with one thing changed at
a time. Rows: mean CPU us a step, over the whole run and by phase (steps 0-300 and 300-700:
tracking, no contact; 700-1000: reach and grasp; 1000-2000: held while the human moves it).

    .venv/bin/python tools/grasp_engine_probe.py [scenarios/grasp_hexahedron.yaml]

Measured on this 2-core machine (grasp_hexahedron, busy, 23:50 UTC; the bare initial scene
steps in ~61 us):

- in the run: 630 us a step (320-430 before any contact, 750-770 grasping and holding; no contact
  point before step 700, 5-11 after); the same calls replayed back to back: 450 (310, 550). The
  difference (~1.4x) is cold caches after the run's Python, as for the catch
  (tools/arm_engine_probe.py);
- the motors are most of the rest: replayed without any motor call 79 us (59-97); the arm's 7
  torques alone 121; the hand's 14 velocity motors alone (implicit, 1 N m each, solved with the
  contacts) 226. The human's fixed constraint costs ~90 before contact and ~200 while grasping
  (replayed without it: 290); the object (its contacts and constraint) ~230 (removed: 214);
- collision detection alone (performCollisionDetection) is 30-45 us of it: the box is a PyBullet
  box already, the arm's cylinders are convex hulls (URDF cylinders load as meshes unless
  URDF_USE_IMPLICIT_CYLINDER, which would change the contact geometry) and the robot never
  collides with itself (no self-collision flag; test_the_robot_never_collides_with_itself), so
  no shape or pair filter has much to give;
- the solver's 50 iterations (the scenario's, unchanged): with 1, 10, 25 iterations the replayed
  run costs 130, 158, 233 us a step (50: 450). Fewer iterations are the only large gain, and
  they change the physics: measured here, not landed.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from tempfile import TemporaryDirectory

import numpy as np
import pybullet as p

from replay import registry
from replay.runner import Runner
from replay.scenario import load_scenario

PHASES = ((0, 300), (300, 700), (700, 1000), (1000, 2000))
RECORDED = ("setJointMotorControlArray", "changeConstraint", "resetBaseVelocity")


def _row(label: str, us: np.ndarray) -> None:
    parts = " ".join(f"{us[a:b].mean():6.1f}" for a, b in PHASES if a < len(us))
    print(f"{label:48s} {us.mean():6.1f} | {parts}")


def main(path: str) -> None:
    sc = load_scenario(path)
    clock = time.process_time
    runner = Runner(sc)
    bc, calls, times = runner.plant.engine.bc, [], []
    for name in RECORDED:
        call = getattr(bc, name)

        def record(*a, _name=name, _call=call, **k):
            calls.append((_name, a, k))
            return _call(*a, **k)

        setattr(bc, name, record)
    runner.plant.engine.set_motors = (
        bc.setJointMotorControlArray
    )  # the plant's bound one: recorded too
    step = bc.stepSimulation

    def timed() -> None:
        calls.append(None)
        c0 = clock()
        step()
        times.append(clock() - c0)

    bc.stepSimulation = timed
    with TemporaryDirectory() as tmp:
        runner.run(Path(tmp) / "probe.mcap")
    print("mean CPU us a step: whole run | by phase " + " ".join(f"{a}-{b}" for a, b in PHASES))
    _row("in the run", np.array(times) * 1e6)
    cls = registry.load("plant", sc.plant.type)

    def replay(label, setup=lambda plant: None, skip=(), keep=lambda name, a: True) -> None:
        plant = cls(sc.plant.params, dt=1.0 / sc.timing.physics_rate, rng=np.random.default_rng(0))
        setup(plant)
        cid, us = plant.engine.bc._client, []
        for item in calls:
            if item is None:
                c0 = clock()
                p.stepSimulation(physicsClientId=cid)
                us.append(clock() - c0)
            elif item[0] not in skip and keep(item[0], item[1]):
                getattr(p, item[0])(*item[1], physicsClientId=cid, **item[2])
        plant.close()
        _row(label, np.array(us) * 1e6)

    arm = tuple(runner.plant.engine.arm_j)

    def is_arm(name, a):
        return name != "setJointMotorControlArray" or tuple(a[1]) == arm

    replay("replayed back to back")
    replay(
        "replayed, human constraint removed",
        lambda plant: plant.engine.bc.removeConstraint(plant.human.cid),
        skip=("changeConstraint",),
    )
    replay(
        "replayed, object removed",
        lambda plant: plant.engine.bc.removeBody(plant.engine.obj),
        skip=("changeConstraint", "resetBaseVelocity"),
    )
    replay("replayed, no motor calls", skip=("setJointMotorControlArray",))
    replay("replayed, arm torques only", keep=is_arm)
    replay(
        "replayed, hand motors only",
        keep=lambda name, a: name != "setJointMotorControlArray" or tuple(a[1]) != arm,
    )
    for it in (1, 10, 25):
        replay(
            f"replayed, numSolverIterations={it} (not landed)",
            lambda plant, it=it: plant.engine.bc.setPhysicsEngineParameter(numSolverIterations=it),
        )


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "scenarios/grasp_hexahedron.yaml")
