"""The small typed interfaces where plants, sensors and controllers meet (in the runner only).

- A **Plant** knows physics and nothing of any paper's method. It takes actuator commands,
  steps its simulator by a fixed ``dt``, reports ground truth for the log, a :class:`Scene` for
  cameras, physics events (collisions, rest) and a ``spec()``: the nominal robot and object
  description a controller may know (kinematics, limits, the object's mass), never simulator state.
- A **Sensor** turns a Scene into a measurement (a payload dataclass); the runner logs it at the
  capture time and delivers it to the controller ``latency`` seconds later.
- A **Controller** knows its paper's method and nothing of any simulator: it sees only
  measurements (and the spec), returns commands, and says what it intends (``intent()``, merged
  into the plant's collision events) and what it decided (``pop_events()``, e.g. ``infeasible``).

Each plug-in declares ``Params``, a dataclass of :func:`replay.params.param` fields, validated from
the scenario's ``params:`` mapping. Plug-ins are found by name through entry points
(``paper_replay.plants``, ``paper_replay.sensors``, ``paper_replay.controllers``).

Typed ports: what a plug-in gives and takes is declared on its class, and the scenario loader
(:mod:`replay.scenario.ports`) checks that the plant, sensors and controller of a scenario fit
before anything runs:

- ``Plant.spec_type``: the type ``spec()`` returns; ``Plant.command_types``: what ``apply()``
  accepts;
- ``Controller.spec_type``: the spec it needs (the plant's must be it or a subclass);
  ``Controller.command_type``: what ``update()`` returns; ``Controller.reads``: the topics it
  reads, each of which some sensor of the scenario must publish;
- ``Sensor.spec_type``: the spec it needs, or None; ``Sensor.topic`` (or its params' ``topic``):
  what it publishes.

``object`` (the default) fits anything, so a plug-in that declares nothing is not checked.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from replay.scene import Frame, Scene


@dataclass
class Occurrence:
    """Something that happened, before it becomes an ``/events`` message: ``kind`` and ``data``."""

    kind: str
    data: dict


class Plant(ABC):
    Params: ClassVar[type]
    description: ClassVar[str] = ""
    spec_type: ClassVar[type] = object  # what spec() returns
    command_types: ClassVar[tuple[type, ...]] = (object,)  # what apply() accepts

    def __init__(self, params: Any, *, dt: float, rng: np.random.Generator) -> None:
        self.params = params
        self.dt = dt
        self.rng = rng

    @abstractmethod
    def apply(self, command: Any) -> None:
        """Set the actuator command, held until the next call."""

    @abstractmethod
    def step(self) -> None:
        """Advance the simulation by ``dt``."""

    @abstractmethod
    def truth(self, t: float) -> dict[str, Any]:
        """Ground truth to log now: topic -> payload dataclass (or a list of them, as in
        ``Controller.telemetry``)."""

    @abstractmethod
    def scene(self) -> Scene:
        """The visible primitives now, for cameras."""

    @abstractmethod
    def spec(self) -> Any:
        """The nominal description a controller may know (no simulator objects)."""

    def pop_events(self) -> list[Occurrence]:
        """Physics events since the last call."""
        return []

    def outcome(self, t: float) -> dict | None:
        """The physical verdict at the end of a run: ``{"success": bool, "reason": str, **metrics}``
        (e.g. captured and the final speed; caught and the relative speed at first contact), or
        None when this plant has no notion of success."""
        return None

    # -- for 3-D viewers (Foxglove, Rerun: replay/foxglove); the scene's bodies need nothing more
    def frames(self) -> list[Frame]:
        """The robot's link frames now (``/tf``): the root link in ``world``, every other link
        in its parent link. Default: none (a plant without a robot model)."""
        return []

    def joints(self) -> tuple[list, list, list, list] | None:
        """Every robot joint now (``/joint_states``): names, positions, velocities, efforts;
        None when the plant has none."""
        return None

    def robot_description(self) -> str | None:
        """The robot's URDF text (``/robot_description``, whose links :meth:`frames` names),
        or None."""
        return None

    def close(self) -> None:
        pass


class Sensor(ABC):
    Params: ClassVar[type]
    topic: str  # a class default; an instance may publish on its params' ``topic``
    description: ClassVar[str] = ""
    spec_type: ClassVar[type | None] = None  # the plant spec it needs, or None

    @classmethod
    def topic_for(cls, params: Any) -> str:
        """The topic this sensor publishes with ``params`` (a ``topic`` param, else ``topic``)."""
        return getattr(params, "topic", None) or cls.topic

    def __init__(self, params: Any, *, rng: np.random.Generator, spec: Any = None) -> None:
        self.params = params
        self.rng = rng
        self.spec = spec

    @abstractmethod
    def measure(self, t: float, scene: Scene) -> Any | None:
        """A measurement payload (with ``t`` = capture time), or None when nothing was seen."""


class Controller(ABC):
    Params: ClassVar[type]
    description: ClassVar[str] = ""
    spec_type: ClassVar[type] = object  # the plant spec it needs
    command_type: ClassVar[type] = object  # what update() returns
    reads: ClassVar[tuple[str, ...]] = ()  # topics it reads (sensors must give them)

    def __init__(self, params: Any, *, spec: Any) -> None:
        self.params = params
        self.spec = spec

    @abstractmethod
    def update(self, t: float, measurements: list[tuple[str, Any]]) -> Any | None:
        """Measurements delivered since the last call (topic, payload) -> a command or None."""

    def intent(self) -> dict:
        """What the method plans for the next contact (merged into collision events)."""
        return {}

    def pop_events(self) -> list[Occurrence]:
        """Decisions worth an ``/events`` message since the last call (e.g. ``infeasible``)."""
        return []

    def outcome(self, t: float) -> dict:
        """The method's side of the verdict at the end of a run: metrics to add and, when the
        method knows it failed (no feasible plan, target out of reach), ``success: False`` with
        its ``reason``."""
        return {}

    def telemetry(self, t: float) -> dict[str, Any]:
        """Extra topics to log this control step: topic -> payload (or a list of payloads)."""
        return {}
