"""The fixed-step, multi-rate runner: the only place where a plant, its sensors and a controller meet.

Time is an integer count of physics steps k (t = k / physics_rate), so rates never drift. Each
step: cameras due at k capture the plant's scene (logged at the capture time, delivered to the
controller ``latency`` later), the controller due at k reads what was delivered and commands the
plant (or, with ``tasks:``, each due task reads its inputs and writes its part of the command:
``replay.tasks``), the plant's state is logged, the plant steps, and the physics events of that step are
logged at its end, collisions with the controller's intent attached. What a step makes is one
record handed once to the run's observers (``replay.observers``: the log, a live viewer's
callables). The run stops at
``timing.duration`` or ``stop.after`` seconds after one of ``stop.on_events``.

``Runner(scenario).run(out)`` is the whole run; it is :meth:`Runner.start`, :meth:`Runner.step`
until :attr:`Runner.done`, then :meth:`Runner.finish`, which a caller may drive itself.
"""

from __future__ import annotations

import functools
import os
import heapq
import platform
import time
from dataclasses import dataclass, field
from importlib import metadata as importlib_metadata
from pathlib import Path
from typing import Any, Callable

import numpy as np

from replay import __version__, registry, version
from replay.foxglove.run import RunTopics
from replay.log import LogWriter, NonFiniteValueError
from replay.log.memory import KeptLog
from replay.log.unwritten import UnwrittenLog
from replay.messages import TOPIC_EVENTS, Event, ScenarioInfo
from replay.observers import Capture, LogObserver, MessageObserver, RunObserver, StepRecord
from replay.scenario import Scenario, resolved_yaml
from replay.scenario.schema import LogSpec
from replay.tasks import Task, TaskSet


class RunInterrupted(Exception):
    """Ctrl-C during a run; the log was closed and kept."""

    def __init__(self, result: "RunResult"):
        self.result = result
        super().__init__(f"interrupted at t = {result.t_end:.4f} s")


@dataclass
class RunResult:
    path: Path
    steps: int = 0
    t_end: float = 0.0
    stopped_by: str = "duration"  # duration | event kind | error | interrupted
    events: dict = field(default_factory=dict)
    messages: int = 0
    wall_time: float = 0.0
    error: str = ""
    outcome: dict = field(default_factory=dict)  # the final ``outcome`` event's data


_git_commit = version.commit  # from git in a checkout, from the build in a wheel


@functools.cache  # once a process (~3 ms of package metadata reads)
def _versions() -> tuple[tuple[str, str], ...]:
    found = []
    for pkg in (
        "numpy",
        "pymunk",
        "pybullet",
        "mujoco",
        "drake",
        "opencv-python-headless",
        "mcap",
        "foxglove-sdk",  # (the log's writer)
    ):
        try:
            found.append((pkg, importlib_metadata.version(pkg)))
        except importlib_metadata.PackageNotFoundError:
            pass
    return tuple(found)


def provenance(sc: Scenario, commit: str) -> dict[str, str]:
    info = {
        "scenario": sc.name,
        "paper": sc.paper,
        "seed": str(sc.seed),
        "paper-replay": __version__,
        "python": platform.python_version(),
        "git_commit": commit,
    }
    info.update(_versions())
    return info


def _divider(physics_rate: int, rate: float) -> int:
    return max(1, int(round(physics_rate / rate)))


class Runner:
    watchers: list[RunObserver]  # who is handed each step's record, from start()

    def __init__(
        self,
        scenario: Scenario,
        *,
        progress: Callable[[float, float], None] | None = None,
        observers: tuple = (),
    ) -> None:
        self.sc = scenario
        self.progress = progress
        self.observers = observers  # callables(topic, payload, t_ns) — e.g. a live viewer
        self.rate = rate = scenario.timing.physics_rate
        self.dt = 1.0 / rate
        seeds = np.random.SeedSequence(scenario.seed).spawn(2 + len(scenario.sensors))
        plant_cls = registry.load("plant", scenario.plant.type)
        self.plant = plant_cls(
            scenario.plant.params, dt=self.dt, rng=np.random.default_rng(seeds[0])
        )
        spec = self.plant.spec()
        self.sensors = []
        for i, (name, s) in enumerate(scenario.sensors.items()):
            cls = registry.load("sensor", s.type)
            sensor = cls(s.params, rng=np.random.default_rng(seeds[2 + i]), spec=spec)
            self.sensors.append(
                (name, sensor, _divider(rate, s.rate), int(round(s.latency * rate)))
            )
        if scenario.tasks:  # the method as parallel tasks (replay/tasks.py)
            self.controller = TaskSet(
                [
                    Task(
                        name,
                        registry.load("controller", ts.type)(ts.params, spec=spec),
                        _divider(rate, ts.rate),
                        frozenset(ts.inputs),
                        frozenset(ts.outputs),
                    )
                    for name, ts in scenario.tasks.items()
                ],
                rate,
            )
            self.ctrl_div = 1
        else:
            cs = scenario.controller
            assert cs is not None  # the loader requires controller: or tasks:
            ctrl_cls = registry.load("controller", cs.type)
            self.controller = ctrl_cls(cs.params, spec=spec)
            self.ctrl_div = _divider(rate, cs.rate)
        self.log_div = (
            _divider(rate, scenario.timing.state_log_rate) if scenario.timing.state_log_rate else 1
        )
        fr = scenario.timing.frame_rate  # the 3-D viewer topics (replay/foxglove)
        self.frame_div = _divider(rate, fr) if fr else 0
        self.level = level = scenario.log or LogSpec()  # what the log holds (scenario ``log:``)
        self.image_div = 1  # steps between a camera's logged images (at least its captures')
        if level.level == "decimated":
            self.log_div = max(self.log_div, _divider(rate, level.state_rate))
            self.image_div = _divider(rate, level.image_rate)
            self.frame_div = max(self.frame_div, self.image_div) if self.frame_div else 0

    def t_ns(self, k: int) -> int:
        return k * 1_000_000_000 // self.sc.timing.physics_rate

    # -- the run, step by step: start(out), step() until done, finish() ----------------------

    def run(self, out: str | Path | None, *, keep: bool = False) -> RunResult:
        """The whole run into the log ``out`` (None: no log, the outcome and events alike;
        with ``keep`` its messages kept in memory instead, read as a log's through
        ``self.log.reader()``): :meth:`start`, :meth:`step` until :attr:`done`, :meth:`finish`.
        Ctrl-C closes the log (kept) and raises :class:`RunInterrupted`."""
        self.start(out, keep=keep)
        progress_div = max(1, self.rate // 20)
        try:
            while not self.done:
                self.step()
                if self.progress and self.k % progress_div == 0:
                    self.progress(self.k / self.rate, self.sc.timing.duration)
            return self.finish()
        except NonFiniteValueError as exc:
            return self.fail(exc)
        except KeyboardInterrupt:
            raise RunInterrupted(self.interrupt()) from None
        except BaseException:
            self.plant.close()
            raise

    def start(self, out: str | Path | None, *, keep: bool = False) -> None:
        """Open the log ``out`` (None: none; with ``keep``, the messages kept in memory: a
        :class:`~replay.log.memory.KeptLog`) and write what a run starts with (its provenance,
        the resolved scenario, the robot's description); the run is at step 0."""
        sc = self.sc
        self.result = RunResult(path=Path(out if out is not None else os.devnull))
        self._wall0 = time.perf_counter()
        self.k = 0
        self._n_steps = int(round(sc.timing.duration * self.rate))
        self._stop_at: int | None = None
        self._collisions = 0
        self._nan: dict | None = None  # a ``nan`` event's data, until the run ends on it
        self._seq = 0
        # (deliver at step, sequence, topic, payload), delivered in that order whatever the
        # sensors' order and latencies
        self._pending: list = []
        self._sensed: tuple = (-1, None, [])  # (k, scene, delivered) of sense() at step k
        log = self.log = (
            LogWriter(out) if out is not None else KeptLog() if keep else UnwrittenLog()
        )
        commit = _git_commit() or "unknown"
        log.metadata("provenance", provenance(sc, commit))
        text = resolved_yaml(sc)
        log.metadata("scenario", {"yaml": text})
        version = f"{__version__}+{commit}"
        outcome_only = self.level.level == "outcome"
        # the measurements, telemetry and state: logged, or (outcome only) checked and dropped
        data = UnwrittenLog() if outcome_only else log
        self._image_at = dict.fromkeys((s[0] for s in self.sensors), 0)  # next image's step
        topics = (
            RunTopics(log, self.plant, [(s[0], s[1]) for s in self.sensors])
            if out is not None and not outcome_only
            else None
        )
        self._frames = topics is not None  # (a scene only for topics that draw it)
        self.watchers = [LogObserver(log, data, topics)]
        if self.observers:
            self.watchers.append(MessageObserver(tuple(self.observers)))
        self._record = StepRecord(0, 0)
        info = ScenarioInfo(0.0, sc.name, sc.paper, text, sc.seed, version)
        for watcher in self.watchers:
            watcher.start(info)

    @property
    def done(self) -> bool:
        """The run's duration is over, or ``stop.after`` seconds after a stopping event."""
        return self.k >= self._n_steps or (self._stop_at is not None and self.k >= self._stop_at)

    def sense(self) -> list:
        """The first part of step k: the sensors due capture the scene (logged now, delivered
        ``latency`` later); at a control step, the measurements delivered by now, which the
        controller reads (``[(topic, payload)]``), else []. :meth:`step` calls it if not done."""
        k = self.k
        t = k / self.rate
        scene = None
        captures = self._record.captures
        for name, sensor, div, latency in self.sensors:
            if k % div:
                continue
            if scene is None:
                scene = self.plant.scene()
            m = sensor.measure(t, scene)
            image = k >= self._image_at[name]  # its frame drawn (Foxglove / Rerun)
            if image:
                self._image_at[name] = k + self.image_div
            captures.append(Capture(name, sensor, sensor.topic, m, image))
            if m is not None:
                heapq.heappush(self._pending, (k + latency, self._seq, sensor.topic, m))
                self._seq += 1
        delivered, pending = [], self._pending
        if k % self.ctrl_div == 0:
            while pending and pending[0][0] <= k:
                _, _, topic, m = heapq.heappop(pending)
                delivered.append((topic, m))
        self._sensed = (k, scene, delivered)
        return delivered

    def step(self, command: Any = None) -> None:
        """One physics step k: :meth:`sense`, then at a control step the controller reads what
        was delivered and commands the plant (``command`` given: that command instead of the
        controller's, which is not asked; the rest is the same), the plant's state is logged,
        the plant steps, and its events are logged at the step's end (a collision with the
        controller's intent)."""
        k, plant = self.k, self.plant
        t = k / self.rate
        if self._sensed[0] != k:
            self.sense()
        _, scene, delivered = self._sensed
        rec = self._record
        if k % self.ctrl_div == 0:
            self._control(t, delivered, command)
        if k % self.log_div == 0:
            rec.state = plant.truth(t)
        if self._frames and self.frame_div and k % self.frame_div == 0:  # the 3-D topics
            rec.scene = scene if scene is not None else plant.scene()
        self._hand()  # the step's record, once
        plant.step()
        self.k = k = k + 1
        for occ in plant.pop_events():  # the next record's first messages, at the step's end
            if occ.kind == "collision":
                self._collisions += 1
                occ.data = {
                    "index": self._collisions,
                    **occ.data,
                    "planned": self.controller.intent(),
                }
            self._event(occ, self._record.events)
        self._check_nan()

    def _control(self, t: float, delivered: list, command: Any = None) -> None:
        """The controller's turn: what the sensors delivered by now in, the command out (or
        the ``command`` given from outside)."""
        if command is None:
            command = self.controller.update(t, delivered)
        if isinstance(command, list):  # parallel tasks' partial commands
            for c in command:
                self.plant.apply(c)
        elif command is not None:
            self.plant.apply(command)
        occurrences = self.controller.pop_events()
        telemetry = self.controller.telemetry(t)
        for occ in occurrences:
            self._event(occ, self._record.control)
        self._check_nan()
        if telemetry:
            self._record.telemetry = telemetry

    def finish(self) -> RunResult:
        """The final state (so the log ends where the run ended), the ``outcome`` event, the
        log closed; the run's result."""
        rec, t = self._record, self.k / self.rate
        rec.state = self.plant.truth(t)
        if self._frames and self.frame_div:
            rec.scene = self.plant.scene()
        self._hand()
        self._outcome(self._verdict(t))
        return self._finish()

    def fail(self, exc: NonFiniteValueError) -> RunResult:
        """End the run at a non-finite value on a topic (what :meth:`step` raised): an
        ``error`` event and a failed outcome."""
        self.result.stopped_by = "error"
        self.result.error = str(exc)
        data = {"reason": "non-finite value", "topic": exc.topic, "fields": exc.fields}
        self._hand([Event(self.k / self.rate, "error", data)])
        reason = f"error: non-finite value on {exc.topic}"
        self._outcome({"success": False, "reason": reason})
        return self._finish()

    def interrupt(self) -> RunResult:
        """End the run here as interrupted (Ctrl-C, or an environment's episode left before its
        end): an ``interrupted`` event, a failed outcome, the log kept as interrupted."""
        self.result.stopped_by = "interrupted"
        self._hand([Event(self.k / self.rate, "interrupted", {})])  # after what the step made
        self._outcome({"success": False, "reason": "interrupted"})
        return self._finish()

    def _verdict(self, t: float) -> dict:
        """The plant's physical verdict, with the method's metrics and its own failure reason."""
        verdict = {"success": True, "reason": "completed"}
        verdict.update(self.plant.outcome(t) or {})
        method = dict(self.controller.outcome(t) or {})
        failed = method.pop("success", True) is False
        reason = method.pop("reason", None)
        verdict.update(method)
        if failed and verdict["success"]:
            verdict["success"] = False
            verdict["reason"] = reason or "the method reported a failure"
        return verdict

    def _outcome(self, verdict: dict) -> None:
        """Every run ends with one ``outcome`` event: the one place a user or a sweep reads it."""
        self.result.outcome = verdict
        self._hand([Event(self.k / self.rate, "outcome", verdict)])

    def _finish(self) -> RunResult:
        result, k = self.result, self.k
        self.plant.close()
        result.steps = k
        result.t_end = k / self.rate
        result.messages = self.log.count
        # a failed or interrupted run never replaces a finished log at ``out``: NAME.failed.mcap
        result.path = self.log.close(
            {"error": "failed", "interrupted": "interrupted"}.get(result.stopped_by, "")
        )
        result.wall_time = time.perf_counter() - self._wall0
        return result

    def _hand(self, events: list[Event] | None = None) -> None:
        """The record of step k now to every watcher, once; the next one begun. ``events``: the
        record under way, then one of only these events."""
        if events is not None:
            self._hand()
            self._record.events = events
        rec, self._record = self._record, StepRecord(0, 0)
        rec.k = k = self.k
        rec.t_ns = k * 1_000_000_000 // self.rate  # (self.t_ns(k))
        for watcher in self.watchers:
            watcher.record(rec)

    def _event(self, occ, into: list[Event]) -> None:
        """An occurrence of the plant or the method, an event of the record under way (``into``
        its list); a stopping one sets the run to end ``stop.after`` seconds later."""
        if self._nan is not None:
            return  # (the run ends at the first non-finite value)
        into.append(Event(self.k / self.rate, occ.kind, occ.data))
        events = self.result.events
        events[occ.kind] = events.get(occ.kind, 0) + 1
        if occ.kind == "nan":
            self._nan = occ.data
        if self._stop_at is None and occ.kind in self.sc.stop.on_events:
            self.result.stopped_by = occ.kind
            self._stop_at = self.k + int(round(self.sc.stop.after * self.rate))

    def _check_nan(self) -> None:
        """A ``nan`` event (the plant's or the method's) ends the run now: its record handed
        (what the step made until then), a :class:`NonFiniteValueError` raised."""
        if self._nan is not None:
            data, self._nan = self._nan, None
            self._hand()
            said = data.get("fields")  # (the air table's names them; the arm rig's the step)
            named = [str(f) for f in said] if isinstance(said, list) and said else []
            step = data.get("step", "?")
            raise NonFiniteValueError(
                TOPIC_EVENTS, data, named or [f"the simulation diverged at step {step}"]
            )
