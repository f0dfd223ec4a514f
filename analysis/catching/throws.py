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


def tuning_throws() -> list[dict]:
    """The throws every catching controller is tuned on: the direct mapping's optimisation set
    (controller.params of catch_optimised: 8, 9, 10 m/s at r_o(t0) aimed at the 3 x 3 grid of
    +-0.1 m around the catch point, lateral and vertical), as release states."""
    out = []
    for speed in (8.0, 9.0, 10.0):
        for dy in (-0.1, 0.0, 0.1):
            for dz in (-0.1, 0.0, 0.1):
                pos, vel = release(speed, (0.0, dy, dz))
                out.append(
                    {"speed": speed, "offset": (0.0, dy, dz), "position": pos, "velocity": vel}
                )
    return out


def perturbed_throws(
    n: int,
    seed: int = 20030914,
    spread: float = 0.0,
    speeds=(8.0, 10.0),
    tilt_deg: float = 1.0,
    jitter: float = 0.005,
) -> list[dict]:
    """Throws none of the controllers was tuned on (tests/analysis/test_catch_robustness.py's
    neighbourhood): speed at first sight U(speeds), r_o(t0) jittered by +-``jitter`` per axis,
    aimed at a point drawn in the +-``spread`` square around the catch point, then tilted by
    U(0, ``tilt_deg``) deg about the aim; released T0 before first sight."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        speed = rng.uniform(*speeds)
        r0 = THROW_START + rng.uniform(-jitter, jitter, 3)
        aim = CATCH_POINT + np.array(
            [0.0, *(rng.uniform(-spread, spread, 2) if spread > 0 else (0.0, 0.0))]
        )
        v0, _ = launch_velocity(r0, aim, speed, G)
        tilt, az = np.radians(rng.uniform(0.0, tilt_deg)), rng.uniform(0.0, 2 * np.pi)
        u = v0 / np.linalg.norm(v0)
        e1 = np.cross(u, [0.0, 0.0, 1.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(u, e1)
        v0 = speed * (np.cos(tilt) * u + np.sin(tilt) * (np.cos(az) * e1 + np.sin(az) * e2))
        out.append(
            {
                "speed": float(speed),
                "tilt_deg": float(np.degrees(tilt)),
                "position": (r0 - v0 * T0 + 0.5 * G * T0 * T0).tolist(),
                "velocity": (v0 - G * T0).tolist(),
            }
        )
    return out


def throw_overrides(throw: dict) -> list[str]:
    """``--set`` strings that make a catching scenario release ``throw``."""
    fmt = lambda v: "[" + ", ".join(f"{x:.6f}" for x in v) + "]"  # noqa: E731
    return [
        f"plant.params.object_position={fmt(throw['position'])}",
        f"plant.params.object_velocity={fmt(throw['velocity'])}",
    ]


if __name__ == "__main__":
    for s in (6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0):
        print(s, *release(s))
    for off in ((0, 0.05, 0), (0, -0.05, 0), (0, 0, 0.05), (0, 0, -0.05)):
        print(off, *release(9.0, off))
