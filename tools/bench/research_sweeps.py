"""``make bench`` (research workloads, issue #41): what a robustness sweep costs, against a single
full-log ``replay run`` of the same scenario and against the bare engine.

Three workloads, each a ``--no-logs`` sweep with 2 local workers into a fresh folder:

- catch_optimised over N perturbed throws (``analysis.catching.throws.perturbed_throws(N,
  spread=0.1)``, the throws of sweeps/catch_rate.yaml's neighbourhood), 0.45 s each, stopped at
  the catch or miss (catch_rate's settings);
- grasp_hexahedron over N human paths (the run's seed draws the human hand's path), each
  ``GRASP_DURATION`` s simulated, shorter than the scenario's 2.0 s (tracking, reach and grasp
  end by 0.8 s; the rest is the hold): that keeps the bench to about a minute;
- stick_3step over N seeded random throws (``plant.params.throw.random``), 2.0 s each (a run
  stops at the capture).

For each: the first variant run in this process with a full log, and without one (medians of
``RUNS`` after a warm-up run: imports and caches paid; interpreter start-up excluded, the plant's
set-up included, as in a variant's CPU time), CPU time and CPU per simulated second; then the sweep (its
workers fork from this process: the imports are theirs too, as a long sweep's workers have them
after their first variant): wall time, variants per minute, CPU per variant (each worker's CPU
time of its variants) and CPU per simulated second; and the
bare engine (``tools.bench.runs.bare_stepper``: Pymunk ``space.step``, PyBullet
``stepSimulation``) stepping that scene for the same simulated time, the physical floor. The
ratios: sweep to full-log run (issue #41's target: <= 0.6) and sweep to bare engine. ``--quick``
runs a few short variants of each (the test's mode; its figures say nothing). Nothing here is a
test: it prints, it does not judge.
"""

from __future__ import annotations

import argparse
import resource
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from replay.resources import scenario_dir
from replay.runner import Runner
from replay.sweep.engine import run_sweep
from replay.sweep.spec import Axis, SweepSpec
from replay.sweep.table import as_float
from replay.sweep.variants import Variant, expand
from tools.bench.runs import bare_stepper

WORKERS = 2
GRASP_DURATION = 1.0  # s simulated a grasp variant (the scenario's 2.0 s: the longer hold)
RUNS = 3  # in-process runs of the first variant, each with and without a log (medians)
QUICK = {"n": 2, "duration": 0.1}  # --quick: variants a workload, s simulated each


@dataclass
class Workload:
    name: str
    scenario: str
    sets: list[str]
    axis: Axis
    what: str  # what varies, for the report


def _catch(n: int) -> Workload:
    from analysis.catching.throws import perturbed_throws

    throws = [
        {
            "plant.params.object_position": t["position"],
            "plant.params.object_velocity": t["velocity"],
        }
        for t in perturbed_throws(n, spread=0.1)
    ]
    return Workload(
        "catch_optimised",
        "catch_optimised",
        ["timing.duration=0.45", "stop.after=0.0"],
        Axis("throw", throws, [f"{i:03d}" for i in range(n)]),
        f"{n} perturbed throws",
    )


def _grasp(n: int) -> Workload:
    return Workload(
        "grasp_hexahedron",
        "grasp_hexahedron",
        [f"timing.duration={GRASP_DURATION}"],
        Axis("seed", list(range(n))),
        f"{n} human paths",
    )


def _stick(n: int) -> Workload:
    return Workload(
        "stick_3step",
        "stick_3step",
        ["plant.params.throw.random=true"],
        Axis("seed", list(range(n))),
        f"{n} random throws",
    )


def workloads(quick: bool) -> list[Workload]:
    sizes = (QUICK["n"],) * 3 if quick else (200, 40, 200)
    out = [make(n) for make, n in zip((_catch, _grasp, _stick), sizes)]
    if quick:
        for w in out:
            w.sets = [s for s in w.sets if not s.startswith("timing.duration=")]
            w.sets.append(f"timing.duration={QUICK['duration']}")
    return out


def _children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def sweep(w: Workload) -> dict:
    """The workload as a ``--no-logs`` sweep with WORKERS local workers."""
    path = scenario_dir() / f"{w.scenario}.yaml"
    variants = expand(path, SweepSpec(grid=[w.axis]), 0, sets=w.sets, version="bench")
    with tempfile.TemporaryDirectory(prefix="research-bench-") as d:
        c0, t0 = _children_cpu() + time.process_time(), time.perf_counter()
        s = run_sweep(variants, d, workers=WORKERS, keep_logs=False, progress=False)
        wall = time.perf_counter() - t0
        total_cpu = _children_cpu() + time.process_time() - c0  # (workers reaped at the end)
    cpu = sum(as_float(r.get("cpu_time")) for r in s.rows)
    sim = sum(as_float(r.get("t_end")) for r in s.rows)
    errors = [r for r in s.rows if str(r.get("reason", "")).startswith(("error", "invalid"))]
    return {
        "variants": s.ran,
        "ok": s.ok,
        "errors": len(errors),
        "wall": wall,
        "per_minute": 60.0 * s.ran / wall,
        "cpu_per_variant": cpu / max(1, s.ran),
        "cpu_per_sim": cpu / sim if sim > 0 else float("nan"),
        "total_cpu_per_variant": total_cpu / max(1, s.ran),
    }


def _runner(v: Variant) -> Runner:
    """A variant's runner, as a sweep worker makes it (its data files found as there)."""
    from replay.scenario.loader import scenario_from_text, set_file_dirs

    sc = scenario_from_text(v.resolved, name=f"<variant {v.key}>", resolved=True)
    set_file_dirs(sc, v.file_dirs)
    return Runner(sc)


def full_run(v: Variant, out: Path, runs: int = RUNS) -> dict:
    """A variant run in this process with a full log and without one, each ``runs`` times after
    a warm-up run: median CPU s of each, simulated s, physics steps. The CPU time counts what a
    sweep variant's does: the scenario parsed, the plant and controller made, the run."""
    _runner(v).run(None)  # warm-up: imports, caches

    def cpu(log: Path | None):
        c0 = time.process_time()
        result = _runner(v).run(log)
        return time.process_time() - c0, result

    full = [cpu(out) for _ in range(runs)]
    bare = [cpu(None)[0] for _ in range(runs)]
    result = full[0][1]
    return {
        "cpu": statistics.median(c for c, _ in full),
        "no_log_cpu": statistics.median(bare),
        "sim": result.t_end,
        "steps": result.steps,
    }


def bare_engine(v: Variant, steps: int) -> tuple[str, float]:
    """(engine, CPU s) of the bare engine stepping the variant's scene ``steps`` times."""
    runner = _runner(v)
    name, plant, step = bare_stepper(runner)
    try:
        c0 = time.process_time()
        for _ in range(steps):
            step()
        return name, time.process_time() - c0
    finally:
        plant.close()
        runner.plant.close()


def measure(w: Workload) -> dict:
    one = SweepSpec(grid=[Axis(w.axis.name, w.axis.values[:1])])
    first = expand(scenario_dir() / f"{w.scenario}.yaml", one, 0, sets=w.sets)
    with tempfile.TemporaryDirectory(prefix="research-bench-run-") as d:
        full = full_run(first[0], Path(d) / "run.mcap")
    engine, bare_cpu = bare_engine(first[0], full["steps"])
    r = sweep(w)
    r.update(
        full_cpu=full["cpu"],
        full_cpu_per_sim=full["cpu"] / full["sim"],
        no_log_cpu_per_sim=full["no_log_cpu"] / full["sim"],
        engine=engine,
        bare_cpu_per_sim=bare_cpu / full["sim"],
    )
    r["ratio_full"] = r["cpu_per_sim"] / r["full_cpu_per_sim"]
    r["ratio_variant"] = r["cpu_per_variant"] / r["full_cpu"]
    r["ratio_bare"] = r["cpu_per_sim"] / r["bare_cpu_per_sim"]
    return r


def report(w: Workload, r: dict) -> str:
    return "\n".join(
        [
            f"{w.name}: {w.what} ({' '.join(w.sets)}), --no-logs, {WORKERS} local workers",
            f"  sweep: {r['variants']} variants ({r['ok']} succeeded, {r['errors']} errors) in "
            f"{r['wall']:.1f} s wall = {r['per_minute']:.1f} variants/min; "
            f"{r['cpu_per_variant']:.3f} CPU s a variant ({r['total_cpu_per_variant']:.3f} with "
            f"the workers' start and the pool), {r['cpu_per_sim']:.3f} CPU s per simulated s",
            f"  one full-log run (first variant, in this process, median of {RUNS}): "
            f"{r['full_cpu']:.3f} CPU s, {r['full_cpu_per_sim']:.3f} CPU s per simulated s "
            f"(without a log: {r['no_log_cpu_per_sim']:.3f})",
            f"  bare engine ({r['engine']}), same simulated time: "
            f"{r['bare_cpu_per_sim']:.4f} CPU s per simulated s",
            f"  ratios (CPU per simulated s): sweep / full-log run {r['ratio_full']:.2f} "
            f"(per variant {r['ratio_variant']:.2f}; target <= 0.6), "
            f"sweep / bare engine {r['ratio_bare']:.1f}x",
        ]
    )


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="a few short variants (a smoke test)")
    args = ap.parse_args(argv)
    for w in workloads(args.quick):
        print(report(w, measure(w)), flush=True)


if __name__ == "__main__":
    main()
