"""The fixed-step, multi-rate runner: the only place where a plant, its sensors and a controller meet.

Time is an integer count of physics steps k (t = k / physics_rate), so rates never drift. Each
step: cameras due at k capture the plant's scene (logged at the capture time, delivered to the
controller ``latency`` later), the controller due at k reads what was delivered and commands the
plant (or, with ``tasks:``, each due task reads its inputs and writes its part of the command:
``replay.tasks``), the plant's state is logged, the plant steps, and the physics events of that step are
logged at its end, collisions with the controller's intent attached. The run stops at
``timing.duration`` or ``stop.after`` seconds after one of ``stop.on_events``.
"""

from __future__ import annotations

import collections
import functools
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
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO, Event, ScenarioInfo
from replay.scenario import Scenario, resolved_yaml
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
    # wall seconds spent in each part of the loop (COMPONENTS); "runner" is the rest of the run
    timings: dict = field(default_factory=dict)


# The parts of a run timed by the runner itself (perf_counter, one reading a part), so `make
# bench` shows where the time goes without a profiler: sensors (measure); controller (update,
# pop_events, telemetry, intent); plant (scene, apply, truth, step, pop_events); logging (log
# writes and observers); runner (the rest: the loop itself, delivery, set-up, closing the log).
COMPONENTS = ("sensors", "controller", "plant", "logging", "runner")


_git_commit = version.commit  # from git in a checkout, from the build in a wheel


@functools.cache  # once a process (~3 ms of package metadata reads)
def _versions() -> tuple[tuple[str, str], ...]:
    found = []
    for pkg in (
        "numpy",
        "pymunk",
        "pybullet",
        "mujoco",
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
    def __init__(
        self,
        scenario: Scenario,
        *,
        progress: Callable[[float, float], None] | None = None,
        observers: tuple = (),
    ) -> None:
        self.sc = scenario
        self.progress = progress
        self.observers = observers  # callables(topic, payload, t) — e.g. a live viewer
        rate = scenario.timing.physics_rate
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
        self.viz: RunTopics | None = None
        self._t_log = 0.0  # seconds in log writes (and observers) this run

    def t_ns(self, k: int) -> int:
        return k * 1_000_000_000 // self.sc.timing.physics_rate

    def run(self, out: str | Path) -> RunResult:
        sc = self.sc
        rate = sc.timing.physics_rate
        n_steps = int(round(sc.timing.duration * rate))
        result = RunResult(path=Path(out))
        wall0 = time.perf_counter()
        log = LogWriter(out)
        commit = _git_commit() or "unknown"
        log.metadata("provenance", provenance(sc, commit))
        text = resolved_yaml(sc)
        log.metadata("scenario", {"yaml": text})
        version = f"{__version__}+{commit}"
        self._write(
            log, TOPIC_SCENARIO, ScenarioInfo(0.0, sc.name, sc.paper, text, sc.seed, version), 0
        )
        viz = self.viz = RunTopics(log, self.plant, [(s[0], s[1]) for s in self.sensors])
        viz.start(0)
        seq = 0
        stop_at: int | None = None
        collisions = 0
        k = 0
        # The loop is the hot path (1-3 k steps and 4-22 k messages per simulated second): the
        # plug-ins' methods are bound once, and each part is timed by one clock reading at its
        # end (the start is the previous part's end), so timing a message costs one perf_counter.
        clock = time.perf_counter
        plant, controller = self.plant, self.controller
        scene_of, apply, truth_of, step = plant.scene, plant.apply, plant.truth, plant.step
        plant_events = plant.pop_events
        update, telemetry_of, controller_events = (
            controller.update,
            controller.telemetry,
            controller.pop_events,
        )
        write = self._emitter(log)
        write_all = self._emitter_all(log)
        sensors = [
            (s.measure, s.topic, div, latency, (name, s) if name in viz.imaging else None)
            for name, s, div, latency in self.sensors
        ]
        ctrl_div, log_div, n_ns = self.ctrl_div, self.log_div, 1_000_000_000
        frame_div = self.frame_div
        progress, progress_div = self.progress, max(1, rate // 20)
        # (deliver at step, sequence, topic, payload), delivered in that order whatever the
        # sensors' order and latencies: a heap; with one latency for all, readings are made in
        # delivery order, so a FIFO (half the cost of a heap's push and pop) is that order
        pending: Any
        if len({latency for _, _, _, latency, _ in sensors}) <= 1:
            pending = collections.deque()
            push, pop = pending.append, pending.popleft
        else:
            pending = []
            push = functools.partial(heapq.heappush, pending)
            pop = functools.partial(heapq.heappop, pending)
        t_sensors = t_controller = t_plant = 0.0
        self._t_log = 0.0
        t_log = 0.0
        try:
            while k < n_steps and (stop_at is None or k < stop_at):
                t = k / rate
                t_ns = k * n_ns // rate
                scene = None
                for measure, topic, div, latency, imaging in sensors:
                    if k % div == 0:
                        c0 = clock()
                        if scene is None:
                            scene = scene_of()
                            c1 = clock()
                            t_plant += c1 - c0
                            c0 = c1
                        m = measure(t, scene)
                        c1 = clock()
                        t_sensors += c1 - c0
                        if imaging is not None:  # its frame, for Foxglove / Rerun
                            viz.sensor(imaging[0], imaging[1], t_ns)
                            c0 = clock()
                            t_log += c0 - c1
                            c1 = c0
                        if m is not None:
                            write(topic, m, t_ns)
                            t_log += clock() - c1
                            push((k + latency, seq, topic, m))
                            seq += 1
                if k % ctrl_div == 0:
                    delivered = []
                    while pending and pending[0][0] <= k:
                        _, _, topic, m = pop()
                        delivered.append((topic, m))
                    c0 = clock()
                    command = update(t, delivered)
                    c1 = clock()
                    t_controller += c1 - c0
                    if command is not None:
                        if isinstance(command, list):  # parallel tasks' partial commands
                            for c in command:
                                apply(c)
                        else:
                            apply(command)
                        c0 = clock()
                        t_plant += c0 - c1
                        c1 = c0
                    occurrences = controller_events()
                    telemetry = telemetry_of(t)
                    c0 = clock()
                    t_controller += c0 - c1
                    if occurrences:
                        for occ in occurrences:
                            stop_at = self._event(log, occ, t, t_ns, result, stop_at, k)
                        c0 = clock()
                    if telemetry:
                        write_all(telemetry, t_ns)
                        t_log += clock() - c0
                c0 = clock()
                if k % log_div == 0:
                    truth = truth_of(t)
                    c1 = clock()
                    t_plant += c1 - c0
                    write_all(truth, t_ns)
                    c0 = clock()
                    t_log += c0 - c1
                if frame_div and k % frame_div == 0:  # the 3-D topics (replay/foxglove)
                    c1 = clock()
                    viz.frame(scene if scene is not None else scene_of(), t_ns)
                    c0 = clock()
                    t_log += c0 - c1
                step()
                k += 1
                occurrences = plant_events()
                t_plant += clock() - c0
                if occurrences:
                    t1, t1_ns = k / rate, k * n_ns // rate
                    for occ in occurrences:
                        if occ.kind == "collision":
                            collisions += 1
                            c0 = clock()
                            planned = controller.intent()
                            t_controller += clock() - c0
                            occ.data = {"index": collisions, **occ.data, "planned": planned}
                        stop_at = self._event(log, occ, t1, t1_ns, result, stop_at, k)
                if progress and k % progress_div == 0:
                    progress(k / rate, sc.timing.duration)
            # the final state, so the log ends where the run ended
            t_end = k / rate
            truth = self.plant.truth(t_end)
            c0 = clock()
            write_all(truth, self.t_ns(k))  # (as in the loop)
            t_log += clock() - c0
            if frame_div:
                viz.frame(self.plant.scene(), self.t_ns(k))
            self._outcome(log, result, k, self._verdict(k / rate))
        except NonFiniteValueError as exc:
            result.stopped_by = "error"
            result.error = str(exc)
            self._write(
                log,
                TOPIC_EVENTS,
                Event(
                    k / rate,
                    "error",
                    {"reason": "non-finite value", "topic": exc.topic, "fields": exc.fields},
                ),
                self.t_ns(k),
            )
            self._outcome(
                log,
                result,
                k,
                {"success": False, "reason": f"error: non-finite value on {exc.topic}"},
            )
        except KeyboardInterrupt:
            result.stopped_by = "interrupted"
            self._write(log, TOPIC_EVENTS, Event(k / rate, "interrupted", {}), self.t_ns(k))
            self._outcome(log, result, k, {"success": False, "reason": "interrupted"})
            self._finish(log, result, k, wall0)
            raise RunInterrupted(result) from None
        finally:
            self._t_log += t_log
            self.plant.close()
        self._finish(log, result, k, wall0)
        result.timings = {
            "sensors": t_sensors,
            "controller": t_controller,
            "plant": t_plant,
            "logging": self._t_log,
        }
        result.timings["runner"] = result.wall_time - sum(result.timings.values())
        return result

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

    def _outcome(self, log: LogWriter, result: RunResult, k: int, verdict: dict) -> None:
        """Every run ends with one ``outcome`` event: the one place a user or a sweep reads it."""
        result.outcome = verdict
        self._write(
            log,
            TOPIC_EVENTS,
            Event(k / self.sc.timing.physics_rate, "outcome", verdict),
            self.t_ns(k),
        )

    def _finish(self, log: LogWriter, result: RunResult, k: int, wall0: float) -> None:
        result.steps = k
        result.t_end = k / self.sc.timing.physics_rate
        result.messages = log.count
        # a failed or interrupted run never replaces a finished log at ``out``: NAME.failed.mcap
        result.path = log.close(
            {"error": "failed", "interrupted": "interrupted"}.get(result.stopped_by, "")
        )
        result.wall_time = time.perf_counter() - wall0

    def _emitter(self, log: LogWriter) -> Callable[[str, object, int], None]:
        """``write(topic, payload, t_ns)``: the log's own write, and the observers' after it."""
        if not self.observers:
            return log.write
        observers = self.observers

        def write(topic: str, payload, t_ns: int) -> None:
            log.write(topic, payload, t_ns)
            for observe in observers:
                observe(topic, payload, t_ns)

        return write

    def _emitter_all(self, log: LogWriter) -> Callable[[dict, int], None]:
        """``write_all(messages, t_ns)``: each (topic, payload) of a dict written, a list payload
        as its items' messages; the log's own compiled write_all without observers."""
        if not self.observers:
            return log.write_all
        write = self._emitter(log)

        def write_all(messages: dict, t_ns: int) -> None:
            for topic, payload in messages.items():
                for item in payload if isinstance(payload, list) else (payload,):
                    write(topic, item, t_ns)

        return write_all

    def _write(self, log: LogWriter, topic: str, payload, t_ns: int) -> None:
        """A message outside the loop's hot path (scenario, events, outcome), timed as logging."""
        c0 = time.perf_counter()
        self._emitter(log)(topic, payload, t_ns)
        if topic == TOPIC_EVENTS and self.viz is not None:
            self.viz.event(payload, t_ns)  # its /log line
        self._t_log += time.perf_counter() - c0

    def _event(self, log, occ, t, t_ns, result, stop_at, k):
        self._write(log, TOPIC_EVENTS, Event(t, occ.kind, occ.data), t_ns)
        result.events[occ.kind] = result.events.get(occ.kind, 0) + 1
        if occ.kind == "nan":
            raise NonFiniteValueError(TOPIC_EVENTS, occ.data)
        if stop_at is None and occ.kind in self.sc.stop.on_events:
            result.stopped_by = occ.kind
            stop_at = k + int(round(self.sc.stop.after * self.sc.timing.physics_rate))
        return stop_at
