"""Variants: one resolved scenario each, keyed by the hash of (resolved scenario, seed, code version).

The key is what makes a sweep resumable: a variant whose key is already in the table is done (a
rerun skips it, an interrupted sweep picks up the rest); change the scenario, the seed or the code
and the key changes. A variant whose scenario does not load (a value out of range, an unknown plug-in
parameter) is still a variant: it becomes a row with that reason, keyed by what was asked.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Iterator

from replay.scenario import ScenarioError, load_scenario, resolved_yaml
from replay.scenario.loader import file_dirs
from replay.sweep.spec import SweepSpec, sets_for
from replay.version import code_version


@dataclass
class Variant:
    index: int
    key: str  # 16 hex digits
    params: dict[str, str]  # axis -> the table's cell
    scenario_path: str
    sets: list[str]
    seed: int
    resolved: str = ""  # the resolved YAML ("" when it failed to load)
    error: str = ""  # why it failed to load
    name: str = ""  # the scenario's name
    version: str = ""  # the code version it is keyed by (the table's version column)
    # where each plug-in's *_file parameters resolve (loader.file_dirs): not in the resolved text
    file_dirs: dict[str, str] = field(default_factory=dict)
    extra: dict[str, Any] = field(default_factory=dict)


def variant_key(resolved: str, seed: int, version: str) -> str:
    h = hashlib.sha256()
    for part in (resolved, str(seed), version):
        h.update(part.encode())
        h.update(b"\0")
    return h.hexdigest()[:16]


def expand(
    scenario: str | Path,
    spec: SweepSpec,
    seed: int,
    *,
    sets: list[str] | tuple = (),
    version: str | None = None,
) -> list[Variant]:
    """The sweep's variants, each loaded and validated (or carrying why it cannot be); their
    count checked against the ``sweep_variants`` limit first (SweepSpecError)."""
    spec.check_count()
    return list(plan(scenario, spec, seed, sets=sets, version=version))


def plan(
    scenario: str | Path,
    spec: SweepSpec,
    seed: int,
    *,
    sets: list[str] | tuple = (),
    version: str | None = None,
) -> Iterator[Variant]:
    """:func:`expand`'s variants one at a time (a scenario loads in ~10 ms), unchecked."""
    version = code_version() if version is None else version
    for i, point in enumerate(spec.iter_points(seed)):
        path, point_seed, point_sets = sets_for(point)
        path = str(path or scenario)
        all_sets = list(sets) + point_sets
        vseed = seed if point_seed is None else point_seed
        cells = {k: spec.label(k, v) for k, v in point.items()}
        v = Variant(
            index=i,
            key="",
            params=cells,
            scenario_path=path,
            sets=all_sets,
            seed=vseed,
            version=version,
        )
        try:
            sc = load_scenario(path, sets=all_sets, seed=vseed)
            v.resolved = resolved_yaml(sc)
            v.file_dirs = file_dirs(sc)
            v.name = sc.name
            v.key = variant_key(v.resolved, vseed, version)
        except ScenarioError as exc:
            v.error = f"invalid: {exc}"
            v.key = variant_key(f"{path}\n" + "\n".join(all_sets), vseed, version)
        yield v


def check_keys(scenario: str | Path, spec: SweepSpec, sets: list[str] | tuple = ()) -> None:
    """A varied key that names no field of the scenario is a bad --grid/--random, not a variant
    failure: raise SweepSpecError before anything runs."""
    from replay.scenario.loader import to_plain
    from replay.sweep.spec import SCENARIO_AXIS, SEED_AXIS, SweepSpecError, check_seed

    try:
        base = to_plain(load_scenario(scenario, sets=list(sets)))
    except ScenarioError as exc:
        raise SweepSpecError(str(exc)) from None
    seeds = [("--grid seed", v) for a in spec.grid if a.name == SEED_AXIS for v in a.values]
    seeds += [
        ("--random seed", v) for r in spec.random if r.name == SEED_AXIS for v in (r.lo, r.hi)
    ]
    for where, value in seeds:  # (a seed axis: each value a scenario's seed)
        check_seed(value, where)
    keys = {r.name: r.lo for r in spec.random}  # key -> a value it takes (the first)
    for a in spec.grid:
        if a.name in (SCENARIO_AXIS, SEED_AXIS):
            continue
        first = a.values[0]
        keys.update(first if isinstance(first, dict) else {a.name: first})
    for key, value in keys.items():
        node: Any = base
        others = [_assignment(k, v) for k, v in keys.items() if k != key]  # (as variants run)
        for depth, part in enumerate(key.split(".")):
            if not isinstance(node, dict) or part not in node:
                if _settable(scenario, [*sets, *others], key, value):
                    break  # a field left out while empty (plant.params.engine: {}), set here
                where = ".".join(key.split(".")[:depth]) or "(top level)"
                choices = ", ".join(node) if isinstance(node, dict) else "(not a mapping)"
                raise SweepSpecError(
                    f"{key}: no field {part!r} in {where} of {scenario} (fields: {choices})"
                )
            node = node[part]


def _assignment(key: str, value: Any) -> str:
    """``key=value`` as a ``--set`` assignment."""
    import yaml

    text = yaml.safe_dump(value, default_flow_style=True).strip().removesuffix("...").strip()
    return f"{key}={text}"


def _settable(scenario: str | Path, sets: list[str], key: str, value: Any) -> bool:
    """Whether the scenario loads with ``key`` set to ``value`` (as the variant will set it,
    with ``sets``: the command's and the other axes' first values)."""
    try:
        load_scenario(scenario, sets=[*sets, _assignment(key, value)])
    except ScenarioError:
        return False
    return True
