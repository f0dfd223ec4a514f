"""Seeded random throws of the stick (``plant.params.throw``; our choice, the paper shows one
throw per strategy, Sec. IV-B). No simulator.

A throw: speed and heading (from straight at the palm, -y), spin magnitude with either sign at
equal odds, orientation uniform in [0, pi), and a pass point: the stick's centre would cross
y = ``pass_y`` (the paper's first collision at 0.12 m) at x in ``pass_x``, ``pass_time`` after
the start. The draws are made in that order from the plant's generator (the run's seed), so
``analysis.stick.throws.random_throw`` gives the same throws from the same generator.
"""

from __future__ import annotations

import math

import numpy as np

from plants.airtable.params import ThrowParams


def draw(rng: np.random.Generator, p: ThrowParams) -> dict[str, float]:
    """The initial state (x, y, theta, vx, vy, omega; m, rad, m/s, rad/s) of one throw."""

    def between(bounds: list[float]) -> float:
        return float(rng.uniform(bounds[0], bounds[1]))

    speed = between(p.speed)
    heading = between(p.heading)
    omega = between(p.spin) * float(rng.choice([-1.0, 1.0]))
    theta = float(rng.uniform(0.0, math.pi))
    x_pass = between(p.pass_x)
    t_pass = between(p.pass_time)
    vx, vy = speed * math.sin(heading), -speed * math.cos(heading)
    return {
        "x": x_pass - vx * t_pass,
        "y": p.pass_y - vy * t_pass,
        "theta": theta,
        "vx": vx,
        "vy": vy,
        "omega": omega,
    }
