"""Target trajectories for the offline optimisation of eq. 25 (the paper gives no set: ours).

"Parameters ... were optimized using all possible target trajectories in the neighborhood of the
catching point" (Sec. IV-B); throws were "about 8 ~ 10 m/s". Our set: ballistic throws under
gravity from one release point (the nominal start of tracking, t0) to arrival points on a
``grid x grid`` lattice of half-width ``spread`` around the catching point, in the plane normal to
the horizontal throw direction, each projected onto the catch surface |r - O| = |c| (where q4 =
q_alpha, so the catch happens exactly at the end of the sampled trajectory), at each launch speed.
Every throw is sampled at ``n_samples`` equally spaced instants from t0 to arrival.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def launch_velocity(start, end, speed: float, gravity) -> tuple[np.ndarray, float]:
    """The flatter ballistic launch from ``start`` through ``end`` at launch speed ``speed``.

    |d/T - g T/2|^2 = v^2 gives |g|^2 T^4 / 4 - (v^2 + d.g) T^2 + |d|^2 = 0; the smaller root.
    Returns (v0, flight time T).
    """
    d = np.asarray(end, float) - np.asarray(start, float)
    g = np.asarray(gravity, float)
    gg = float(g @ g)
    b = speed * speed + float(d @ g)
    disc = b * b - gg * float(d @ d)
    if disc < 0.0 or b <= 0.0:
        raise ValueError(f"{speed} m/s cannot reach {end} from {start}")
    if gg == 0.0:
        T2 = float(d @ d) / speed**2
    else:
        T2 = (b - np.sqrt(disc)) / (0.5 * gg)
    T = float(np.sqrt(T2))
    return d / T - 0.5 * g * T, T


@dataclass
class Throw:
    t: np.ndarray  # (n,) s since t0
    r: np.ndarray  # (n, 3)
    rd: np.ndarray  # (n, 3)
    rdd: np.ndarray  # (n, 3)
    speed: float
    arrival: np.ndarray


def sample_throw(start, v0, T: float, n: int, gravity, speed: float = 0.0) -> Throw:
    t = np.linspace(0.0, T, n)
    g = np.asarray(gravity, float)
    r = np.asarray(start, float) + np.outer(t, v0) + 0.5 * np.outer(t * t, g)
    rd = np.asarray(v0, float) + np.outer(t, g)
    return Throw(t, r, rd, np.tile(g, (n, 1)), speed, r[-1].copy())


@dataclass
class ThrowSet:
    throws: list[Throw]
    nominal: int  # index of the nominal throw (centre arrival, middle speed)

    def stacked(self):
        """(r, rd, rdd) of every sample of every throw, (N, 3) each."""
        return (
            np.vstack([th.r for th in self.throws]),
            np.vstack([th.rd for th in self.throws]),
            np.vstack([th.rdd for th in self.throws]),
        )


def throw_set(
    start,
    catch_point,
    origin,
    catch_radius: float,
    speeds=(8.0, 9.0, 10.0),
    spread: float = 0.1,
    grid: int = 3,
    n_samples: int = 20,
    gravity=(0.0, 0.0, -9.81),
) -> ThrowSet:
    start, cp, origin = (np.asarray(x, float) for x in (start, catch_point, origin))
    horiz = cp - start
    horiz[2] = 0.0
    lateral = np.cross([0.0, 0.0, 1.0], horiz)
    nl = np.linalg.norm(lateral)
    lateral = lateral / nl if nl > 0 else np.array([0.0, 1.0, 0.0])
    ticks = np.linspace(-spread, spread, grid) if grid > 1 else np.zeros(1)
    speeds = list(speeds)
    throws: list[Throw] = []
    nominal = 0
    for v in speeds:
        for dy in ticks:
            for dz in ticks:
                a = cp + dy * lateral + np.array([0.0, 0.0, dz]) - origin
                arrival = origin + catch_radius * a / np.linalg.norm(a)
                v0, T = launch_velocity(start, arrival, v, gravity)
                if (
                    dy == ticks[len(ticks) // 2]
                    and dz == ticks[len(ticks) // 2]
                    and v == speeds[len(speeds) // 2]
                ):
                    nominal = len(throws)
                throws.append(sample_throw(start, v0, T, n_samples, gravity, v))
    return ThrowSet(throws, nominal)
