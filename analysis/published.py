"""Whether a scenario will publish what its paper's figures and claims read (``replay validate``).

A plug-in declares what it reads (``Controller.reads``) but not what it publishes: a
controller's ``telemetry()`` and a plant's ``truth()`` say it only when they run. So the check
runs the scenario for :data:`TRIAL` simulated seconds (its log in a temporary folder) and
compares the topics it published with those its experiment (the shipped scenario it varies,
:func:`analysis.runs.describe`'s) publishes in the same time: a topic that a figure or claims
row reads (the ``TOPICS`` tables of the paper's figure and claims modules) and the experiment
publishes but the scenario does not is named, with what reads it. A scenario as shipped is not
tried (it is its own experiment).
"""

from __future__ import annotations

import dataclasses
import inspect
import tempfile
from functools import lru_cache
from pathlib import Path
from typing import Any

import yaml

from analysis import runs
from replay import registry

TRIAL = 0.05  # s simulated: every shipped controller publishes its topics from the first steps


def reads(paper: str) -> dict[str, tuple[str, ...]]:
    """What reads which topics in ``paper``'s analysis: ``Fig. 7`` -> topics, ``claims
    (group)`` -> topics (the figure and claims modules' ``TOPICS``); {} when none."""
    out: dict[str, tuple[str, ...]] = {}
    for kind in ("figures", "claims"):
        try:
            module = inspect.getmodule(registry.load(kind, paper))
        except registry.UnknownPlugin:
            continue
        table: Any = getattr(module, "TOPICS", None)
        if isinstance(table, dict):
            for what, topics in table.items():
                out[what if kind == "figures" else f"claims ({what})"] = tuple(topics)
        elif table:
            out["claims (every row)" if kind == "claims" else kind] = tuple(table)
    return out


def trial_topics(sc: Any) -> frozenset[str]:
    """The topics ``sc`` publishes in its first :data:`TRIAL` seconds (a fresh run)."""
    from replay.log import LogReader
    from replay.runner import Runner

    timing = dataclasses.replace(sc.timing, duration=min(sc.timing.duration, TRIAL))
    short = dataclasses.replace(sc, timing=timing)
    with tempfile.TemporaryDirectory(prefix="replay-trial-") as tmp:
        path = Path(tmp) / "trial.mcap"
        Runner(short).run(path)
        return frozenset(t for t, n in LogReader(path).topic_counts().items() if n)


@lru_cache(maxsize=None)
def _shipped_topics(name: str) -> frozenset[str]:
    from replay.resources import scenario_dir
    from replay.scenario import load_scenario

    return trial_topics(load_scenario(scenario_dir() / f"{name}.yaml"))


def unmet(sc: Any) -> str | None:
    """One line naming the topics ``sc`` will not publish that its experiment does and its
    paper's figures or claims read, with what reads each; None when there are none (or no
    shipped scenario of its paper to compare with). Runs ``sc`` briefly (:data:`TRIAL`)."""
    from replay.scenario import resolved_yaml

    table = reads(sc.paper)
    if not table:
        return None
    stored = runs._flat(yaml.safe_load(resolved_yaml(sc)))
    experiment, differences = runs._compare(stored, sc.name, sc.paper)
    if not experiment or (experiment == sc.name and not differences):
        return None  # (as shipped)
    needed = {t for topics in table.values() for t in topics}
    lacking = sorted((needed & _shipped_topics(experiment)) - trial_topics(sc))
    if not lacking:
        return None
    what = [w for w, topics in table.items() if set(topics) & set(lacking)]
    figures = [w for w in what if not w.startswith("claims")]
    rows = [w[len("claims (") : -1] for w in what if w.startswith("claims")]
    said = ([", ".join(figures)] if figures else []) + (
        [f"claims rows ({'; '.join(rows)})"] if rows else []
    )
    return (
        f"publishes no {', '.join(lacking)} ({experiment} does, in a {TRIAL:g} s trial run): "
        f"{sc.paper}'s {' and '.join(said)} will leave its runs out"
    )
