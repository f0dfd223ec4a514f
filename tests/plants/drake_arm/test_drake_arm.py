"""The Drake adapter (plants/drake_arm) on its own: a fast ball stopped by the palm with point and
hydroelastic contact, its bounce off the palm the documented one, two runs bit-identical. The
checks every engine passes (inverse dynamics against our RNEA, the ballistic ball, the wrist's
static loads, the servos' step test, a grasp held still, the scenarios differing from their
PyBullet twins only in the engine field) are tests/plants/mujoco_arm/test_cross_engine.py's."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from grasp_rig import DT

from arm_checks import hold_torque
from plants.arm_rig.params import Params
from plants.arm_rig.rig import ArmRig
from replay.robot.arm_types import ArmCommand

ROOT = Path(__file__).resolve().parents[3]
START = [0.0, math.pi / 4, 0.0, 0.0]  # Namiki & Ishikawa IV-A
CATCHING = dict(initial_q=START, locked_joints=["J3"])


def make(**kw) -> ArmRig:
    """The arm rig in Drake; ``dk_*`` keywords are Drake's settings, the rest the rig's."""
    engine = {k: kw.pop(k) for k in list(kw) if k.startswith("dk_")}
    params = Params(**kw, engine={"type": "drake", **engine})
    return ArmRig(params, dt=DT, rng=np.random.default_rng(0))


@pytest.mark.parametrize("model", ["point", "hydroelastic"])
def test_fast_ball_is_stopped_by_the_palm(model):
    """A 9 m/s ball thrown at the palm's face: a contact event on the palm (a point contact's or
    a hydroelastic patch's row), the ball turned back (its speed along the face normal reversed
    or stopped), never through the palm."""
    plant = make(**CATCHING)
    spec = plant.spec()
    T = spec.model.fk(np.asarray(START))
    n = T[:3, 2]
    face = T[:3, 3] + n * spec.hand.table.palm_thickness
    r0 = face + n * 0.1
    plant = make(
        object_position=r0.tolist(), object_velocity=(-9.0 * n).tolist(),
        dk_contact_model=model, **CATCHING,
    )  # fmt: skip
    contact = None
    for _ in range(60):
        plant.apply(ArmCommand(hold_torque(plant, START)))
        plant.step()
        for e in plant.pop_events():
            if e.kind == "contact" and contact is None:
                contact = e.data
    pos, _, v, _ = plant.object_state()
    assert contact is not None and "palm" in contact["parts"]
    assert contact["normal_speed"] > 5.0  # the normal points from the palm towards the ball
    assert float(v @ n) >= -0.5  # stopped or bounced back
    assert float((pos - face) @ n) > 0.0  # the ball's centre never passed the face


def test_deterministic():
    """Two Drake plants from the same params step to bit-identical states."""

    def run():
        plant = make(object_position=[1.0, 0.0, 0.6], object_velocity=[-4.0, 0.0, 0.0], **CATCHING)
        for _ in range(200):
            plant.apply(ArmCommand(hold_torque(plant, START)))
            plant.step()
        return [a.tolist() for a in plant.object_state()] + [plant.arm_state()[0].tolist()]

    assert run() == run()


def bounce(speed: float, **kw) -> float:
    """The ball's speed back off the held arm's palm over its speed in (no gravity on it)."""
    probe = make(**CATCHING)
    spec = probe.spec()
    T = spec.model.fk(np.asarray(START))
    n = T[:3, 2]
    r0 = T[:3, 3] + n * (spec.hand.table.palm_thickness + 0.0175 + 0.01)
    plant = make(
        object_position=r0.tolist(), object_velocity=(-speed * n).tolist(),
        object_gravity=False, **CATCHING, **kw,
    )  # fmt: skip
    for _ in range(60):
        plant.apply(ArmCommand(hold_torque(plant, START)))
        plant.step()
    return float(plant.object_state()[2] @ n) / speed


def test_bounce_off_the_palm_is_the_documented_one():
    """plants/drake_arm/params.py's dk_dissipation: 0.08 of the speed back at 1.3 m/s, 0.02 at
    6 m/s (Hunt-Crossley's bounce falls with the speed), 0.22 at both without dissipation."""
    assert bounce(1.3) == pytest.approx(0.08, abs=0.01)
    assert bounce(6.0) == pytest.approx(0.02, abs=0.01)
    assert bounce(1.3, dk_dissipation=0.0) == pytest.approx(0.22, abs=0.02)
    assert bounce(6.0, dk_dissipation=0.0) == pytest.approx(0.22, abs=0.02)
