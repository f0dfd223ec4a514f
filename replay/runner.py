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

import heapq
import platform
import subprocess
import time
from dataclasses import dataclass, field
from importlib import metadata as importlib_metadata
from pathlib import Path
from typing import Callable

import numpy as np

from replay import __version__, registry
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


# The parts of a run timed by the runner itself (perf_counter around each call: ~0.1 us a call),
# so `make bench` shows where the time goes without a profiler.
COMPONENTS = ("sensors", "controller", "plant", "logging", "runner")


def _git_commit() -> str:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "--short=12", "HEAD"],
            capture_output=True,
            text=True,
            timeout=5,
            cwd=Path(__file__).resolve().parent,
        )
        return out.stdout.strip() if out.returncode == 0 else ""
    except (OSError, subprocess.SubprocessError):
        return ""


def provenance(sc: Scenario, commit: str) -> dict[str, str]:
    info = {
        "scenario": sc.name,
        "paper": sc.paper,
        "seed": str(sc.seed),
        "paper-replay": __version__,
        "python": platform.python_version(),
        "git_commit": commit,
    }
    for pkg in ("numpy", "pymunk", "pybullet", "opencv-python-headless", "mcap"):
        try:
            info[pkg] = importlib_metadata.version(pkg)
        except importlib_metadata.PackageNotFoundError:
            pass
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
        # (deliver at step, sequence, topic, payload): a heap, so readings reach the controller in
        # time order whatever the sensors' order and latencies
        pending: list = []
        seq = 0
        stop_at: int | None = None
        collisions = 0
        k = 0
        clock = time.perf_counter
        t_sensors = t_controller = t_plant = 0.0
        self._t_log = 0.0
        try:
            while k < n_steps and (stop_at is None or k < stop_at):
                t = k / rate
                t_ns = self.t_ns(k)
                scene = None
                for name, sensor, div, latency in self.sensors:
                    if k % div == 0:
                        c0 = clock()
                        if scene is None:
                            scene = self.plant.scene()
                            c1 = clock()
                            t_plant += c1 - c0
                            c0 = c1
                        m = sensor.measure(t, scene)
                        t_sensors += clock() - c0
                        if name in viz.imaging:
                            c0 = clock()
                            viz.sensor(name, sensor, t_ns)
                            self._t_log += clock() - c0
                        if m is not None:
                            self._write(log, sensor.topic, m, t_ns)
                            heapq.heappush(pending, (k + latency, seq, sensor.topic, m))
                            seq += 1
                if k % self.ctrl_div == 0:
                    delivered = []
                    while pending and pending[0][0] <= k:
                        _, _, topic, m = heapq.heappop(pending)
                        delivered.append((topic, m))
                    c0 = clock()
                    command = self.controller.update(t, delivered)
                    c1 = clock()
                    t_controller += c1 - c0
                    if isinstance(command, list):  # parallel tasks' partial commands
                        for c in command:
                            self.plant.apply(c)
                        t_plant += clock() - c1
                    elif command is not None:
                        self.plant.apply(command)
                        t_plant += clock() - c1
                    for occ in self.controller.pop_events():
                        stop_at = self._event(log, occ, t, t_ns, result, stop_at, k)
                    c0 = clock()
                    telemetry = self.controller.telemetry(t)
                    t_controller += clock() - c0
                    for topic, payload in telemetry.items():
                        for item in payload if isinstance(payload, list) else [payload]:
                            self._write(log, topic, item, t_ns)
                c0 = clock()
                if k % self.log_div == 0:
                    truth = self.plant.truth(t)
                    c1 = clock()
                    t_plant += c1 - c0
                    for topic, payload in truth.items():
                        self._write(log, topic, payload, t_ns)
                    c0 = clock()
                if self.frame_div and k % self.frame_div == 0:
                    self._frame(scene, t_ns)
                    c0 = clock()
                self.plant.step()
                t_plant += clock() - c0
                k += 1
                t1, t1_ns = k / rate, self.t_ns(k)
                for occ in self.plant.pop_events():
                    if occ.kind == "collision":
                        collisions += 1
                        occ.data = {
                            "index": collisions,
                            **occ.data,
                            "planned": self.controller.intent(),
                        }
                    stop_at = self._event(log, occ, t1, t1_ns, result, stop_at, k)
                if self.progress and k % max(1, rate // 20) == 0:
                    self.progress(t1, sc.timing.duration)
            # the final state, so the log ends where the run ended
            t_end = k / rate
            for topic, payload in self.plant.truth(t_end).items():
                self._write(log, topic, payload, self.t_ns(k))
            if self.frame_div:
                self._frame(None, self.t_ns(k))
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

    def _frame(self, scene, t_ns: int) -> None:
        """The 3-D viewer topics now (``scene``: this step's, if a camera already asked)."""
        c0 = time.perf_counter()
        assert self.viz is not None
        self.viz.frame(scene if scene is not None else self.plant.scene(), t_ns)
        self._t_log += time.perf_counter() - c0

    def _write(self, log: LogWriter, topic: str, payload, t_ns: int) -> None:
        c0 = time.perf_counter()
        log.write(topic, payload, t_ns)
        if topic == TOPIC_EVENTS and self.viz is not None:
            self.viz.event(payload, t_ns)
        for observe in self.observers:
            observe(topic, payload, t_ns)
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
