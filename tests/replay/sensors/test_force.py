"""The grasping rig's force sensors publish the plant's readings (with their seeded noise)."""

import numpy as np

from replay.scene import Scene
from replay.sensors.force import HandTorqueParams, HandTorqueSensor, WristFTParams, WristFTSensor


def _scene(wrench, torque):
    return Scene(
        [],
        readings={
            "wrist": {"wrench": wrench},
            "hand_torque": {"name": ["a", "b", "c"], "torque": torque},
        },
    )


def test_exact_wrist_sensor_gives_the_readings_floats():
    wrench = [1.5, -2.0, 9.81, 0.01, -0.2, 0.0]
    m = WristFTSensor(WristFTParams(), rng=np.random.default_rng(0)).measure(
        0.1, _scene(wrench, [])
    )
    assert m.t == 0.1 and m.force == wrench[:3] and m.torque == wrench[3:]
    assert all(type(x) is float for x in m.force + m.torque)
    m = WristFTSensor(WristFTParams(), rng=np.random.default_rng(0)).measure(
        0.1, _scene(np.array(wrench), [])
    )
    assert m.force == wrench[:3] and all(type(x) is float for x in m.force + m.torque)


def test_noisy_force_sensors_add_their_seeded_noise_per_axis():
    """Seeded random readings: the reading plus sigma times the sensor's own normal draws (the
    same stream as a fresh generator of the seed), noise of the stated size over many draws."""
    rng = np.random.default_rng(4)
    params = WristFTParams(force_noise=0.05, torque_noise=0.005)
    wrist = WristFTSensor(params, rng=np.random.default_rng(12))
    hand = HandTorqueSensor(HandTorqueParams(noise=0.01), rng=np.random.default_rng(13))
    ref_w, ref_h = np.random.default_rng(12), np.random.default_rng(13)
    sigma = np.repeat([0.05, 0.005], 3)
    errs = []
    for k in range(300):
        w, tau = rng.normal(0.0, 5.0, 6), rng.normal(0.0, 0.5, 3)
        m = wrist.measure(k * 1e-3, _scene(w.tolist(), tau.tolist()))
        want = w + sigma * ref_w.standard_normal(6)
        np.testing.assert_array_equal(m.force + m.torque, want)
        h = hand.measure(k * 1e-3, _scene(w.tolist(), tau.tolist()))
        np.testing.assert_array_equal(h.torque, tau + 0.01 * ref_h.standard_normal(3))
        errs.append((np.array(m.force + m.torque) - w) / sigma)
    spread = np.std(errs, axis=0)
    print(f"wrist noise / sigma per axis: {np.round(spread, 2).tolist()}")
    assert np.all(np.abs(spread - 1.0) < 0.2)


def test_missing_readings_give_none():
    rng = np.random.default_rng(0)
    assert WristFTSensor(WristFTParams(), rng=rng).measure(0.0, Scene()) is None
    assert HandTorqueSensor(HandTorqueParams(), rng=rng).measure(0.0, Scene()) is None
