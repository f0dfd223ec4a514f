"""Random throws for the stick-capture strategies (Higashimori et al. 2007): capture rates.

The paper shows one throw per strategy (Sec. IV-B: 1.1 m/s, ~10 rad/s). This draws seeded random
throws in its neighbourhood, within the hand's reach, runs each through the full pipeline (Pymunk
air table, rendered 300 fps camera, the strategy) and reads the run's ``outcome`` event.

A throw (our choice; the paper gives no distribution) is the plant's seeded random throw
(``plant.params.throw.random``, ``plants.airtable.throw``; the sweeps use it through the run's
seed): speed 0.8-1.4 m/s, heading within +-15 deg of straight at the palm (-y), spin 4-14 rad/s
either way, orientation uniform, and a pass point: the stick's centre would cross y = 0.12 m
(the paper's first collision, Sec. IV-B) at x in +-0.06 m, 0.20-0.35 s after the start (the
start is then on the 300 fps camera's view).
``out_of_reach=True`` throws it across the table instead, along x at y = 0.50-0.58 m, where no
fingertip can get (slider +-0.2 m, finger reach 0.14 m: y <= 0.34 m).

    .venv/bin/python -m analysis.stick.throws --n 20 [--strategy stick_2step] [--seed 1] [-v]
"""

from __future__ import annotations

import argparse
import math
import tempfile
from collections import Counter
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plants.airtable.params import ThrowParams
from plants.airtable.throw import draw
from replay.resources import scenario_dir

SCENARIO = {
    "stick_2step": scenario_dir() / "stick_2step.yaml",
    "stick_3step": scenario_dir() / "stick_3step.yaml",
}
# s, per strategy: a run stops 0.1 s after the capture; the 3-step's clamped second contact
# leaves ~30 % of the spin and the spin-stop collision added then waits up to half a turn (~1 s)
DURATION = {"stick_2step": 2.0, "stick_3step": 3.0}


@dataclass(frozen=True)
class Throw:
    x: float
    y: float
    theta: float
    vx: float
    vy: float
    omega: float

    def sets(self) -> list[str]:
        return [
            f"plant.params.initial.{k}={float(getattr(self, k))!r}"
            for k in ("x", "y", "theta", "vx", "vy", "omega")
        ]


def random_throw(rng: np.random.Generator, out_of_reach: bool = False) -> Throw:
    """One throw of ``plants.airtable.throw.draw`` (the plant's ``throw.random``, default
    ranges), or with ``out_of_reach`` the same draws sent across the table."""
    if not out_of_reach:
        return Throw(**draw(rng, ThrowParams()))
    speed = rng.uniform(0.8, 1.4)  # the draws of ``draw`` in its order
    heading = math.radians(rng.uniform(-15.0, 15.0))
    omega = rng.uniform(4.0, 14.0) * rng.choice([-1.0, 1.0])
    theta = rng.uniform(0.0, math.pi)
    t_pass = rng.uniform(0.20, 0.35)  # across the table at y = 0.50-0.58 m, moving along +-x
    sign = float(rng.choice([-1.0, 1.0]))
    vx, vy = sign * speed * math.cos(heading), speed * math.sin(heading)
    return Throw(
        x=-vx * t_pass,
        y=rng.uniform(0.50, 0.58) - vy * t_pass,
        theta=theta,
        vx=vx,
        vy=vy,
        omega=omega,
    )


def run_throw(strategy: str, throw: Throw, out: Path, duration: float | None = None) -> dict:
    """The run's ``outcome`` event data (``duration`` default: ``DURATION[strategy]``)."""
    duration = DURATION[strategy] if duration is None else duration
    from replay.runner import Runner
    from replay.scenario import load_scenario

    sc = load_scenario(SCENARIO[strategy], sets=throw.sets() + [f"timing.duration={duration}"])
    return Runner(sc).run(out).outcome


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=20, help="throws per strategy")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--strategy", choices=sorted(SCENARIO), action="append")
    ap.add_argument(
        "--duration", type=float, help="s (default: 2.0 for the 2-step, 3.0 for the 3-step)"
    )
    ap.add_argument("--out-of-reach", action="store_true")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    strategies = a.strategy or sorted(SCENARIO)
    with tempfile.TemporaryDirectory() as tmp:
        for strategy in strategies:
            rng = np.random.default_rng(a.seed)
            reasons: Counter = Counter()
            ok = 0
            for i in range(a.n):
                throw = random_throw(rng, a.out_of_reach)
                o = run_throw(strategy, throw, Path(tmp) / f"{strategy}_{i}.mcap", a.duration)
                ok += bool(o["success"])
                reasons[o["reason"]] += 1
                if a.verbose or not o["success"]:
                    print(f"  {strategy} #{i}: {o['success']} {o['reason']!r}  {throw}")
            print(f"{strategy}: captured {ok} of {a.n}  reasons: {dict(reasons)}")


if __name__ == "__main__":
    main()
