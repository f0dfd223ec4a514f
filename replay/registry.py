"""Plug-ins found by name through entry points, so a new plant, sensor or controller needs no
core edit: declare it in a package's ``pyproject.toml`` under one of these groups. A paper
registers once (group ``paper_replay.papers``, a :class:`replay.papers.Paper`): the plug-ins it
names are found here as if each were in its group.

A scenario may also name one by its import path, ``module:Class`` (a ``my_module.py`` beside the
scenario file, or any importable module): :func:`import_plugin` imports it, for the scenario
loader only when it loads a scenario to run (never from a log's stored scenario), and
:func:`load` finds it afterwards by that name."""

from __future__ import annotations

import functools
import importlib
import inspect
import re
import sys
from importlib.metadata import EntryPoint, entry_points
from pathlib import Path
from typing import Any

from replay.top_level import guard

guard()  # entry points name plants.* and analysis.*: the installed ones, never a cwd folder

GROUPS = {
    "plant": "paper_replay.plants",
    "sensor": "paper_replay.sensors",
    "controller": "paper_replay.controllers",
    # paper key -> make(logs_by_name, outdir) -> paths / evaluate(logs_by_name) -> [Claim]: each
    # paper's registration names its own; these groups stay for a figures/claims plug-in alone
    "figures": "paper_replay.figures",
    "claims": "paper_replay.claims",
    "viewer_scene": "paper_replay.viewer_scenes",  # plant type -> replay.viewer RunScene class
    "commands": "paper_replay.commands",  # name -> register(click group): more `replay` commands
    "check": "paper_replay.checks",  # name -> check(scenario) -> a warning for `validate`, or ""
    "sweep_plot": "paper_replay.sweep_plots",  # name -> plot(summary.csv, out folder) -> paths
    "input_sets": "paper_replay.input_sets",  # name -> episodes(task, n) for `replay evaluate`
    "paper": "paper_replay.papers",  # paper key -> replay.papers.Paper: all of one paper, once
}

# what a paper's registration adds to a kind: the Paper field of its names -> "module:attr"
# (figures and claims: the paper's own key)
_FROM_PAPERS = {
    "plant": "plants",
    "sensor": "sensors",
    "controller": "controllers",
    "viewer_scene": "viewer_scenes",
    "figures": "figures",
    "claims": "claims",
}


class UnknownPlugin(LookupError):
    pass


_registered: dict[str, dict[str, Any]] = {kind: {} for kind in GROUPS}
_imported: dict[str, dict[str, type]] = {kind: {} for kind in GROUPS}  # module:Class names
_folders: dict[tuple[str, str], str] = {}  # (kind, module:Class) -> the folder it came from

IMPORT_PATH = r"[A-Za-z_]\w*(\.[A-Za-z_]\w*)*:[A-Za-z_]\w*(\.[A-Za-z_]\w*)*"  # module:Class
_IMPORT_PATH = re.compile(IMPORT_PATH)


class _Loaded:
    def __init__(self, cls: Any) -> None:
        self.cls = cls

    def load(self) -> Any:
        return self.cls


def register(kind: str, name: str, cls: Any) -> None:
    """Register a plug-in (or a paper) in this process only (tests, notebooks); entry points are
    for packages."""
    _registered[kind][name] = cls


@functools.cache  # once a process: each scan reads every installed package's metadata (~8 ms;
# a run looked plug-ins up 13 times); a package installed later needs a new process, as imports do
def _installed(group: str) -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=group)}


def _entries(kind: str) -> dict[str, Any]:
    found: dict[str, Any] = _from_papers(kind) if kind in _FROM_PAPERS else {}
    found.update(_installed(GROUPS[kind]))
    found.update({name: _Loaded(cls) for name, cls in _registered[kind].items()})
    return found


def _from_papers(kind: str) -> dict[str, EntryPoint]:
    """The ``kind`` plug-ins the registered papers name (a group's entry of the same name wins)."""
    found: dict[str, EntryPoint] = {}
    for entry in _entries("paper").values():
        paper = entry.load()
        refs = getattr(paper, _FROM_PAPERS[kind])
        refs = {paper.key: refs} if isinstance(refs, str) else refs
        found.update({n: EntryPoint(n, ref, GROUPS[kind]) for n, ref in refs.items() if ref})
    return found


def is_import_path(name: str) -> bool:
    """Whether a plug-in name is an import path (``module:Class``) rather than a name."""
    return ":" in name


def current_name(kind: str, name: str) -> str:
    """``name`` as the plug-in is called now: a plant type a registered paper renamed (its
    ``renamed_plants``, kept for old scenarios and logs) -> its new name, for a plant or the
    viewer scene registered under its type; any other unchanged."""
    if kind not in ("plant", "viewer_scene") or is_import_path(name) or name in _entries(kind):
        return name
    for entry in _entries("paper").values():
        new = entry.load().renamed_plants.get(name)
        if new:
            return new
    return name


def known(kind: str, name: str) -> bool:
    """Whether :func:`load` finds ``name`` (or the name it was renamed to) without importing
    anything new."""
    if is_import_path(name):
        return name in _imported[kind]
    return current_name(kind, name) in _entries(kind)


def _interface(kind: str) -> type | None:
    from replay.interfaces import Controller, Plant, Sensor

    return {"plant": Plant, "sensor": Sensor, "controller": Controller}.get(kind)


def import_plugin(kind: str, name: str, folder: str | Path) -> type:
    """The class ``module:Class`` names, imported (once a process) with ``folder`` (the scenario
    file's) at the end of ``sys.path`` so that a module beside the scenario is found, while an
    installed package of the same name still wins (docs/DESIGN.md, "Top-level packages").
    Importing runs the module's code: call it only for a scenario about to run. Raises
    UnknownPlugin, one line: no such module, no such object, not a class of the interface."""
    if name in _imported[kind]:
        return _imported[kind][name]
    if not _IMPORT_PATH.fullmatch(name):
        raise UnknownPlugin(f"bad import path {name[:100]!r} (expected module:Class)")
    module_name, _, attr = name.partition(":")
    where = str(Path(folder).resolve())
    if where not in sys.path:
        sys.path.append(where)
        importlib.invalidate_caches()
    try:
        module = importlib.import_module(module_name)
    except ModuleNotFoundError as exc:
        if exc.name and (module_name + ".").startswith(exc.name + "."):
            raise UnknownPlugin(
                f"no module {module_name!r} for {kind} {name!r} (neither in {where} nor installed)"
            ) from None
        raise UnknownPlugin(f"{kind} {name!r}: its module cannot import {exc.name!r}") from None
    except Exception as exc:  # noqa: BLE001 - the module's own code failed: one line
        raise UnknownPlugin(
            f"{kind} {name!r}: importing {module_name!r} failed: {_first(exc)}"
        ) from None
    obj: Any = module
    for part in attr.split("."):
        if not hasattr(obj, part):
            raise UnknownPlugin(f"module {module_name!r} has no {attr!r} ({kind} {name!r})")
        obj = getattr(obj, part)
    base = _interface(kind)
    if base is not None and not (isinstance(obj, type) and issubclass(obj, base)):
        raise UnknownPlugin(
            f"{kind} {name!r} is not a class implementing replay.interfaces.{base.__name__}"
        )
    if inspect.isabstract(obj):
        missing = ", ".join(sorted(getattr(obj, "__abstractmethods__", ())))
        raise UnknownPlugin(f"{kind} {name!r} does not implement {missing}")
    if not hasattr(obj, "Params"):
        raise UnknownPlugin(f"{kind} {name!r} declares no Params dataclass")
    _imported[kind][name] = obj
    _folders[(kind, name)] = where
    return obj


def imported_plugins() -> list[tuple[str, str, str]]:
    """(kind, ``module:Class``, folder) of every plug-in this process imported by its path: what
    a fresh worker process (a Ray worker of a sweep) imports again before it loads a variant."""
    return [(kind, name, folder) for (kind, name), folder in _folders.items()]


def _first(exc: BaseException) -> str:
    """``exc`` as one short line (a SyntaxError with its file and line)."""
    if isinstance(exc, SyntaxError):
        return f"SyntaxError: {exc.msg} ({Path(exc.filename or '?').name}:{exc.lineno})"
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0][:200]}" if text else type(exc).__name__


def names(kind: str) -> list[str]:
    return sorted(_entries(kind))


def load(kind: str, name: str) -> Any:
    """The plug-in class called ``name``; an unknown name answers with the known ones. An
    import path (``module:Class``) is found only once :func:`import_plugin` imported it."""
    if is_import_path(name):
        if name in _imported[kind]:
            return _imported[kind][name]
        raise UnknownPlugin(
            f"{kind} {name[:100]!r} is not imported (a module:Class plug-in is imported only by "
            "loading a scenario to run, never from a log)"
        )
    entries = _entries(kind)
    name = current_name(kind, name)
    if name not in entries:
        known = ", ".join(sorted(entries)) or "none installed"
        raise UnknownPlugin(f"unknown {kind} {name!r} (known: {known})")
    return entries[name].load()
