"""``make bench`` (sweeps): throughput of ``replay sweep`` in variants per second, with 1 and 2
local workers (and Ray with 2, if installed), on the same short stick variants.

Each executor runs the same N variants (stick_3step to just past its first collision, friction
varied) into a fresh directory, so nothing is skipped. Wall-clock throughput on a shared machine is
noisy; the CPU seconds per variant (summed over the workers) say how much of the wall time was
ours. Nothing here is a test: it prints, it does not judge. ``--variants N`` sets N.
"""

from __future__ import annotations

import argparse
import importlib.util
import tempfile
import time

from replay.sweep.engine import run_sweep
from replay.sweep.spec import from_options
from replay.sweep.table import as_float
from replay.sweep.variants import expand

SCENARIO = "scenarios/stick_3step.yaml"
SETS = ["timing.duration=0.33"]


def _variants(n: int, tag: str):
    values = ",".join(f"{i / max(1, n - 1):.4f}" for i in range(n))
    spec = from_options([f"plant.params.stick.friction={values}"], [], None)
    return expand(SCENARIO, spec, 0, sets=SETS, version=f"bench-{tag}")


def measure(n: int, workers: int, executor: str = "local") -> dict:
    with tempfile.TemporaryDirectory(prefix="sweep-bench-") as d:
        variants = _variants(n, f"{executor}{workers}-{time.time_ns()}")
        t0 = time.perf_counter()
        s = run_sweep(
            variants, d, workers=workers, executor=executor, keep_logs=False, progress=False
        )
        wall = time.perf_counter() - t0
    cpu = sum(as_float(r.get("cpu_time")) for r in s.rows)
    return {
        "executor": executor,
        "workers": workers,
        "variants": s.ran,
        "wall": wall,
        "rate": s.ran / wall,
        "cpu_per_variant": cpu / max(1, s.ran),
        "ok": s.ok,
    }


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variants", type=int, default=6)
    ap.add_argument("--no-ray", action="store_true")
    args = ap.parse_args(argv)
    runs = [measure(args.variants, 1), measure(args.variants, 2)]
    if importlib.util.find_spec("ray") is not None and not args.no_ray:
        from replay.sweep import executors

        runs.append(measure(args.variants, 2, "ray"))
        runs[-1]["note"] = f"ray.init {executors.last_ray_init:.1f} s included"
    print(
        f"sweep throughput: {args.variants} variants of {SCENARIO} "
        f"({' '.join(SETS)}, friction varied)"
    )
    for r in runs:
        print(
            f"  {r['executor']:<5} workers={r['workers']}: {r['rate']:.3f} variants/s "
            f"({r['wall']:.1f} s wall, {r['cpu_per_variant']:.2f} s CPU per variant, "
            f"{r['ok']}/{r['variants']} ok){'  ' + r['note'] if 'note' in r else ''}"
        )
    print(
        f"  speed-up 2 vs 1 local workers: {runs[1]['rate'] / runs[0]['rate']:.2f}x (2.0 = linear)"
    )


if __name__ == "__main__":
    main()
