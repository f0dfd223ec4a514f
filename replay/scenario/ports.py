"""Typed ports: a scenario's plant, sensors and controller must fit before anything runs.

Checked from the classes' declarations (:mod:`replay.interfaces`), never by running them: the
plant's ``spec_type`` is what the controller (and each sensor) needs or a subclass of it, the
controller's ``command_type`` is one the plant accepts, and every topic the controller reads is
published by a sensor of the scenario. A mismatch is one :class:`ScenarioError` at the
controller's (or the sensor's) ``type``.
"""

from __future__ import annotations

from typing import Callable

import yaml

from replay import registry
from replay.scenario.yamlio import ScenarioError


def _name(tp) -> str:
    return getattr(tp, "__name__", str(tp))


def _check_controller(plant, plant_type: str, ctrl, spec, path: str, where) -> None:
    gives = getattr(plant, "spec_type", object)
    needs = getattr(ctrl, "spec_type", object)
    if not (isinstance(gives, type) and issubclass(gives, needs)):
        raise ScenarioError(
            f"controller {spec.type!r} needs a plant giving {_name(needs)}; "
            f"plant {plant_type!r} gives {_name(gives)}",
            node=where,
            path=f"{path}.type",
        )
    command = getattr(ctrl, "command_type", object)
    accepts = tuple(getattr(plant, "command_types", (object,)))
    if not any(issubclass(command, t) for t in accepts):
        raise ScenarioError(
            f"controller {spec.type!r} commands {_name(command)}; plant "
            f"{plant_type!r} takes {' or '.join(map(_name, accepts))}",
            node=where,
            path=f"{path}.type",
        )


def check_ports(sc, node_of: Callable[[str], yaml.Node]) -> None:
    """Every controller (``controller:``, and each of a ``tasks:`` section) against the plant;
    each sensor against the plant; what ``controller:`` reads against what the sensors give."""
    from replay.scenario.loader import plugin_sections

    plant = registry.load("plant", sc.plant.type)
    gives = getattr(plant, "spec_type", object)
    for kind, spec, path in plugin_sections(sc):
        if kind == "controller":
            _check_controller(
                plant,
                sc.plant.type,
                registry.load("controller", spec.type),
                spec,
                path,
                node_of(f"{path}.type"),
            )
    ctrl = registry.load("controller", sc.controller.type) if sc.controller is not None else None
    where = node_of("controller.type")
    published: dict[str, str] = {}
    for name, s in sc.sensors.items():
        cls = registry.load("sensor", s.type)
        need = getattr(cls, "spec_type", None)
        if need is not None and not issubclass(gives, need):
            raise ScenarioError(
                f"sensor {s.type!r} needs a plant giving {_name(need)}; plant "
                f"{sc.plant.type!r} gives {_name(gives)}",
                node=node_of(f"sensors.{name}.type"),
                path=f"sensors.{name}.type",
            )
        topic_for = getattr(cls, "topic_for", None)
        topic = topic_for(s.params) if topic_for else getattr(cls, "topic", None)
        published.setdefault(str(topic), name)
    missing = [t for t in getattr(ctrl, "reads", ()) if t not in published]
    if missing:
        have = ", ".join(f"{t} ({n})" for t, n in published.items()) or "no sensors"
        raise ScenarioError(
            f"controller {sc.controller.type!r} reads {', '.join(missing)}, "
            f"which no sensor publishes (sensors give: {have})",
            node=where,
            path="controller.type",
        )
