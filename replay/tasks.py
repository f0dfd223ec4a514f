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
        n = len(tasks)
        # per task, by its index: the messages since its last tick, the newest capture time per
        # input topic, and the latency (and its topic) at its last tick
        self._inbox: list[list] = [[] for _ in tasks]
        self._newest: list[dict[str, float]] = [{} for _ in tasks]
        self._latency: list[float | None] = [None] * n
        self._oldest: list[str | None] = [None] * n
        self._ticked = [False] * n
        self._names = [t.name for t in tasks]
        self._telemetry: dict[str, Any] = {}
        # topic -> (index, newest stamps) of each task reading it
        self._readers: dict[str, list[tuple[int, dict[str, float]]]] = {}
        for i, t in enumerate(tasks):
            for topic in t.inputs:
                self._readers.setdefault(topic, []).append((i, self._newest[i]))
        # per (task, command type): the command fields the task may not write
        self._forbidden: dict[tuple[int, type], tuple[str, ...]] = {}
        # what a step needs of each task, looked up once
        self._loop = [
            (
                i,
                t,
                t.divider,
                t.controller.update,
                t.controller.telemetry,
                t.outputs,
                self._newest[i],
            )
            for i, t in enumerate(tasks)
        ]

    def _route(self, topic: str, payload: Any) -> None:
        readers = self._readers.get(topic)
        if not readers:
            return
        stamp = payload.get("t") if isinstance(payload, dict) else getattr(payload, "t", None)
        item = (topic, payload)
        inbox = self._inbox
        for i, newest in readers:
            inbox[i].append(item)
            if stamp is not None:
                newest[topic] = stamp

    def _check(self, i: int, task: Task, command: Any) -> None:
        key = (i, type(command))
        names = self._forbidden.get(key)
        if names is None:
            fields = (
                tuple(f.name for f in dataclasses.fields(command))
                if dataclasses.is_dataclass(command)
                else ()
            )
            names = self._forbidden[key] = tuple(n for n in fields if n not in task.outputs)
        for n in names:
            if getattr(command, n) is not None:
                raise TaskError(
                    f"task {task.name!r} wrote command field {n!r}, not among its "
                    f"outputs {sorted(task.outputs)}"
                )

    def update(self, t: float, measurements: list[tuple[str, Any]]) -> list | None:
        k = int(round(t * self.rate))
        inboxes, ticked, latency, oldest = self._inbox, self._ticked, self._latency, self._oldest
        readers_of = self._readers
        for topic, m in measurements:  # _route, inline: the sensors' messages of this step
            readers = readers_of.get(topic)
            if readers:
                stamp = m.get("t") if isinstance(m, dict) else getattr(m, "t", None)
                item = (topic, m)
                for i, newest in readers:
                    inboxes[i].append(item)
                    if stamp is not None:
                        newest[topic] = stamp
        route = self._route
        commands = []
        out: dict[str, Any] = {}
        self._telemetry = out
        forbidden = self._forbidden
        for i, task, divider, update, telemetry, outputs, newest in self._loop:
            due = k % divider == 0
            ticked[i] = due
            if not due:
                continue
            inbox = inboxes[i]
            inboxes[i] = []
            command = update(t, inbox)
            if newest:
                stamp, topic = min(zip(newest.values(), newest.keys()))  # oldest, then by name
                latency[i] = t - stamp
                oldest[i] = topic
            if command is not None:
                names = forbidden.get((i, type(command)))
                if names is None or names:
                    self._check(i, task, command)
                commands.append(command)
            for topic, payload in telemetry(t).items():
                prev = out.get(topic)
                if prev is None:
                    out[topic] = payload
                else:  # several tasks (or ticks) on one topic: a list, in order
                    items = prev if isinstance(prev, list) else [prev]
                    out[topic] = items + (payload if isinstance(payload, list) else [payload])
                if topic in outputs:
                    if isinstance(payload, list):
                        for item in payload:
                            route(topic, item)
                    else:
                        route(topic, payload)
        return commands or None

    def telemetry(self, t: float) -> dict[str, Any]:
        out: dict[str, Any] = dict(self._telemetry)
        out[TOPIC_TASK_LOOPS] = TaskLoops(
            t, list(self._names), list(self._ticked), list(self._latency), list(self._oldest)
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
