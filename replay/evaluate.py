"""``replay evaluate``: a policy and the paper's method on the same inputs of a task, each
episode judged by the physics verdict; success rates with Wilson 95 % intervals.

The inputs are a named input set (``--set-of``, default ``held-out``): plug-ins of the entry
point group ``paper_replay.input_sets`` (:mod:`replay.registry`), each ``make(task, n)`` -> the
set's first ``n`` episodes, an episode ``{"seed", "set", "input"}``: the run's seed, the
``--set`` strings that make it another physical input (a throw, a human path), applied through
``reset(options={"set": ...})``, and that input's name (``analysis/input_sets.py``).

A policy is named by an import path ``module:object`` (a module beside the current directory
is found; an installed one of the same name wins): ``object(env)`` returns the episode's
``act(observation, info) -> action``, made once for all episodes; an ``act.reset_options``
mapping is passed to ``reset``. ``paper`` names the paper's method
(:class:`replay.envs.policies.PaperPolicy`). Gymnasium (``paper-replay[envs]``) is imported
only when the command runs, not by every ``replay`` command.
"""

from __future__ import annotations

import importlib
import os
import sys
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import click

from replay.console import fail, say
from replay.registry import IMPORT_PATH
from replay.scenario.yamlio import show

PAPER = "paper"


class PolicyError(ValueError):
    """A policy that cannot be found or made: one line."""


class InputSetError(ValueError):
    """An input set that is not installed or gives no usable episodes: one line."""


@dataclass(frozen=True)
class Episode:
    """One input of a set: its ``number`` in the set, the run's ``seed``, the overrides
    (``set``) that make it that physical input and the input's name (``input``)."""

    number: int
    seed: int
    set: tuple[str, ...] = ()
    input: str = ""


DEFAULT_SET = "held-out"
MAX_OVERRIDES = 64  # an episode's --set strings (a plug-in's data: bounded)


def input_set(name: str, task: str, n: int, first: int = 0) -> list[Episode]:
    """Episodes ``first`` .. ``first + n - 1`` of the input set ``name`` for ``task``."""
    from replay import registry

    known = registry.names("input_sets")
    if name not in known:
        raise InputSetError(
            f"unknown input set {show(name, 40)} (known: {', '.join(known) or 'none installed'})"
        )
    try:
        raw = registry.load("input_sets", name)(task, first + n)
    except Exception as exc:  # noqa: BLE001 - the plug-in's own code failed: one line
        raise InputSetError(f"input set {name!r}: {str(exc)[:200]}") from None
    if not isinstance(raw, list) or len(raw) < first + n:
        raise InputSetError(f"input set {name!r} gave fewer than {first + n} episodes for {task}")
    return [_episode(name, k, raw[k]) for k in range(first, first + n)]


def _episode(name: str, k: int, raw: Any) -> Episode:
    """Episode ``k`` of the set ``name`` checked: a mapping of an int seed, str overrides."""
    seed = raw.get("seed") if isinstance(raw, dict) else None
    sets = raw.get("set", []) if isinstance(raw, dict) else None
    if (
        not isinstance(seed, int)
        or isinstance(seed, bool)
        or not 0 <= seed < 2**31
        or not isinstance(sets, list)
        or len(sets) > MAX_OVERRIDES
        or not all(isinstance(x, str) for x in sets)
    ):
        raise InputSetError(
            f"input set {name!r}: episode {k} is not {{'seed': 0 <= int < 2**31, 'set': [str],"
            " 'input': str}"
        )
    return Episode(k, seed, tuple(sets), str(raw.get("input", f"seed {seed}"))[:200])


@dataclass
class Tally:
    """A policy's episodes on a task: successes of n, failures by reason, seconds simulated."""

    name: str
    wins: int = 0
    n: int = 0
    reasons: Counter = field(default_factory=Counter)

    def interval(self) -> tuple[float, float]:
        from replay.sweep.results import wilson

        return wilson(self.wins, self.n)

    def line(self) -> str:
        lo, hi = self.interval()
        rate = self.wins / self.n if self.n else 0.0
        return (
            f"{self.name[:48]:48s} {self.wins:4d}/{self.n:<4d} {100 * rate:5.1f} %"
            f"  [{100 * lo:5.1f}, {100 * hi:5.1f}] %"
        )


def load_policy(name: str) -> Callable[[Any], Any]:
    """The factory ``module:object`` names (or the paper's method's for ``paper``)."""
    if name == PAPER:
        from replay.envs.policies import paper

        return paper
    import re

    if not re.fullmatch(IMPORT_PATH, name):
        raise PolicyError(f"bad policy {show(name, 100)} (expected module:object or {PAPER})")
    module_name, _, attr = name.partition(":")
    here = os.getcwd()
    if here not in sys.path:
        sys.path.append(here)  # (at the end: installed modules win)
    try:
        obj: Any = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        raise PolicyError(
            f"no module {module_name!r} for the policy {name!r}: {exc.name!r} missing"
        ) from None
    except Exception as exc:  # noqa: BLE001 - the module's own code failed: one line
        raise PolicyError(f"importing the policy's module {module_name!r} failed: {exc}") from None
    for part in attr.split("."):
        if not hasattr(obj, part):
            raise PolicyError(f"module {module_name!r} has no {attr!r}")
        obj = getattr(obj, part)
    if not callable(obj):
        raise PolicyError(f"policy {name!r} is not callable (expected a factory: env -> act)")
    return obj


def episode(env: Any, act: Any, ep: Episode, sets: list[str]) -> dict:
    """One episode of ``act`` on input ``ep`` (its overrides, then ``sets``): the outcome the
    run logged."""
    options = {**(getattr(act, "reset_options", None) or {}), "set": [*ep.set, *sets]}
    obs, info = env.reset(seed=ep.seed, options=options)
    while True:
        obs, _, terminated, truncated, info = env.step(act(obs, info))
        if terminated or truncated:
            return info["outcome"]


def evaluate(
    policy: str,
    task: str,
    episodes: list[Episode],
    *,
    sets: list[str] | None = None,
    logs: Path | None = None,
    progress: Callable[[str, Episode, dict], None] | None = None,
) -> list[Tally]:
    """``policy`` and the paper's method on ``task`` (``catch``, ``grasp``, ``stick``) for each
    episode (its overrides, then ``sets``, which win); with ``logs`` each episode's MCAP log as
    ``LOGS/POLICY-NUMBER.mcap``."""
    from replay.envs import TASKS
    from replay.envs.env import ScenarioEnv

    if task not in TASKS:
        raise PolicyError(f"unknown task {show(task, 40)} (one of {', '.join(sorted(TASKS))})")
    scenario = TASKS[task][1]
    extra = list(sets or [])
    tallies = []
    names = [policy] if policy == PAPER else [policy, PAPER]
    for name in names:
        factory = load_policy(name)
        label = "paper" if name == PAPER else name.replace(":", "-")
        env = ScenarioEnv(scenario, set=extra)
        try:
            act = factory(env)
            tally = Tally(f"{name} (the paper's method)" if name == PAPER else name)
            for ep in episodes:
                env.log = str(logs / f"{label}-{ep.number}.mcap") if logs is not None else None
                outcome = episode(env, act, ep, extra)
                tally.n += 1
                if outcome.get("success"):
                    tally.wins += 1
                else:
                    tally.reasons[str(outcome.get("reason", "?"))] += 1
                if progress:
                    progress(name, ep, outcome)
        finally:
            env.close()
        tallies.append(tally)
    return tallies


@click.command("evaluate")
@click.argument("policy")
@click.option(
    "--task", type=click.Choice(["catch", "grasp", "stick"]), required=True, help="the paper's task"
)
@click.option(
    "--n",
    "n",
    type=click.IntRange(1, 10_000),
    default=10,
    show_default=True,
    help="episodes: the input set's FIRST .. FIRST+N-1",
)
@click.option(
    "--first",
    type=click.IntRange(0, 100_000),
    default=0,
    show_default=True,
    help="the first episode's number in the input set",
)
@click.option(
    "--set-of",
    "set_of",
    default=DEFAULT_SET,
    show_default=True,
    metavar="NAME",
    help="the named input set (throws, human paths) the episodes take",
)
@click.option(
    "--set",
    "sets",
    multiple=True,
    metavar="KEY.PATH=VALUE",
    help="override the task's scenario, as replay run --set (after the input set's)",
)
@click.option("--logs", type=click.Path(file_okay=False), help="keep each episode's log here")
def evaluate_command(policy, task, n, first, set_of, sets, logs):
    """Success rate of POLICY (module:object, a factory env -> act(obs, info) -> action; or
    `paper`) on a paper's task, with a Wilson 95 % interval, beside the paper's method on the
    same inputs of a named set (docs/envs.md)."""
    try:
        import gymnasium  # noqa: F401
    except ImportError:
        fail("replay evaluate needs Gymnasium: pip install 'paper-replay[envs]'")
    from replay.log import LogError
    from replay.scenario import ScenarioError

    try:
        episodes = input_set(set_of, task, n, first)
    except InputSetError as exc:
        fail(str(exc))
    out = Path(logs) if logs else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    try:
        tallies = evaluate(policy, task, episodes, sets=list(sets), logs=out)
    except (PolicyError, ScenarioError, LogError) as exc:
        fail(str(exc))
    except (ValueError, TypeError) as exc:  # a policy's action the plant cannot take
        fail(f"policy {policy}: {exc}")
    inputs = len({ep.input for ep in episodes})
    say(
        f"task {task}: input set {set_of}, episodes {first}..{first + n - 1}: {inputs} distinct"
        f" physical input{'s' if inputs != 1 else ''}, success by the physics verdict"
    )
    say(f"{'policy':48s} {'success':>9s} {'rate':>7s}  Wilson 95 %")
    for tally in tallies:
        say(tally.line())
        for reason, count in tally.reasons.most_common(3):
            say(f"    {count} x {reason[:100]}")
