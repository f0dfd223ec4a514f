"""The scenario as a typed struct: the YAML mirrors these dataclasses field for field.

A plug-in's own ``params:`` are validated against that plug-in's ``Params`` dataclass, found by
its ``type:`` name (see replay.registry). Units are SI; see docs/scenarios.md for every field.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from replay.params import param

NAME_PATTERN = r"[A-Za-z0-9][A-Za-z0-9_.-]{0,99}"  # a file name: no folder, no leading dot


@dataclass(kw_only=True)
class Timing:
    physics_rate: int = param(
        1000,
        unit="Hz",
        gt=0,
        le=100_000,
        doc="physics steps per second; every task rate must divide it",
    )
    duration: float = param(
        2.0, unit="s", gt=0, le=600, doc="simulated time at most (at least one physics step)"
    )
    state_log_rate: int = param(
        0,
        unit="Hz",
        ge=0,
        le=100_000,
        doc="rate of the plant's state topics; 0 = every physics step",
    )
    frame_rate: int = param(
        100,
        unit="Hz",
        ge=0,
        le=100_000,
        doc="rate of the 3-D viewer topics for Foxglove and Rerun (/tf, /scene, /joint_states: "
        "docs/foxglove.md), rounded to whole physics steps; 0 = none",
    )


@dataclass(kw_only=True)
class PlantSpec:
    type: str = param(doc="plant plug-in name (`replay list --plugins`)", max_length=100)
    params: dict[str, Any] = param({}, doc="the plant's own parameters (its Params)")


@dataclass(kw_only=True)
class SensorSpec:
    type: str = param(doc="sensor plug-in name", max_length=100)
    rate: float = param(
        unit="Hz", ge=0.01, le=100_000, doc="capture rate; must divide the physics rate"
    )
    latency: float = param(
        0.0,
        unit="s",
        ge=0,
        le=60,
        doc="delay from capture to delivery to the controller (rounded to physics steps)",
    )
    params: dict[str, Any] = param({}, doc="the sensor's own parameters")


@dataclass(kw_only=True)
class ControllerSpec:
    type: str = param(doc="controller plug-in name", max_length=100)
    rate: float = param(
        1000.0, unit="Hz", ge=0.01, le=100_000, doc="control rate; must divide the physics rate"
    )
    params: dict[str, Any] = param({}, doc="the controller's own parameters")


@dataclass(kw_only=True)
class TaskSpec:
    """One of several parallel tasks (a scenario's ``tasks:``): a controller plug-in with its own
    rate, the topics it reads and what it writes (Namiki et al. 1999, Fig. 4)."""

    type: str = param(doc="controller plug-in name")
    rate: float = param(1000.0, unit="Hz", gt=0, doc="task rate; must divide the physics rate")
    inputs: list[str] = param([], doc="topics it reads (sensors' or other tasks' outputs)")
    outputs: list[str] = param(
        [],
        doc="topics it publishes for other tasks, and the command "
        "fields it writes (e.g. arm, hand, head)",
    )
    params: dict[str, Any] = param({}, doc="the task's own parameters")


@dataclass(kw_only=True)
class Stop:
    on_events: list[str] = param(
        [], max_length=64, doc="event kinds that end the run (e.g. [capture, rest])"
    )
    after: float = param(
        0.0, unit="s", ge=0, le=600, doc="keep running this long after a stop event"
    )


LOG_LEVELS = ("full", "decimated", "outcome")


@dataclass(kw_only=True)
class LogSpec:
    """What a run's log holds (and a sweep's metrics read without a log): a choice a sweep of
    thousands of runs makes to pay only for what it keeps."""

    level: str = param(
        "full",
        choices=LOG_LEVELS,
        doc="full: every topic; decimated: the plant's state, the camera images and the 3-D "
        "viewer topics at the rates below, the rest in full; outcome: the scenario and the "
        "events (the outcome last) only, every other message still checked for non-finite values",
    )
    state_rate: float = param(
        100.0,
        unit="Hz",
        gt=0,
        le=100_000,
        doc="decimated: rate of the plant's state topics (never above timing.state_log_rate), "
        "rounded to whole physics steps",
    )
    image_rate: float = param(
        10.0,
        unit="Hz",
        gt=0,
        le=100_000,
        doc="decimated: rate of each camera's images and of the 3-D viewer topics (never above "
        "timing.frame_rate), rounded to whole physics steps",
    )


@dataclass(kw_only=True)
class Scenario:
    name: str = param(
        doc="scenario name, used for log and figure file names (letters, digits, "
        "_ . -; so a log cannot leave its folder)",
        pattern=NAME_PATTERN,
    )
    paper: str = param(
        doc="paper key (`replay list`): higashimori2007, namiki2003, ...", pattern=NAME_PATTERN
    )
    description: str = param("", doc="one line for `replay list`", max_length=1000)
    seed: int = param(0, ge=0, le=2**63 - 1, doc="seed of every random generator of the run")
    timing: Timing = field(default_factory=Timing)
    plant: PlantSpec = param(doc="the simulated world")
    sensors: dict[str, SensorSpec] = param({}, doc="name -> sensor")
    controller: ControllerSpec | None = param(None, doc="the paper's method (one controller), or")
    tasks: dict[str, TaskSpec] = param(
        {},
        doc="name -> task: the method as parallel tasks, run in this order each step",
        omit_empty=True,
    )
    stop: Stop = field(default_factory=Stop)
    log: LogSpec | None = param(
        None, doc="what the run's log holds (none: level full)", omit_empty=True
    )
    notes: str = param(
        "", doc="free text: derivations, assumptions, deviations", max_length=100_000
    )

    # filled by the loader, not from YAML
    source: Any = field(default=None, repr=False, compare=False, metadata={"internal": True})
    inputs: tuple = field(
        default=(),
        repr=False,
        compare=False,  # the files read (extends)
        metadata={"internal": True},
    )
