"""What the runner hands its observers: each step's record, once (``Runner``'s loop).

A :class:`StepRecord` is what one physics step k made at its time t_k, in the order the log holds
it: the events that ended the step before (logged at t_k), the sensors' captures (with their
frames to draw), the controller's events and telemetry, the plant's state and, when due, the
scene for the 3-D topics. An observer (:class:`RunObserver`) takes whole records:
:class:`LogObserver` writes them to the run's log (its Foxglove topics drawn in between),
:class:`MessageObserver` passes their messages one by one to callables such as the live viewer.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Protocol

from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, Event, ScenarioInfo
from replay.scene import Scene


@dataclass
class Capture:
    """A sensor due at the step: its measurement (None: none this time) and whether its frame
    is drawn (a camera's image, at the log level's image rate)."""

    name: str
    sensor: Any
    topic: str
    measurement: Any
    image: bool


@dataclass
class StepRecord:
    k: int
    t_ns: int
    events: list[Event] = field(default_factory=list)  # the step before ended with them
    captures: list[Capture] = field(default_factory=list)
    control: list[Event] = field(default_factory=list)  # the controller's events now
    telemetry: dict | None = None
    state: dict | None = None
    scene: Scene | None = None  # the 3-D topics' frame, when due

    def messages(self) -> list[tuple[str, Any]]:
        """(topic, payload) of each message in log order; a list payload is its items'."""
        out: list[tuple[str, Any]] = [(TOPIC_EVENTS, e) for e in self.events]
        out += [(c.topic, c.measurement) for c in self.captures if c.measurement is not None]
        out += [(TOPIC_EVENTS, e) for e in self.control]
        for data in (self.telemetry, self.state):
            for topic, payload in (data or {}).items():
                out += [(topic, p) for p in (payload if isinstance(payload, list) else (payload,))]
        return out


class RunObserver(Protocol):
    def start(self, info: ScenarioInfo) -> None: ...  # the run's first message

    def record(self, rec: StepRecord) -> None: ...


class LogObserver:
    """The run's log: the events in ``log``, the other messages in ``data`` (the log itself, or
    at ``outcome`` level a log that only checks them), the Foxglove topics (``topics``: a
    :class:`~replay.foxglove.run.RunTopics`, or None) in between: a capture's frame before its
    measurement, an event's ``/log`` line after it, the 3-D frame after the state."""

    def __init__(self, log, data, topics=None) -> None:
        self.log, self.data, self.topics = log, data, topics

    def start(self, info: ScenarioInfo) -> None:
        self.log.write(TOPIC_SCENARIO, info, 0)
        if self.topics is not None:
            self.topics.start(0)  # the robot's description

    def record(self, rec: StepRecord) -> None:
        t_ns, topics, data = rec.t_ns, self.topics, self.data
        if rec.events:
            self.events(rec.events, t_ns)
        for c in rec.captures:
            if c.image and topics is not None:
                topics.sensor(c.name, c.sensor, t_ns)
            if c.measurement is not None:
                data.write(c.topic, c.measurement, t_ns)
        if rec.control:
            self.events(rec.control, t_ns)
        if rec.telemetry:
            data.write_all(rec.telemetry, t_ns)
        if rec.state:
            data.write_all(rec.state, t_ns)
        if rec.scene is not None and topics is not None:
            topics.frame(rec.scene, t_ns)

    def events(self, events: list[Event], t_ns: int) -> None:
        for e in events:
            self.log.write(TOPIC_EVENTS, e, t_ns)
            if self.topics is not None:
                self.topics.event(e, t_ns)


class MessageObserver:
    """Each message of a record to ``callables(topic, payload, t_ns)`` (e.g. a live viewer's),
    in log order, at every log level."""

    def __init__(self, callables: tuple[Callable[[str, Any, int], None], ...]) -> None:
        self.callables = callables

    def start(self, info: ScenarioInfo) -> None:
        for observe in self.callables:
            observe(TOPIC_SCENARIO, info, 0)

    def record(self, rec: StepRecord) -> None:
        for topic, payload in rec.messages():
            for observe in self.callables:
                observe(topic, payload, rec.t_ns)
