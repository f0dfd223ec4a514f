"""The Python API, as a notebook would use it: run a scenario twice, compare, open a log.

    .venv/bin/python examples/04_python_api.py [OUT_DIR]

Each ``# %%`` is a notebook cell (Jupyter, VS Code). Without OUT_DIR the kept log goes to a
temporary folder.
"""

# %% run the stick experiment at two fingertip frictions (Higashimori et al. 2007, Sec. II-C:
# collisions planned under eq. 12 come out the same whatever mu is); no file is written
from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

import replay

short = {"timing.duration": 0.5}  # s: past the first collision (t = 0.31 s)
runs = {
    mu: replay.run("stick_3step", set={**short, "plant.params.stick.friction": mu})
    for mu in (0.3, 1.0)
}
for mu, run in runs.items():
    print(f"mu = {mu}: {run.outcome['reason']} ({run.topics['/stick/state']} states)")

# %% compare a column: the stick's spin, one row a logged state (1 kHz)
low, high = (runs[mu].table("/stick/state") for mu in (0.3, 1.0))
assert np.array_equal(low["t"], high["t"])
after = low["t"] > 0.32  # after the first collision
print(
    f"omega after the first collision: {low['omega'][after][0]:+.4f} rad/s (mu = 0.3), "
    f"{high['omega'][after][0]:+.4f} rad/s (mu = 1.0)"
)
print(f"largest spin difference: {np.abs(low['omega'] - high['omega']).max():.2e} rad/s")

# %% events and vector fields: collisions from /events, fingertips as a (rows, 2, 2) array
events = runs[0.3].table("/events")
print("events:", ", ".join(f"{k} at {t:.3f} s" for k, t in zip(events["kind"], events["t"])))
tips = runs[0.3].table("/fingers/state")["tips"]
print(f"fingertips: {tips.shape[0]} rows of {tips.shape[1]} tips x (x, y)")


# %% keep a run's log, then open it again (as a colleague would): the same numbers
def keep_and_open(out_dir: Path) -> None:
    kept = replay.run("stick_3step", set=short, log=out_dir / "stick_3step.mcap")
    again = replay.open_log(kept.path)
    same = np.array_equal(again.table("/stick/state")["omega"], low["omega"])
    print(
        f"opened {again.path.name}: scenario {again.scenario['name']}, "
        f"seed {again.scenario['seed']}, same omega as the run in memory: {same}"
    )
    try:  # a DataFrame, with pandas (pip install 'paper-replay[frames]')
        print(again.df("/stick/state")[["t", "x", "y", "omega"]].tail(3).to_string())
    except ImportError as exc:
        print(exc)


if len(sys.argv) > 1:
    keep_and_open(Path(sys.argv[1]))
else:
    with tempfile.TemporaryDirectory() as tmp:
        keep_and_open(Path(tmp))
