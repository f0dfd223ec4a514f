"""Plug-ins found by name through entry points, so a new plant, sensor or controller needs no
core edit: declare it in a package's ``pyproject.toml`` under one of these groups."""

from __future__ import annotations

import functools
from importlib.metadata import EntryPoint, entry_points
from typing import Any

GROUPS = {
    "plant": "paper_replay.plants",
    "sensor": "paper_replay.sensors",
    "controller": "paper_replay.controllers",
    "figures": "paper_replay.figures",  # paper key -> make(logs_by_name, outdir) -> paths
    "claims": "paper_replay.claims",  # paper key -> evaluate(logs_by_name) -> [Claim]
    "viewer_scene": "paper_replay.viewer_scenes",  # plant type -> replay.viewer RunScene class
}


class UnknownPlugin(LookupError):
    pass


_registered: dict[str, dict[str, type]] = {kind: {} for kind in GROUPS}


class _Loaded:
    def __init__(self, cls: type) -> None:
        self.cls = cls

    def load(self) -> type:
        return self.cls


def register(kind: str, name: str, cls: type) -> None:
    """Register a plug-in in this process only (tests, notebooks); entry points are for packages."""
    _registered[kind][name] = cls


@functools.cache  # once a process: each scan reads every installed package's metadata (~8 ms;
# a run looked plug-ins up 13 times); a package installed later needs a new process, as imports do
def _installed(group: str) -> dict[str, EntryPoint]:
    return {ep.name: ep for ep in entry_points(group=group)}


def _entries(kind: str) -> dict[str, Any]:
    found: dict[str, Any] = dict(_installed(GROUPS[kind]))
    found.update({name: _Loaded(cls) for name, cls in _registered[kind].items()})
    return found


def names(kind: str) -> list[str]:
    return sorted(_entries(kind))


def load(kind: str, name: str) -> Any:
    """The plug-in class called ``name``; an unknown name answers with the known ones."""
    entries = _entries(kind)
    if name not in entries:
        known = ", ".join(sorted(entries)) or "none installed"
        raise UnknownPlugin(f"unknown {kind} {name!r} (known: {known})")
    return entries[name].load()
