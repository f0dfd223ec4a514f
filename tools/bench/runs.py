"""``make bench``: speed of whole runs, measured so that it can be trusted on a shared machine.

For each benchmarked scenario, in one process: a warm-up run, then full runs (vision, controller
and full logging), at least ``--runs`` of them and more until they have taken ``--min-time`` CPU
seconds (a short scenario's five runs last half a second: one slow spell of a shared host would
be all of them; runs spread over seconds make the median the machine's usual speed), with a
fixed Python loop timed before each as a probe of the host's own speed; medians with min-max of
CPU time (``time.process_time``: what other users of the machine do not inflate much) and wall
time; the real-time factor (simulated seconds per second, CPU and wall); the CPU time per
simulated second; the ratio of a full run's CPU time to the bare engine's stepping the same scene
the same number of steps (Pymunk ``space.step``, PyBullet ``stepSimulation``, MuJoCo ``mj_step``, nothing else); the
share of each part of the loop (sensors, controller, plant, logging, runner: each plug-in call
timed from outside the runner, :func:`timed_run`); what a JSON message, a camera image, a 3-D frame and a /log line cost each (one more
run, each such call timed); whether the issue's target is met (#10; #24 for the MuJoCo twins); and, apart, the interpreter's
start-up and the imports a run needs. Nothing here is a test: it prints, it does not fail.
"""

from __future__ import annotations

import argparse
import platform
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from replay.foxglove.run import RunTopics
from replay.foxglove.topics import FoxgloveTopics
from replay.log import LogWriter
from replay.observers import LogObserver
from replay.resources import scenario_dir
from replay.runner import RunResult, Runner
from replay.scenario import ScenarioError, load_scenario

DEFAULT = [
    str(scenario_dir() / f"{name}.yaml")
    for name in (
        "stick_3step",
        "catch_optimised",
        "grasp_hexahedron",
        "catch_optimised_mujoco",
        "grasp_hexahedron_mujoco",
    )
]


# The parts of a run :func:`timed_run` times: sensors (measure); controller (update, pop_events,
# telemetry, intent); plant (scene, apply, truth, step, pop_events); logging (the log's observer
# of the step records: its writes and the Foxglove topics); runner (the rest: the loop itself,
# delivery, set-up, closing).
COMPONENTS = ("sensors", "controller", "plant", "logging", "runner")


def timed_run(runner: Runner, out: Path) -> tuple[RunResult, dict[str, float]]:
    """``runner.run(out)`` with the wall time of each part of the loop (``COMPONENTS``): every
    plug-in call and log write wrapped in a timer (only the outermost of nested ones counts),
    "runner" the rest of the run's wall time."""
    spent = dict.fromkeys(COMPONENTS, 0.0)
    depth, clock = [0], time.perf_counter

    def timed(part: str, fn):
        def wrapper(*args, **kw):
            if depth[0]:
                return fn(*args, **kw)
            depth[0] += 1
            c0 = clock()
            try:
                return fn(*args, **kw)
            finally:
                spent[part] += clock() - c0
                depth[0] -= 1

        return wrapper

    for attr in ("scene", "apply", "truth", "step", "pop_events"):
        setattr(runner.plant, attr, timed("plant", getattr(runner.plant, attr)))
    for _, sensor, _, _ in runner.sensors:
        sensor.measure = timed("sensors", sensor.measure)
    for attr in ("update", "pop_events", "telemetry", "intent"):
        setattr(runner.controller, attr, timed("controller", getattr(runner.controller, attr)))
    logged = [(LogWriter, "write"), (LogWriter, "write_all"), (LogObserver, "record")]
    logged += [(RunTopics, a) for a in ("start", "frame", "sensor", "event")]
    original = {(cls, attr): getattr(cls, attr) for cls, attr in logged}
    for (cls, attr), fn in original.items():
        setattr(cls, attr, timed("logging", fn))
    try:
        result = runner.run(out)
    finally:
        for (cls, attr), fn in original.items():
            setattr(cls, attr, fn)
    spent["runner"] = result.wall_time - sum(spent.values())
    return result, spent


def bare_stepper(runner: Runner):
    """(engine name, one bare engine step) of a fresh plant of the runner's scenario: no runner,
    sensors, control, logging or plant wrapper."""
    plant = type(runner.plant)(runner.sc.plant.params, dt=runner.dt, rng=runner.plant.rng)
    space = getattr(plant, "space", None)
    if space is not None and hasattr(space, "step"):  # Pymunk
        dt = plant.dt
        return "pymunk space.step", plant, lambda: space.step(dt)
    engine = getattr(plant, "engine", plant)  # the arm rig's engine adapter
    bc = getattr(engine, "bc", None)
    if bc is not None:  # PyBullet (a BulletClient)
        import pybullet as p

        client = bc._client
        return "pybullet stepSimulation", plant, lambda: p.stepSimulation(physicsClientId=client)
    mj, md = getattr(engine, "mj", None), getattr(engine, "md", None)
    if mj is not None and md is not None:  # MuJoCo (an MjModel and its MjData)
        import mujoco

        return "mujoco mj_step", plant, lambda: mujoco.mj_step(mj, md)
    return "plant.step (no bare engine found)", plant, plant.step


def engine_in_run(sc, out: Path) -> tuple[float, float, int]:
    """(CPU s of the whole run, CPU s inside the engine's own step, steps) of one run with the
    engine's step call timed: the engine's share of a real run, where contacts and motors make
    it work harder than bare stepping of the initial scene. The step is caught however the
    plant calls it: Pymunk's ``space.step``; PyBullet's through its ``BulletClient``
    (``bc.stepSimulation()``) or the module (``pybullet.stepSimulation(physicsClientId=...)``);
    MuJoCo's ``mujoco.mj_step2`` + ``mj_step1`` (the split step; steps counted by ``mj_step2``).
    A plant that reached the engine's step another way gives fewer steps than the run's."""
    runner = Runner(sc)
    plant, spent = runner.plant, [0.0, 0]
    clock = time.process_time

    def timed(step):
        def wrapper(*args, **kw):
            c0 = clock()
            out = step(*args, **kw)
            spent[0] += clock() - c0
            spent[1] += 1
            return out

        return wrapper

    engine = getattr(plant, "engine", plant)  # the arm rig's engine adapter
    space, bc = getattr(plant, "space", None), getattr(engine, "bc", None)
    restore = None
    if space is not None and hasattr(space, "step"):
        space.step = timed(space.step)
    elif bc is not None:
        import pybullet

        bc.stepSimulation = timed(bc.stepSimulation)
        original = pybullet.stepSimulation
        pybullet.stepSimulation = timed(original)

        def restore():
            pybullet.stepSimulation = original

    elif getattr(engine, "md", None) is not None:
        import mujoco

        originals = (mujoco.mj_step1, mujoco.mj_step2)

        def step1(*args):  # the second half of a step: its time counted, not a step of its own
            c0 = clock()
            originals[0](*args)
            spent[0] += clock() - c0

        mujoco.mj_step1, mujoco.mj_step2 = step1, timed(originals[1])

        def restore():
            mujoco.mj_step1, mujoco.mj_step2 = originals

    c0 = clock()
    try:
        runner.run(out)
    finally:
        if restore is not None:
            restore()
    return clock() - c0, spent[0], spent[1]


# what ``logging_costs`` times in a run: (name, class, method); the JSON messages, the camera
# frames (the sensor's frame_images, PNG, message), the 3-D frames (/tf, /scene, /joint_states
# with the plant's frames() and joints()), the Foxglove /log lines and opening and closing
LOGGED = (
    ("message", LogWriter, "write"),
    ("message", LogWriter, "write_all"),  # (a dict of them: counted by the log's count)
    ("image", RunTopics, "sensor"),
    ("frame", RunTopics, "frame"),
    ("log_line", RunTopics, "event"),
    ("open", LogWriter, "__init__"),
    ("close", LogWriter, "close"),
)


def _clock_cost(n: int = 20000) -> float:
    """CPU seconds two ``time.process_time`` readings cost (subtracted from each timed call)."""
    clock = time.process_time
    c0 = clock()
    for _ in range(n):
        clock()
        clock()
    return (clock() - c0) / n


def logging_costs(sc, out: Path) -> dict[str, tuple[float, int]]:
    """(CPU s, calls) of each of ``LOGGED`` in one run, each call timed by ``process_time`` less
    the timer's own cost; "image" counts the images written (a stereo frame is two), "message"
    the JSON messages (write's and write_all's, by the log's count)."""
    spent = {name: [0.0, 0] for name, _, _ in LOGGED}
    images = [0]
    clock, overhead = time.process_time, _clock_cost()
    original = {(cls, attr): getattr(cls, attr) for _, cls, attr in LOGGED}
    images_of = FoxgloveTopics.images  # (a sensor's frame: its views' images)

    def timed(name, fn):
        def wrapper(*args, **kw):
            c0 = clock()
            out = fn(*args, **kw)
            spent[name][0] += clock() - c0 - overhead
            spent[name][1] += 1
            return out

        return wrapper

    depth = [0]  # write_all calls write for what it leaves to Python: time and count it once

    def timed_messages(fn):
        def wrapper(log, *args, **kw):
            if depth[0]:
                return fn(log, *args, **kw)
            depth[0] += 1
            n0, c0 = log.count, clock()
            try:
                return fn(log, *args, **kw)
            finally:
                spent["message"][0] += clock() - c0 - overhead
                spent["message"][1] += log.count - n0
                depth[0] -= 1

        return wrapper

    def counted(self, sensor, frames, t_ns):
        frames = list(frames)
        images[0] += len(frames)
        return images_of(self, sensor, frames, t_ns)

    try:
        for name, cls, attr in LOGGED:
            fn = original[(cls, attr)]
            setattr(cls, attr, timed_messages(fn) if name == "message" else timed(name, fn))
        FoxgloveTopics.images = counted  # type: ignore[method-assign]
        Runner(sc).run(out)
    finally:
        for (cls, attr), fn in original.items():
            setattr(cls, attr, fn)
        FoxgloveTopics.images = images_of  # type: ignore[method-assign]
    result = {name: (max(v[0], 0.0), v[1]) for name, v in spent.items()}
    result["image"] = (result["image"][0], images[0])
    return result


def host_probe(n: int = 20000) -> float:
    """CPU seconds of a fixed pure-Python loop (~1-2 ms): timed before each run, its spread is
    how much the shared host's own speed swung while the runs were timed (the code is the same
    every time, so a slower loop is a slower machine, not slower code)."""
    c0 = time.process_time()
    s = 0
    for i in range(n):
        s += i * i
    return time.process_time() - c0


def interpreter() -> str:
    """Which Python runs the benchmark: its build matters as much as the code (pyenv's default
    build, with no PGO or LTO and a shared libpython, ran whole catch runs 10-25 % slower than
    Debian's own python3.11 here, the logs the same: ``make install PYTHON=...`` picks it)."""
    return f"interpreter: {sys.executable} (CPython {platform.python_version()})"


def _stats(values: list[float]) -> tuple[float, float, float]:
    return statistics.median(values), min(values), max(values)


def _startup(modules: list[str], repeat: int = 3) -> dict:
    """Median wall and CPU seconds of ``python -c pass`` and, beyond it, of the imports."""

    def child(code: str) -> tuple[float, float]:
        walls, cpus = [], []
        for _ in range(repeat):
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-c", code], check=True)
            walls.append(time.perf_counter() - t0)
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpus.append(r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)
        return statistics.median(walls), statistics.median(cpus)

    bare = child("pass")
    imp = child("import " + ", ".join(modules))
    return {"python": bare, "imports": (imp[0] - bare[0], imp[1] - bare[1])}


# the issues' targets (#10; #24 for the MuJoCo twins): real-time factor (simulated s per CPU s) of a full run
TARGETS = {
    "stick_3step": 10.0,
    "catch_optimised": 4.0,
    "grasp_hexahedron": 3.0,
    "catch_optimised_mujoco": 10.0,  # issue #24
    "grasp_hexahedron_mujoco": 5.0,  # issue #24
}
TARGET_ISSUE = {"catch_optimised_mujoco": "#24", "grasp_hexahedron_mujoco": "#24"}


# at most this many timed runs of a scenario, whatever ``min_time`` asks
MAX_RUNS = 200


def bench(
    path: str,
    runs: int = 5,
    startup: bool = True,
    optimiser: bool = True,
    min_time: float = 0.0,
) -> dict:
    """``runs`` timed runs at least, and more (up to ``MAX_RUNS``) until they took ``min_time``
    CPU seconds in all."""
    sc = load_scenario(path)
    cpu, wall, shares, result, runner = [], [], {c: [] for c in COMPONENTS}, None, None
    probes = []
    with tempfile.TemporaryDirectory() as tmp:
        i = 0
        while i <= runs or (sum(cpu) < min_time and i <= MAX_RUNS):
            runner = Runner(sc)  # run 0 warms up (imports, caches, files)
            probe = host_probe()
            c0, w0 = time.process_time(), time.perf_counter()
            result, times = timed_run(runner, Path(tmp) / f"run{i % 2}.mcap")
            c1, w1 = time.process_time(), time.perf_counter()
            i += 1
            if i == 1:
                continue
            probes.append(probe)
            cpu.append(c1 - c0)
            wall.append(w1 - w0)
            total = sum(times.values())
            for c in COMPONENTS:
                shares[c].append(times[c] / total)
        run_cpu, engine_cpu, engine_steps = engine_in_run(sc, Path(tmp) / "engine.mcap")
        logged = logging_costs(sc, Path(tmp) / "logging.mcap")
    engine, plant, step = bare_stepper(Runner(sc))
    bare = []
    for _ in range(max(runs, 3)):
        c0 = time.process_time()
        for _ in range(result.steps):
            step()
        bare.append(time.process_time() - c0)
    plant.close()
    out = {
        "scenario": sc.name,
        "sim_time": result.t_end,
        "steps": result.steps,
        "messages": result.messages,
        "runs": len(cpu),
        "capped": len(cpu) >= MAX_RUNS and sum(cpu) < min_time,  # min_time not reached
        "cpu": _stats(cpu),
        "wall": _stats(wall),
        "engine": engine,
        "bare": _stats(bare),
        "engine_in_run": (engine_cpu / run_cpu, engine_cpu / max(engine_steps, 1)),
        "engine_steps": engine_steps,
        "shares": {c: statistics.median(v) for c, v in shares.items()},
        "host": _stats(probes),
        "logged": logged,
    }
    for key in ("cpu", "wall"):  # (median, min, max) of simulated s per second
        med, lo, hi = out[key]
        out["rtf_" + key] = (result.t_end / med, result.t_end / hi, result.t_end / lo)
    out["ratio"] = out["cpu"][0] / out["bare"][0]
    if startup:
        modules = sorted(
            {
                type(runner.plant).__module__,
                type(runner.controller).__module__,
                *(type(s).__module__ for _, s, _, _ in runner.sensors),
                "replay.runner",
            }
        )
        out["startup"] = _startup(modules)
    out["optimiser"] = None
    problem = getattr(runner.controller, "problem", None)  # an offline optimisation (eq. 25)
    if optimiser and problem is not None and hasattr(problem, "solve"):
        c0, t0 = time.process_time(), time.perf_counter()
        solved = problem.solve()
        out["optimiser"] = (
            time.process_time() - c0,
            time.perf_counter() - t0,
            len(solved.history) - 1,
        )
    return out


def _range(s: tuple[float, float, float], fmt: str) -> str:
    med, lo, hi = s
    return f"{med:{fmt}} ({lo:{fmt}}-{hi:{fmt}})"


def _engine_in_run(r: dict) -> str:
    share, per_step = r["engine_in_run"]
    if r["engine_steps"] != r["steps"]:
        return (
            f"inside a run the engine's step was seen {r['engine_steps']} times in "
            f"{r['steps']} steps (the plant reaches it another way): not measured"
        )
    return (
        f"inside a run the engine takes {1e6 * per_step:.1f} us a step, {100 * share:.1f} % "
        "of the run's CPU (contacts, motors)"
    )


def _logging_line(r: dict) -> str:
    """What each kind of logged item costs (CPU, one instrumented run) and how often."""
    sim, logged = r["sim_time"], r["logged"]
    parts = []
    for name, label in (
        ("message", "JSON message"),
        ("image", "camera image"),
        ("frame", "3-D frame (/tf, /scene, /joint_states)"),
        ("log_line", "/log line"),
    ):
        cpu, n = logged[name]
        if n:
            parts.append(
                f"{label} {1e6 * cpu / n:.1f} us x {n / sim:.0f}/s = {1e3 * cpu / sim:.1f} ms/s"
            )
    opened = logged["open"][0] + logged["close"][0]
    return (
        "logging, CPU per item (one run, each call timed): "
        + "; ".join(parts)
        + f"; opening and closing the log {1e3 * opened:.1f} ms a run"
    )


def report(r: dict) -> str:
    sim = r["sim_time"]
    lines = [
        f"{r['scenario']}: {sim:.3f} s simulated, {r['steps']} physics steps, "
        f"{r['messages']} log messages; median (min-max) of {r['runs']} runs after a warm-up"
        + (f" (stopped at {MAX_RUNS} runs before --min-time)" if r.get("capped") else ""),
        f"  CPU time:  {_range(r['cpu'], '.3f')} s = {r['cpu'][0] / sim:.3f} s per simulated s; "
        f"real-time factor {_range(r['rtf_cpu'], '.1f')}x",
        f"  wall time: {_range(r['wall'], '.3f')} s; real-time factor "
        f"{_range(r['rtf_wall'], '.1f')}x (shared machine: wall is noisy)",
        f"  bare engine ({r['engine']}, same scene and steps): {_range(r['bare'], '.4f')} s CPU "
        f"= {1e6 * r['bare'][0] / max(r['steps'], 1):.1f} us a step; "
        f"full run / bare = {r['ratio']:.0f}x; " + _engine_in_run(r),
        "  where the time goes (runner's timers, share of the loop): "
        + ", ".join(f"{c} {100 * r['shares'][c]:.0f} %" for c in COMPONENTS)
        + "  ["
        + ", ".join(f"{c} {1e3 * r['shares'][c] * r['cpu'][0] / sim:.0f}" for c in COMPONENTS)
        + " ms CPU per simulated s; logging "
        + f"{1e6 * r['shares']['logging'] * r['cpu'][0] / max(r['messages'], 1):.1f} us a message]",
    ]
    if "logged" in r:
        lines.append("  " + _logging_line(r))
    if "host" in r:
        med, lo, hi = r["host"]
        lines.append(
            f"  host speed while timed: a fixed Python loop took {1e3 * med:.2f} "
            f"({1e3 * lo:.2f}-{1e3 * hi:.2f}) ms CPU before each run, {hi / lo:.2f}x apart (the "
            "same code each time: the machine's own swings, part of the runs' spread)"
        )
    target = TARGETS.get(r["scenario"])
    if target is not None:
        rtf = r["rtf_cpu"][0]
        short = 1.0 - rtf / target  # the share of the CPU time to save
        verdict = (
            "met"
            if rtf >= target
            else f"NOT met: needs {target / rtf:.2f}x less CPU ({100 * short:.0f} % less)"
        )
        issue = TARGET_ISSUE.get(r["scenario"], "#10")
        lines.append(
            f"  target (issue {issue}): >= {target:g}x real time (<= {1 / target:.3f} CPU s per "
            f"simulated s): {verdict} (median {rtf:.2f}x = {r['cpu'][0] / sim:.3f} CPU s per "
            "simulated s)"
        )
    if "startup" in r:
        (pw, pc), (iw, ic) = r["startup"]["python"], r["startup"]["imports"]
        lines.append(
            f"  not counted above: interpreter start-up {pw:.3f} s wall ({pc:.3f} s CPU),"
            f" imports {iw:.3f} s wall ({ic:.3f} s CPU)"
        )
    if r.get("optimiser") is not None:
        c, w, iterations = r["optimiser"]
        lines.append(
            f"  offline optimisation from scratch: {c:.2f} s CPU ({w:.2f} s wall), "
            f"{iterations} iterations (the runs read its result from a file)"
        )
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    ap.add_argument("--runs", type=int, default=5, help="timed runs after the warm-up, at least")
    ap.add_argument(
        "--min-time",
        type=float,
        default=3.0,
        help="CPU seconds the timed runs take at least (more runs until they do; default 3)",
    )
    ap.add_argument("--no-startup", action="store_true", help="skip the start-up timing")
    ap.add_argument(
        "--no-optimiser",
        action="store_true",
        help="skip timing an offline optimisation from scratch",
    )
    args = ap.parse_args(argv)
    if args.runs < 1:
        ap.error(f"--runs {args.runs}: at least 1 timed run")
    if not args.min_time >= 0.0:  # (NaN too)
        ap.error(f"--min-time {args.min_time}: CPU seconds, 0 or more")
    for path in args.scenarios:  # a bad path or scenario: its message, before any run
        try:
            load_scenario(path)
        except ScenarioError as exc:
            ap.error(str(exc))
    print(interpreter(), flush=True)
    for path in args.scenarios:
        print(
            report(
                bench(
                    path,
                    runs=args.runs,
                    startup=not args.no_startup,
                    optimiser=not args.no_optimiser,
                    min_time=args.min_time,
                )
            ),
            flush=True,
        )


if __name__ == "__main__":
    main()
