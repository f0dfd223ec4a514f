"""The named input sets of ``replay evaluate`` (entry points ``paper_replay.input_sets``): each a
function ``(task, n) -> [episode]``, an episode a mapping ``{"seed": int, "set": ["key=value",
...], "input": str}`` whose ``set`` makes the task's scenario another physical input and whose
``input`` names that input (two episodes with the same ``input`` ran the same throw or path).

``held-out``: inputs none of the papers' methods was tuned on, from the sets the analysis
already judges them on:

- catch (``catch_optimised``): the shared set's perturbed 8-10 m/s throws
  (:func:`analysis.catching.throws.perturbed_throws` with its seed 20030914: the engine rates'
  and the ablations' base cell; the direct mapping was tuned on ``tuning_throws``, 8, 9, 10 m/s
  aimed at a 3 x 3 grid), released through ``plant.params.object_*``; the seed of episode ``i``
  is ``i`` (the stereo cameras' noise);
- grasp (``grasp_hexahedron``): the unseen human paths (:data:`analysis.engine_rates.GRASP_PATHS`,
  seeds 101-105, 211-225 at 0.05-0.3 m/s; the scenario's is seed 0 at 0.10 m/s): the seed draws
  the human's band-limited path, ``plant.params.human_speed`` its speed; at most 23 episodes;
- stick (``stick_3step``): the plant's seeded random throws (``plant.params.throw.random``: speed
  0.8-1.4 m/s, heading +-15 deg, spin 4-14 rad/s either way; docs/stick.md), seeds 0, 1, ...
  (the stick sweeps' throws; the paper shows one), 10 s a run as in those sweeps
  (sweeps/stick_conditions.yaml; a run stops 0.1 s after the capture). At 3.0 s two of the
  first ten ended undecided, the stick still turning slowly in reach; at 10 s all ten captured.
"""

from __future__ import annotations

from typing import Any

TASKS = ("catch", "grasp", "stick")
STICK_DURATION = 10.0  # s: the stick sweeps' (sweeps/stick_conditions.yaml)


def held_out(task: str, n: int) -> list[dict[str, Any]]:
    """The first ``n`` episodes of the held-out set of ``task`` (module docstring)."""
    if task not in TASKS:
        raise ValueError(f"no set for the task {task!r} (one of {', '.join(TASKS)})")
    return {"catch": _catch, "grasp": _grasp, "stick": _stick}[task](n)


def _catch(n: int) -> list[dict[str, Any]]:
    from analysis.catching.throws import perturbed_throws, throw_overrides

    return [
        {"seed": i, "set": throw_overrides(th), "input": f"throw {i} ({th['speed']:.2f} m/s)"}
        for i, th in enumerate(perturbed_throws(n))  # (its default seed: the shared set's)
    ]


def _grasp(n: int) -> list[dict[str, Any]]:
    from analysis.engine_rates import GRASP_PATHS

    if n > len(GRASP_PATHS):
        raise ValueError(f"grasp has {len(GRASP_PATHS)} human paths, asked for {n}")
    return [
        {
            "seed": seed,
            "set": [f"plant.params.human_speed={speed}"],
            "input": f"human path seed {seed}, {speed:g} m/s",
        }
        for seed, speed in GRASP_PATHS[:n]
    ]


def _stick(n: int) -> list[dict[str, Any]]:
    sets = ["plant.params.throw.random=true", f"timing.duration={STICK_DURATION}"]
    return [{"seed": s, "set": sets, "input": f"random throw seed {s}"} for s in range(n)]
