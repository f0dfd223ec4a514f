"""The bullet_arm plant's scenario-set impulse on the object (plants/arm_rig/impulse.py)."""

from __future__ import annotations

import numpy as np
import pytest

from plants.arm_rig.params import Params
from plants.arm_rig.rig import ArmRig
from plants.arm_rig.impulse import ImpulseSchedule

DT = 1e-3


def _plant(**kw):
    base = dict(
        hand="none",
        object="ball",
        object_gravity=False,
        object_mass=0.025,
        object_position=[1.5, 0.0, 1.0],
        object_velocity=[-2.0, 0.0, 0.0],
    )
    base.update(kw)
    return ArmRig(Params(**base), dt=DT, rng=np.random.default_rng(0))


def test_a_kick_changes_the_velocity_by_j_over_m_once_at_its_time():
    p = _plant(object_impulses=[[0.05, 0.0, 0.02, -0.01]])
    events, v_log = [], []
    for _ in range(100):
        p.step()
        events += p.pop_events()
        v_log.append(p.object_state()[2])
    p.close()
    kicks = [e for e in events if e.kind == "impulse"]
    assert len(kicks) == 1
    v = np.array(v_log)
    np.testing.assert_allclose(v[45], [-2.0, 0.0, 0.0], atol=1e-6)
    np.testing.assert_allclose(v[-1], [-2.0, 0.8, -0.4], atol=1e-6)  # J / m = (0, 0.8, -0.4)
    k = int(np.argmax(np.abs(v[:, 1]) > 0.1))
    assert k == 50  # the step at t = 0.05 s (steps 0..49 before it)
    np.testing.assert_allclose(kicks[0].data["impulse"], [0.0, 0.02, -0.01])


def test_no_impulse_no_change():
    p = _plant()
    for _ in range(50):
        p.step()
    np.testing.assert_allclose(p.object_state()[2], [-2.0, 0.0, 0.0], atol=1e-9)
    assert not [e for e in p.pop_events() if e.kind == "impulse"]
    p.close()


@pytest.mark.parametrize("entry", [[0.1, 1.0, 2.0], [-0.1, 0, 0, 0], [0.1, float("nan"), 0, 0]])
def test_bad_entries_are_refused(entry):
    with pytest.raises(ValueError, match="object_impulses"):
        ImpulseSchedule([entry], DT)
