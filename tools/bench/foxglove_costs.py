"""What the Foxglove topics cost a run: CPU time per simulated second with and without them.

``python -m tools.bench.foxglove_costs [SCENARIO...] [--runs N] [--duration S]``: in one process, for
each scenario, alternately runs it as it is (``/tf``, ``/scene``, ``/joint_states`` at
``timing.frame_rate``, camera images where ``log_images``) and with them off
(``timing.frame_rate=0`` and every sensor's ``log_images=false``), and prints the median CPU
seconds (``time.process_time``) per simulated second of each, their difference, the log sizes
and the time in logging (``tools.bench.runs.timed_run``). It prints; it does not judge.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from pathlib import Path

from replay.resources import scenario_dir
from replay.runner import Runner
from replay.scenario import load_scenario

DEFAULT = [
    str(scenario_dir() / f"{name}.yaml")
    for name in ("stick_3step", "catch_optimised", "grasp_hexahedron")
]


def off_sets(path: str) -> list[str]:
    sc = load_scenario(path)
    sets = ["timing.frame_rate=0"]
    for name, s in sc.sensors.items():
        if hasattr(s.params, "log_images"):
            sets.append(f"sensors.{name}.params.log_images=false")
    return sets


def one(path: str, sets: list[str], out: Path) -> tuple[float, float, int, float]:
    """(CPU s, simulated s, log bytes, wall s in logging) of one run."""
    from tools.bench.runs import timed_run

    sc = load_scenario(path, sets)
    runner = Runner(sc)
    c0 = time.process_time()
    result, times = timed_run(runner, out)
    cpu = time.process_time() - c0
    return cpu, result.t_end, result.path.stat().st_size, times["logging"]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenarios", nargs="*", default=DEFAULT)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--duration", type=float, default=0.0, help="cut each run (s); 0 = as is")
    args = ap.parse_args(argv)
    with tempfile.TemporaryDirectory() as tmp:
        for path in args.scenarios:
            cut = [f"timing.duration={args.duration}"] if args.duration else []
            configs = {"with": cut, "without": cut + off_sets(path)}
            rows: dict[str, list] = {k: [] for k in configs}
            for k, sets in configs.items():  # warm-up
                one(path, sets, Path(tmp) / f"{k}.mcap")
            for _ in range(args.runs):
                for k, sets in configs.items():
                    rows[k].append(one(path, sets, Path(tmp) / f"{k}.mcap"))
            per = {k: statistics.median(r[0] / r[1] for r in v) for k, v in rows.items()}
            size = {k: v[-1][2] for k, v in rows.items()}
            logging = {k: statistics.median(r[3] / r[1] for r in v) for k, v in rows.items()}
            name = Path(path).stem
            print(
                f"{name}: CPU s per simulated s: with {per['with']:.4f}, without "
                f"{per['without']:.4f}, Foxglove topics {per['with'] - per['without']:+.4f} "
                f"({100 * (per['with'] / per['without'] - 1):+.1f} %); logging timer "
                f"{logging['with']:.4f} vs {logging['without']:.4f}; log "
                f"{size['with'] / 1024:.0f} KiB vs {size['without'] / 1024:.0f} KiB"
            )


if __name__ == "__main__":
    main()
