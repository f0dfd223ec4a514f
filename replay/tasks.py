"""Several controller plug-ins run as parallel tasks, each with its own rate, inputs and outputs:
the hierarchical parallel architecture of Namiki et al. 1999 (Figs. 1, 4), behind the one
:class:`~replay.interfaces.Controller` face the runner drives.

Each physics step k, the due tasks (``k % divider == 0``) run in the scenario's order. A task
receives the sensor messages and the other tasks' outputs on its ``inputs`` topics that arrived
since its last tick; a topic it publishes (``telemetry``) that is among its ``outputs`` reaches
the tasks listed after it in the same step and those before it at their next tick (a one-cycle
pipeline, like DSPs passing results through shared memory). Its command is a partial one (a
dataclass whose None fields leave an actuator alone, e.g. ``ServoCommand``); writing a field not
among its ``outputs`` is an error. The run's ``/tasks/loops`` topic records, every step, which
tasks ticked and each task's sensor-to-actuator **latency**: now minus the capture time ``t`` of
the oldest of the newest messages on its inputs (the data its command was computed from).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from replay.messages import TOPIC_TASK_LOOPS
from replay.interfaces import Controller, Occurrence


@dataclass
class TaskLoops:
    t: float
    names: list[str]
    ticked: list[bool]  # bool per task: ran this step
    latency: list[float | None]  # s per task (None before its inputs first arrived)
    oldest: list[str | None]  # per task: the input topic that latency is of


@dataclass
class Task:
    name: str
    controller: Controller
    divider: int
    inputs: frozenset
    outputs: frozenset


class TaskError(RuntimeError):
    pass


class TaskSet(Controller):
    description = "parallel tasks (scenario tasks:)"

    def __init__(self, tasks: list[Task], physics_rate: int) -> None:
        self.tasks = tasks
        self.rate = physics_rate
        self._inbox: dict[str, list] = {t.name: [] for t in tasks}
        self._newest: dict[str, dict[str, float]] = {t.name: {} for t in tasks}
        self._latency: dict[str, float | None] = {t.name: None for t in tasks}
        self._oldest: dict[str, str | None] = {t.name: None for t in tasks}
        self._ticked = [False] * len(tasks)
        self._telemetry: dict[str, list] = {}
        self._readers: dict[str, list[Task]] = {}
        for t in tasks:
            for topic in t.inputs:
                self._readers.setdefault(topic, []).append(t)
        self._fields: dict[type, tuple[str, ...]] = {}

    def _route(self, topic: str, payload: Any) -> None:
        readers = self._readers.get(topic)
        if not readers:
            return
        stamp = payload.get("t") if isinstance(payload, dict) else getattr(payload, "t", None)
        item = (topic, payload)
        for task in readers:
            self._inbox[task.name].append(item)
            if stamp is not None:
                self._newest[task.name][topic] = stamp

    def _check(self, task: Task, command: Any) -> None:
        cls = type(command)
        names = self._fields.get(cls)
        if names is None:
            names = self._fields[cls] = (
                tuple(f.name for f in dataclasses.fields(command))
                if dataclasses.is_dataclass(command)
                else ()
            )
        for n in names:
            if getattr(command, n) is not None and n not in task.outputs:
                raise TaskError(
                    f"task {task.name!r} wrote command field {n!r}, not among its "
                    f"outputs {sorted(task.outputs)}"
                )

    def update(self, t: float, measurements: list[tuple[str, Any]]) -> list | None:
        k = int(round(t * self.rate))
        for topic, m in measurements:
            self._route(topic, m)
        commands = []
        self._telemetry = {}
        for i, task in enumerate(self.tasks):
            due = k % task.divider == 0
            self._ticked[i] = due
            if not due:
                continue
            inbox, self._inbox[task.name] = self._inbox[task.name], []
            command = task.controller.update(t, inbox)
            newest = self._newest[task.name]
            if newest:
                stamp, topic = min((v, k) for k, v in newest.items())  # oldest, then by name
                self._latency[task.name] = t - stamp
                self._oldest[task.name] = topic
            if command is not None:
                self._check(task, command)
                commands.append(command)
            for topic, payload in task.controller.telemetry(t).items():
                items = payload if isinstance(payload, list) else [payload]
                self._telemetry.setdefault(topic, []).extend(items)
                if topic in task.outputs:
                    for item in items:
                        self._route(topic, item)
        return commands or None

    def telemetry(self, t: float) -> dict[str, Any]:
        out: dict[str, Any] = dict(self._telemetry)
        out[TOPIC_TASK_LOOPS] = TaskLoops(
            t,
            [x.name for x in self.tasks],
            list(self._ticked),
            [self._latency[x.name] for x in self.tasks],
            [self._oldest[x.name] for x in self.tasks],
        )
        return out

    def pop_events(self) -> list[Occurrence]:
        out = []
        for task in self.tasks:
            out.extend(task.controller.pop_events())
        return out

    def intent(self) -> dict:
        out = {}
        for task in self.tasks:
            out.update(task.controller.intent())
        return out

    def outcome(self, t: float) -> dict:
        """Every task's metrics; the first task that reports a failure gives the reason."""
        out: dict = {}
        failure = None
        for task in self.tasks:
            o = dict(task.controller.outcome(t) or {})
            ok = o.pop("success", True)
            reason = o.pop("reason", None)
            if ok is False and failure is None:
                failure = reason or f"task {task.name} reported a failure"
            out.update(o)
        if failure is not None:
            out["success"] = False
            out["reason"] = failure
        return out
