"""The throws of the catching ablations: release point and velocity for a speed and arrival offset.

As scenarios/catch_optimised.yaml derives its nominal throw: the ball passes r_o(t0) =
(2.34, 0, 0.90) m (where both stereo images first see it whole) at t0 = 0.1 s with the launch
velocity that reaches the catch point l([0, pi/4, 0, pi/2]) = (0.72090, 0, 0.46656) m (plus an
``offset``) at ``speed``; released 0.1 s earlier. The sweep files under sweeps/ carry the numbers
(tests/replay/sweep/test_sweep_files.py re-derives them).
"""

from __future__ import annotations

import numpy as np

from replay.control.catching.trajectories import launch_velocity

THROW_START = np.array([2.34, 0.0, 0.90])  # m, r_o(t0)
CATCH_POINT = np.array([0.72090, 0.0, 0.46656])  # m
T0 = 0.1  # s
G = np.array([0.0, 0.0, -9.81])


def release(speed: float, offset=(0.0, 0.0, 0.0)) -> tuple[list, list]:
    """(object_position, object_velocity) at t = 0, rounded to 10 um and 10 um/s."""
    v0, _ = launch_velocity(THROW_START, CATCH_POINT + np.asarray(offset, float), speed, G)
    pos = THROW_START - v0 * T0 + 0.5 * G * T0 * T0
    vel = v0 - G * T0
    return [round(float(x), 5) for x in pos], [round(float(x), 5) for x in vel]


if __name__ == "__main__":
    for s in (6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0):
        print(s, *release(s))
    for off in ((0, 0.05, 0), (0, -0.05, 0), (0, 0, 0.05), (0, 0, -0.05)):
        print(off, *release(9.0, off))
