"""The robustness rates of both physics engines on the same inputs (issue #24), stored for the
claims table and the report (analysis/engines.py's ``stored_rate_rows``).

- catch (namiki2003): each catching scenario and its ``_mujoco`` twin on the same seeded
  perturbed throws, none of them a tuning throw: the shared throw set's base cell
  (analysis.catching.ablations.run_shared: 8-10 m/s at first sight, tilted by up to 1 deg, r_o(t0)
  jittered by 5 mm; tests/analysis/test_catch_robustness.py's generator and seed), judged by the
  plant's catch verdict (the ball at rest in the hand, from the engine's contacts and the ball's
  true motion);
- grasp (namiki1999): box and ball and their twins on the same human paths, seeds and speeds no
  scenario uses (they use seed 0 at 0.10 m/s): the seeds of tests/analysis/test_grasp_robustness.py,
  tests/plants/mujoco_arm/test_grasp_mujoco.py and docs/grasping.md's 30-run batch, judged by the
  physical criterion from the truth topics (analysis/grasping/judge.py), never by the run's flag.

Where the engines part, a probe (``PROBES``) runs the MuJoCo twin with one setting changed on the
same inputs, so the table says what decides the difference. ``python -m analysis.engine_rates
[throws]`` runs them all (one process, one run at a time; ~17 min on a shared 2-core machine) and
writes data/ablations/engine_rates.csv and .md (per set and engine the rate with its Wilson 95 %
interval and the failures' reasons).
"""

from __future__ import annotations

import csv
import tempfile
from collections import Counter
from pathlib import Path

from analysis.engines import SUFFIX

TABLE = "engine_rates"  # data/ablations/engine_rates.csv and .md
COMMAND = "python -m analysis.engine_rates"
CATCH_SCENARIOS = ("catch_optimised", "catch_initial")
CATCH_CELL = "base (8-10 m/s, 1 kHz)"  # analysis.catching.ablations.SHARED_CELLS' first
GRASP_SCENARIOS = ("grasp_hexahedron", "grasp_sphere")
# (seed, human speed m/s): docs/grasping.md's batch (seeds 101-105 x 0.05, 0.15, 0.3),
# test_grasp_robustness.py's three, test_grasp_mujoco.py's five
GRASP_PATHS = tuple((s, v) for s in range(101, 106) for v in (0.05, 0.15, 0.3)) + (
    (211, 0.05),
    (212, 0.15),
    (213, 0.3),
    (221, 0.05),
    (223, 0.15),
    (225, 0.3),
    (222, 0.10),
    (224, 0.2),
)
# a measured why where the engines part: the set's scenario, MuJoCo twin with these --set
# strings on the same throws (catch_initial: MuJoCo's bounce, solref's damping ratio 1.0 against
# PyBullet's restitution 0.18, decides the initial mapping's off-axis strike on finger f3)
PROBES = {
    "catch_initial": (
        "MuJoCo, mj_solref [0.002, 1.5]",
        ("plant.params.engine.mj_solref=[0.002, 1.5]",),
    ),
}
FIELDS = ("paper", "set", "scenario", "engine", "case", "success", "reason", "flag")


def catch_set(name: str, n: int) -> str:
    return f"{name}: catch rate on {n} perturbed 8-10 m/s throws"


def grasp_set(name: str, n: int) -> str:
    return f"{name}: grasped and held on {n} unseen human paths (0.05-0.3 m/s)"


def run_catch(n: int = 30, names=CATCH_SCENARIOS, probes: bool = False) -> list[dict]:
    """Each catching scenario and its MuJoCo twin on the same ``n`` seeded perturbed throws;
    with ``probes`` only the twins' ``PROBES`` variants on them instead."""
    from analysis.catching.ablations import run_shared

    rows = []
    for name in names:
        engines = {"PyBullet": name, "MuJoCo": name + SUFFIX}
        extra: tuple[str, ...] = ()
        if probes:
            if name not in PROBES:
                continue
            label, extra = PROBES[name]
            engines = {label: name + SUFFIX}
        for r in run_shared(n, cells=[CATCH_CELL], controllers=engines, extra=extra):
            rows.append(
                {
                    "paper": "namiki2003",
                    "set": catch_set(name, n),
                    "scenario": name,
                    "engine": r["controller"],
                    "case": f"throw {r['throw']} ({r['speed']:.2f} m/s)",
                    "success": r["success"],
                    "reason": r["reason"],
                    "flag": r["success"],  # the plant's verdict is the catch criterion
                }
            )
    return rows


def run_grasp(paths=GRASP_PATHS, names=GRASP_SCENARIOS) -> list[dict]:
    """Each grasp scenario and its MuJoCo twin on the same human paths, judged physically."""
    from analysis.grasping.judge import physical_verdict
    from replay.log import LogReader
    from replay.resources import scenario_dir
    from replay.runner import Runner
    from replay.scenario import load_scenario

    rows = []
    with tempfile.TemporaryDirectory(prefix="engine-rates-") as tmp:
        for name in names:
            for engine, scenario in (("PyBullet", name), ("MuJoCo", name + SUFFIX)):
                for seed, speed in paths:
                    sc = load_scenario(
                        scenario_dir() / f"{scenario}.yaml",
                        sets=[f"seed={seed}", f"plant.params.human_speed={speed}"],
                    )
                    log = LogReader(Runner(sc).run(Path(tmp) / "run.mcap").path)
                    ok, why = physical_verdict(log)
                    flag = next(e for e in reversed(log.events()) if e["kind"] == "outcome")
                    rows.append(
                        {
                            "paper": "namiki1999",
                            "set": grasp_set(name, len(paths)),
                            "scenario": name,
                            "engine": engine,
                            "case": f"seed {seed}, {speed:g} m/s",
                            "success": ok,
                            "reason": why,
                            "flag": bool(flag["data"]["success"]),
                        }
                    )
    return rows


def read(path: Path) -> list[dict]:
    """The stored rows (``success``, ``flag`` as bools); [] when the table is not there."""
    if not path.is_file():
        return []
    with path.open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    for r in rows:
        r["success"] = r["success"] == "True"
        r["flag"] = r["flag"] == "True"
    return rows


def write(rows: list[dict], path: Path) -> None:
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.DictWriter(fh, fieldnames=list(FIELDS))
        w.writeheader()
        w.writerows({k: r[k] for k in FIELDS} for r in rows)


def markdown(rows: list[dict]) -> str:
    """Per set and engine: k/n with its Wilson 95 % interval and the failures' reasons."""
    from analysis.catching.ablations import rate_cell

    engines = list(dict.fromkeys(r["engine"] for r in rows))
    lines = ["| set | " + " | ".join(engines) + " |", "|---" * (len(engines) + 1) + "|"]
    for s in dict.fromkeys(r["set"] for r in rows):
        cells = []
        for e in engines:
            sub = [r for r in rows if r["set"] == s and r["engine"] == e]
            if not sub:
                cells.append("–")
                continue
            k = sum(r["success"] for r in sub)
            why = Counter(r["reason"] for r in sub if not r["success"])
            cells.append(rate_cell(k, len(sub), why))
        lines.append(f"| {s} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


if __name__ == "__main__":  # python -m analysis.engine_rates [throws]
    import sys

    from replay.resources import data_path

    n_throws = int(sys.argv[1]) if len(sys.argv) > 1 else 30
    table_rows = run_catch(n_throws) + run_grasp() + run_catch(n_throws, probes=True)
    dest = data_path("ablations")
    write(table_rows, dest / f"{TABLE}.csv")
    text = markdown(table_rows)
    (dest / f"{TABLE}.md").write_text(text + "\n", encoding="utf-8")
    print(text)
