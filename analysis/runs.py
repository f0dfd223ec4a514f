"""Runs identified by their logs, labelled by what differs from their experiment's default.

Analysis (figures, claims, the report) takes logs, not names: two logs of the same scenario name
(``catch_optimised`` and the same run with ``--set sensors.stereo.latency=0.01``) are two runs.
Each run gets a key unique among the logs given (the scenario name; for a second log of that name
the name and its label, ``catch_optimised (stereo latency 10 ms)``) and a label: a short diff
of its stored, resolved scenario against the shipped scenario of the same name, or for a name
that is not shipped against the nearest shipped scenario of its paper (its experiment: a renamed
variant ``catch_lat10`` is a variant of ``catch_optimised``; of equally near ones the fewest
``extends:`` steps from the paper's own). A setting stated at the value the other side leaves to
its default is no difference: an engine named with its defaults (``--set
plant.params.engine.type=pybullet``) where the shipped scenario names none (its plant's own).

The paper's own rows look their runs up by scenario name: the log that matches the shipped
scenario keeps the plain name.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, TypeVar

import numpy as np
import yaml

from replay import registry
from replay.log import LogError, LogReader
from replay.scenario.yamlio import one_line

T = TypeVar("T")
MAX_ITEMS = 3  # differences named in a label ("+N more" after)
LABEL_LENGTH = 80  # characters of a label
_IGNORED = {"name", "description", "notes", "paper"}
_SECONDS = {"latency", "duration", "after"}  # fields in s, written in ms below 1 s, else in s


@dataclass(frozen=True)
class Run:
    key: str  # unique among the logs analysed together
    name: str  # the scenario's name
    paper: str
    label: str  # what differs from ``experiment`` ("" when nothing)
    experiment: str  # the shipped scenario it was compared with ("" when none)
    reader: LogReader


_RUNS: weakref.WeakKeyDictionary[LogReader, Run] = weakref.WeakKeyDictionary()


def _flat(data: Any, prefix: str = "") -> dict[str, Any]:
    if isinstance(data, dict):
        out: dict[str, Any] = {}
        for k, v in data.items():
            out.update(_flat(v, f"{prefix}{k}."))
        return out
    return {prefix.rstrip("."): data}


_TYPED: weakref.WeakKeyDictionary[LogReader, Any] = weakref.WeakKeyDictionary()


def once_per_reader(load: Callable[[LogReader, str | None], T]) -> Callable[..., T]:
    """``load(reader, name)`` made once per reader and name, as long as the reader lives: a
    run's claims, figures and falsifiers read the same log into the same arrays again (the
    grasp falsifiers evaluated the whole table seven times, ~0.85 s of JSON a log each time).
    The caller reads what it is given, never changes it: the run's own arrays are made
    read-only (a slip raises); its dicts and lists (the scenario, the events) are shared as
    they are, for reading (a copy to change: ``copy.deepcopy``)."""
    made: weakref.WeakKeyDictionary[LogReader, dict[str | None, T]] = weakref.WeakKeyDictionary()

    @functools.wraps(load)
    def cached(log: LogReader, name: str | None = None) -> T:  # (the loaders' own names)
        of_reader = made.setdefault(log, {})
        if name not in of_reader:
            run = load(log, name)
            for value in vars(run).values():
                if isinstance(value, np.ndarray):
                    value.flags.writeable = False
            of_reader[name] = run
        return of_reader[name]

    return cached


def typed_scenario(reader: LogReader):
    """The log's stored scenario loaded as the loader types it (known plug-ins only), once per
    reader: the claims and figures ask it of one log many times (~20 ms of YAML each). The
    caller reads it, never changes it. Raises what ``scenario_from_text`` raises."""
    from replay.scenario import scenario_from_text

    typed = _TYPED.get(reader)
    if typed is None:
        name = f"{reader.path.name}:/scenario"
        typed = scenario_from_text(reader.scenario()["yaml"], name=name, plugins="known-only")
        _TYPED[reader] = typed
    return typed


def current_config(reader: LogReader) -> dict[str, Any]:
    """The log's resolved scenario; an old one's (its plant type since renamed) as the loader
    reads it now: the type's name now, fields since moved in their places (a ``Params``'
    ``migrate``), all else as stored, or as stored where it does not load here. (Loading costs
    the plant's imports, ~0.1 s: a log of today's names is as stored.) Raises LogError as
    ``scenario_config`` does."""
    from replay.scenario import ScenarioError, resolved_yaml, scenario_from_text

    config = reader.scenario_config()
    plant = config.get("plant")
    kind = str(plant.get("type")) if isinstance(plant, dict) else ""
    if registry.current_name("plant", kind) == kind:
        return config
    try:
        sc = scenario_from_text(reader.scenario()["yaml"], plugins="known-only")
        return yaml.safe_load(resolved_yaml(sc))
    except (ScenarioError, KeyError, TypeError, ValueError, yaml.YAMLError):
        return config


@lru_cache(maxsize=1)
def _shipped_names() -> frozenset[str]:
    from replay.resources import scenario_dir

    return frozenset(p.stem for p in scenario_dir().glob("*.yaml"))


@lru_cache(maxsize=None)
def _shipped(name: str) -> dict[str, Any] | None:
    """The shipped scenario ``name`` resolved as a log stores it, flattened (None: none). Only
    a name of the shipped folder's listing is read (a log's name never makes a path)."""
    from replay.resources import scenario_dir
    from replay.scenario import ScenarioError, load_scenario, resolved_yaml

    if name not in _shipped_names():
        return None
    path = scenario_dir() / f"{name}.yaml"
    try:
        return _flat(yaml.safe_load(resolved_yaml(load_scenario(path))))
    except (ScenarioError, OSError, ValueError, yaml.YAMLError):
        return None


@lru_cache(maxsize=None)
def _shipped_of(paper: str) -> tuple[str, ...]:
    return tuple(n for n in sorted(_shipped_names()) if (_shipped(n) or {}).get("paper") == paper)


@lru_cache(maxsize=None)
def _depth(name: str) -> int:
    """How many ``extends:`` steps the shipped scenario ``name`` is from one that extends none
    (catch_optimised 0, catch_initial 1): the paper's own set-up is the shallowest."""
    from replay.resources import scenario_dir

    seen: list[str] = []
    while name in _shipped_names() and name not in seen:
        seen.append(name)
        try:
            text = (scenario_dir() / f"{name}.yaml").read_text(encoding="utf-8")
            base = (yaml.safe_load(text) or {}).get("extends")
        except (OSError, ValueError, yaml.YAMLError, AttributeError):
            break
        if not isinstance(base, str):
            break
        name = base.removesuffix(".yaml")
    return max(len(seen) - 1, 0)


def _short(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:g}"
    if isinstance(v, list):
        return "[" + ", ".join(_short(x) for x in v[:3]) + (", …" if len(v) > 3 else "") + "]"
    return str(v)


def _item(path: str, value: Any) -> str:
    parts = [p for p in path.split(".") if p != "params"]
    if parts[0] == "sensors" and len(parts) > 2:
        what = " ".join(parts[1:])
    elif parts[-2:] == ["engine", "type"]:  # plant.params.engine.type
        what = "engine"
    else:
        what = parts[-1].replace("_", " ")
    if parts[-1] in _SECONDS and type(value) in (int, float) and value > 0:
        return f"{what} {1000 * value:g} ms" if value < 1 else f"{what} {value:g} s"
    return f"{what} {_short(value)}"


def _engine(plant_type: str) -> str:
    """The engine's label a plant type names (an arm plant made before the engine field, or the
    engine-free rig: the reference engine), else ""."""
    from analysis.engines import REFERENCE, engine_of, label

    engine = engine_of({"plant": {"type": plant_type}})
    return label(engine) if engine != REFERENCE or plant_type == "arm_rig" else ""


_ENGINE = "plant.params.engine."


@lru_cache(maxsize=None)
def _own_engine(plant_type: str) -> tuple[tuple[str, Any], ...]:
    """The engine a plant of ``plant_type`` runs where its ``plant.params.engine`` is empty
    (plants/arm_rig/engine.py ``own_engine_settings``), as a resolved scenario would state it,
    flattened; () for a plant without one or not installed here. Loads the plant, as typing the
    shipped scenario (``_shipped``) already has."""
    from plants.arm_rig.engine import own_engine_settings
    from replay.scenario.loader import to_plain

    if not registry.known("plant", plant_type):
        return ()
    settings = own_engine_settings(registry.load("plant", plant_type))
    return () if settings is None else tuple(_flat(to_plain(settings), _ENGINE).items())


def _engine_stated(flat: Mapping[str, Any], other: Mapping[str, Any]) -> Mapping[str, Any]:
    """``flat`` (a flattened resolved scenario) with its plant's own engine stated, defaults
    filled, where it names no engine and ``other``, of the same plant type (the shipped one,
    whose plant is loaded), does: an empty engine field is that engine, so a run stating it
    (``--set plant.params.engine.type=pybullet``) changes nothing."""
    if f"{_ENGINE}type" in flat or f"{_ENGINE}type" not in other:
        return flat
    if flat.get("plant.type") != other.get("plant.type"):  # (its params: not compared)
        return flat
    own = _own_engine(str(flat.get("plant.type")))
    return {**flat, **dict(own)} if own else flat


def differences(stored: Mapping[str, Any], ref: Mapping[str, Any]) -> list[str]:
    """What ``stored`` (a flattened resolved scenario) sets differently from ``ref``, as short
    phrases: a changed plug-in type names the new type (its params are then not listed). A
    setting stated at the value its side leaves to the default (an engine named with its
    defaults where the other names none: :func:`_engine_stated`) is no difference."""
    stored, ref = _engine_stated(stored, ref), _engine_stated(ref, stored)
    items, replaced = [], []
    sensors = sorted({p.split(".")[1] for p in stored if p.startswith("sensors.")})
    types = ("plant.type", "plant.params.engine.type", "controller.type")  # (an engine: its own
    for path in (*types, *(f"sensors.{s}.type" for s in sensors)):  # settings, not listed)
        new = stored.get(path)
        if new is not None and new != ref.get(path):
            if path == "plant.type" and _engine(str(new)):
                items.append(f"engine {_engine(str(new))}")
            else:
                items.append(f"{path.split('.')[-2]} {_short(new)}")
            replaced.append(path[: -len("type")])
    for path in sorted(stored.keys() | ref.keys()):
        if path.split(".")[0] in _IGNORED or any(path.startswith(r) for r in replaced):
            continue
        a, b = stored.get(path), ref.get(path)
        if a != b:
            items.append(_item(path, a) if path in stored else f"no {_item(path, '')}".strip())
    return items


def _label(items: list[str]) -> str:
    text = ", ".join(items[:MAX_ITEMS])
    if len(items) > MAX_ITEMS:
        text += f", +{len(items) - MAX_ITEMS} more"
    text = one_line(" ".join(text.split()))  # one line, control characters escaped
    return text if len(text) <= LABEL_LENGTH else text[: LABEL_LENGTH - 1] + "…"


def _compare(stored: dict[str, Any], name: str, paper: str) -> tuple[str, list[str]]:
    """(the experiment, the differences from it): the shipped scenario of the same name, else
    the shipped scenario of the paper with the fewest differences, of those the one fewest
    ``extends:`` steps from the paper's own (a controller swapped in leaves every scenario that
    differs only in controller params tied: it is a variant of catch_optimised, not of the
    first name in the alphabet)."""
    ref = _shipped(name)
    if ref is not None:
        return name, differences(stored, ref)
    found = [(o, differences(stored, _shipped(o) or {})) for o in _shipped_of(paper)]
    if not found:
        return "", []
    return min(found, key=lambda f: (len(f[1]), _depth(f[0]), f[0]))


def describe(reader: LogReader, key: str | None = None) -> Run:
    """The run ``reader`` holds (as :func:`keyed` named it, else by its scenario name)."""
    known = _RUNS.get(reader)
    if known is not None and (key is None or known.key == key):
        return known
    try:
        sc = reader.scenario()
        stored = _flat(current_config(reader))
    except (LogError, AttributeError):
        sc, stored = {}, {}
    name, paper = str(sc.get("name", key or "?")), str(sc.get("paper", ""))
    experiment, items = _compare(stored, name, paper) if stored else ("", [])
    run = Run(key or name, name, paper, _label(items), experiment, reader)
    _RUNS[reader] = run
    return run


def variants_as_shipped(readers: Mapping[str, LogReader]) -> dict[str, str]:
    """key -> label of each log that changes its shipped scenario yet holds its plain name (no
    run of the scenario as shipped among the logs): the paper's rows would read it as the
    paper's run. A run that differs by its engine alone (``engine …``) is the experiment in
    another simulator, not a variant of it."""
    out = {}
    for key, r in readers.items():
        if not isinstance(r, LogReader):
            continue
        run = describe(r, key)
        if run.label and key == run.name == run.experiment:
            if not (run.label.startswith("engine ") and "," not in run.label):
                out[key] = run.label
    return out


def label(reader: LogReader) -> str:
    return describe(reader).label


def keyed(readers: Iterable[LogReader]) -> dict[str, LogReader]:
    """A unique key per log (in the order given): the scenario name; a second log of that name
    gets the name and its label (``name (label)``), or ``name #2``; the log matching the shipped
    scenario keeps the plain name. No key is another run's title (:func:`titled`: a plain key
    with its label): a second log of the plain key's variant is ``name (label) #2``."""
    runs = [describe(r) for r in readers]
    taken: dict[str, int] = {}
    for r in runs:
        taken[r.name] = taken.get(r.name, 0) + 1
    first: dict[
        str, Run
    ] = {}  # name -> the run that keeps it: the unlabelled one, else the first given
    for r in runs:
        if r.name not in first or (not r.label and first[r.name].label):
            first[r.name] = r
    out: dict[str, LogReader] = {}
    titles = {f"{f.name} ({f.label})" for f in first.values() if f.label}  # the plain keys' titles
    for r in runs:
        key = r.name
        if first[r.name] is not r:
            key = f"{r.name} ({r.label})" if r.label else r.name
        n = 2
        base = key
        while key in out or (key != r.name and key in titles):
            key, n = f"{base} #{n}", n + 1
        _RUNS[r.reader] = Run(key, r.name, r.paper, r.label, r.experiment, r.reader)
        out[key] = r.reader
    return out


def titled(key: str, reader: LogReader) -> str:
    """``key``, with its label when the key does not already say it: a figure's run name, its
    control and format characters escaped (a log's ESC is no glyph)."""
    label = describe(reader, key).label
    return one_line(f"{key} ({label})" if label and label not in key else key)


def by_paper(readers: Iterable[LogReader]) -> dict[str, dict[str, LogReader]]:
    """:func:`keyed` per paper (the stored scenario's ``paper``)."""
    keys = keyed(readers)
    out: dict[str, dict[str, LogReader]] = {}
    for key, r in keys.items():
        out.setdefault(describe(r).paper, {})[key] = r
    return out


def name_of(reader: LogReader) -> str:
    """The run's scenario name (its key may carry a label)."""
    return describe(reader).name


def unreadable(reader: LogReader) -> str:
    """Why ``reader``'s log is no run the analysis can read, "" when it is one: its /scenario
    message can be read, names a paper and a scenario, and its plant's params type here as the
    analysis types them (a value of the wrong type, an engine not registered here do not; a
    plant not installed here keeps them as data)."""
    try:
        sc = reader.scenario()
    except LogError as exc:
        return str(exc)
    paper, name = sc.get("paper"), sc.get("name")
    if not (isinstance(paper, str) and paper and isinstance(name, str) and name):
        return "its /scenario message names no paper or scenario (not a run log?)"
    return _untyped_plant(reader)


def _untyped_plant(reader: LogReader) -> str:
    """Why the stored plant's params do not type with its installed plant's ``Params``."""
    from replay import registry
    from replay.scenario import ScenarioError, params_from_data

    plant = reader.scenario_config().get("plant") or {}
    kind = plant.get("type")
    if not (isinstance(kind, str) and registry.known("plant", kind)):
        return ""
    cls = getattr(registry.load("plant", kind), "Params", None)
    try:
        if cls is not None:
            params_from_data(cls, plant.get("params"), "plant.params", "<stored plant.params>")
    except ScenarioError as exc:
        return f"its stored plant does not load here: {exc}"
    return ""
