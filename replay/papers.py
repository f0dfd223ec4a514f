"""The papers this platform reproduces, each registered once (docs/DESIGN.md, "Adding a fourth
paper"): a :class:`Paper` under the entry-point group ``paper_replay.papers``, named by the key a
scenario's ``paper:`` field uses. The registration names everything of the paper by its import
path (``module:Class`` or ``module:function``), so that reading it imports nothing of the paper:
its controllers, plants, sensors and viewer scenes (found by :mod:`replay.registry` beside those
of the plug-in groups), its figures and claims table, its Foxglove layout and its figures'
captions. The core imports no paper: it reads them here."""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib.metadata import EntryPoint
from typing import Any


@dataclass(frozen=True)
class Paper:
    key: str
    title: str
    authors: str
    text: str  # file under shared/papers/
    order: int  # where its section comes in the report and in listings (lower first)
    # plug-in name -> "module:Class", as the groups paper_replay.controllers, .plants, .sensors
    # and .viewer_scenes would hold them
    controllers: dict[str, str] = field(default_factory=dict)
    plants: dict[str, str] = field(default_factory=dict)
    # a plant type's old name -> its name now: old scenarios and logs name it, the scenario
    # loader reads it as the new one (replay.registry.current_name)
    renamed_plants: dict[str, str] = field(default_factory=dict)
    sensors: dict[str, str] = field(default_factory=dict)
    viewer_scenes: dict[str, str] = field(default_factory=dict)
    figures: str = ""  # "module:function": make(logs_by_name, outdir) -> paths
    claims: str = ""  # "module:function": evaluate(logs_by_name) -> [Claim]
    layout: str = ""  # "module:function": () -> the Foxglove layout (replay.foxglove.layouts)
    captions: dict[int, str] = field(default_factory=dict)  # figure number -> the paper's caption
    # figure number -> the method (controller) the paper draws it for: the same figure of a run
    # of another method is captioned "cf." and names both
    drawn_for: dict[int, str] = field(default_factory=dict)
    # how a figure that draws no one figure of the paper ends its file name -> what it shows
    named: dict[str, str] = field(default_factory=dict)


def papers() -> dict[str, Paper]:
    """Every registered paper by its key, in its ``order``."""
    from replay import registry

    found = [registry.load("paper", name) for name in registry.names("paper")]
    return {p.key: p for p in sorted(found, key=lambda p: (p.order, p.key))}


def resolve(ref: str) -> Any:
    """The object a registration names as ``module:attribute``."""
    return EntryPoint(name=ref, value=ref, group="").load()
