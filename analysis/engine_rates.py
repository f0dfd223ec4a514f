"""The robustness rates of every registered physics engine on the same inputs (issue #24, #39),
stored for the claims table and the report (analysis/engines.py's ``stored_rate_rows``).

- catch (namiki2003): each catching scenario in every engine on the same seeded perturbed
  throws, none of them a tuning throw: the shared throw set's base cell
  (analysis.catching.ablations.run_shared: 8-10 m/s at first sight, tilted by up to 1 deg, r_o(t0)
  jittered by 5 mm; tests/analysis/test_catch_robustness.py's generator and seed), judged by the
  plant's catch verdict (the ball at rest in the hand, from the engine's contacts and the ball's
  true motion);
- grasp (namiki1999): box and ball in every engine on the same human paths, seeds and speeds no
  scenario uses (they use seed 0 at 0.10 m/s): the seeds of tests/analysis/test_grasp_robustness.py,
  tests/plants/mujoco_arm/test_grasp_mujoco.py and docs/grasping.md's 30-run batch, judged by the
  physical criterion from the truth topics (analysis/grasping/judge.py), never by the run's flag.

A scenario runs in an engine as its shipped twin ``<scenario>_<engine>`` (which holds the
engine's chosen settings), else with ``--set plant.params.engine.type=<engine>``
(``scenario_for``). Where the engines part, a probe (``PROBES``) runs an engine's scenario with
one setting changed on the same inputs, so the table says what decides the difference; its rows'
engine is ``<engine's label>, <setting>``.

``python -m analysis.engine_rates [throws] [--engine NAME ...]`` runs them (one process, one run
at a time, a line on stderr per scenario and engine) and writes data/ablations/engine_rates.csv
and .md (per set and engine the rate with its Wilson 95 % interval and the failures' reasons);
with ``--engine`` only those engines (and their probes) run, their rows replacing theirs in the
stored table, every other engine's rows kept (docs/mujoco.md: the time it takes).
"""

from __future__ import annotations

import csv
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Iterable, Sequence
from pathlib import Path

from analysis.engines import REFERENCE, label, rank, registered

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
# a measured why where the engines part: per set's scenario, (engine, what, its --set strings),
# run on the same inputs. catch_initial: MuJoCo's bounce, solref's damping ratio 1.0 against
# PyBullet's restitution 0.18, decides the initial mapping's off-axis strike on finger f3;
# grasp_hexahedron: Drake's point contact (one point per pair at the box's edges) lets the box
# walk along the hand on the fast paths, hydroelastic contact holds it (docs/drake.md)
PROBES = {
    "catch_initial": (
        ("mujoco", "mj_solref [0.002, 1.5]", ("plant.params.engine.mj_solref=[0.002, 1.5]",)),
    ),
    "grasp_hexahedron": (
        ("drake", "hydroelastic contact", ("plant.params.engine.dk_contact_model=hydroelastic",)),
    ),
}
FIELDS = ("paper", "set", "scenario", "engine", "case", "success", "reason", "flag")


def catch_set(name: str, n: int) -> str:
    return f"{name}: catch rate on {n} perturbed 8-10 m/s throws"


def grasp_set(name: str, n: int) -> str:
    return f"{name}: grasped and held on {n} unseen human paths (0.05-0.3 m/s)"


def is_probe(engine_label: str) -> bool:
    """A stored row's engine column names a probe (``<label>, <setting>``), not an engine."""
    return ", " in engine_label


def owner(engine_label: str) -> str:
    """The engine label a stored row's engine column (an engine's or a probe's) belongs to."""
    return engine_label.split(", ")[0]


def scenario_for(name: str, engine: str) -> tuple[str, tuple[str, ...]]:
    """The scenario that runs ``name`` in ``engine`` and its ``--set`` strings: ``name`` in the
    reference, else its shipped twin ``name_<engine>`` (the engine's chosen settings), else
    ``name`` with the engine field set (the engine's defaults)."""
    from replay.resources import scenario_dir

    if engine == REFERENCE:
        return name, ()
    if (scenario_dir() / f"{name}_{engine}.yaml").is_file():
        return f"{name}_{engine}", ()
    return name, (f"plant.params.engine.type={engine}",)


def variants(name: str, engines: Sequence[str]) -> list[tuple[str, str, tuple[str, ...]]]:
    """(label, scenario, --set strings) of ``name`` in each of ``engines``, then their probes."""
    out = [(label(e), *scenario_for(name, e)) for e in engines]
    for engine, what, sets in PROBES.get(name, ()):
        if engine in engines:
            scenario, base = scenario_for(name, engine)
            out.append((f"{label(engine)}, {what}", scenario, base + tuple(sets)))
    return out


def _say(what: str, n: int) -> None:
    print(f"{what}: {n} runs ({time.process_time():.0f} s CPU so far)", file=sys.stderr)


def run_catch(
    n: int = 30, names=CATCH_SCENARIOS, engines: Sequence[str] | None = None
) -> list[dict]:
    """Each catching scenario in each of ``engines`` (default: every registered one) and their
    probes on the same ``n`` seeded perturbed throws."""
    from analysis.catching.ablations import run_shared

    rows = []
    for name in names:
        for engine, scenario, sets in variants(name, engines or registered()):
            _say(f"{name} in {engine}", n)
            for r in run_shared(n, cells=[CATCH_CELL], controllers={engine: scenario}, extra=sets):
                rows.append(
                    {
                        "paper": "namiki2003",
                        "set": catch_set(name, n),
                        "scenario": name,
                        "engine": engine,
                        "case": f"throw {r['throw']} ({r['speed']:.2f} m/s)",
                        "success": r["success"],
                        "reason": r["reason"],
                        "flag": r["success"],  # the plant's verdict is the catch criterion
                    }
                )
    return rows


def run_grasp(
    paths=GRASP_PATHS, names=GRASP_SCENARIOS, engines: Sequence[str] | None = None
) -> list[dict]:
    """Each grasp scenario in each of ``engines`` (default: every registered one) and their
    probes on the same human paths, judged physically."""
    rows = []
    with tempfile.TemporaryDirectory(prefix="engine-rates-") as tmp:
        for name in names:
            for engine, scenario, sets in variants(name, engines or registered()):
                _say(f"{name} in {engine}", len(paths))
                for seed, speed in paths:
                    ok, why, flag = _grasp_run(scenario, sets, seed, speed, Path(tmp) / "run.mcap")
                    rows.append(
                        {
                            "paper": "namiki1999",
                            "set": grasp_set(name, len(paths)),
                            "scenario": name,
                            "engine": engine,
                            "case": f"seed {seed}, {speed:g} m/s",
                            "success": ok,
                            "reason": why,
                            "flag": flag,
                        }
                    )
    return rows


def _grasp_run(
    scenario: str, sets: Iterable[str], seed: int, speed: float, out: Path
) -> tuple[bool, str, bool]:
    """One grasp run on a human path: (held by the physical criterion, why, the run's flag)."""
    from analysis.grasping.judge import physical_verdict
    from replay.log import LogReader
    from replay.resources import scenario_dir
    from replay.runner import Runner
    from replay.scenario import load_scenario

    sc = load_scenario(
        scenario_dir() / f"{scenario}.yaml",
        sets=[*sets, f"seed={seed}", f"plant.params.human_speed={speed}"],
    )
    log = LogReader(Runner(sc).run(out).path)
    ok, why = physical_verdict(log)
    flag = next(e for e in reversed(log.events()) if e["kind"] == "outcome")
    return ok, why, bool(flag["data"]["success"])


def merge(stored: list[dict], fresh: list[dict], engines: Iterable[str]) -> list[dict]:
    """The stored rows with those of ``engines`` (and their probes) replaced by ``fresh``: every
    other engine's rows kept; sets in the stored order, then engines, then their probes."""
    labels = {label(e) for e in engines}
    rows = [r for r in stored if owner(r["engine"]) not in labels] + fresh
    sets = list(dict.fromkeys(r["set"] for r in rows))
    return sorted(
        rows, key=lambda r: (sets.index(r["set"]), is_probe(r["engine"]), rank(owner(r["engine"])))
    )


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


def main(argv: Sequence[str]) -> str:
    """Run the sets (``[throws] [--engine NAME ...]``), store them, return the table."""
    import argparse

    from replay.resources import data_path

    parser = argparse.ArgumentParser(prog=COMMAND, description="the engines' robustness rates")
    parser.add_argument("throws", nargs="?", type=int, default=30, help="throws per catch set")
    parser.add_argument(
        "--engine", action="append", choices=registered(), help="run only this engine (repeat)"
    )
    args = parser.parse_args(argv)
    engines = args.engine or list(registered())
    fresh = run_catch(args.throws, engines=engines) + run_grasp(engines=engines)
    dest = data_path("ablations")
    rows = merge(read(dest / f"{TABLE}.csv"), fresh, engines) if args.engine else fresh
    write(rows, dest / f"{TABLE}.csv")
    text = markdown(rows)
    (dest / f"{TABLE}.md").write_text(text + "\n", encoding="utf-8")
    return text


if __name__ == "__main__":  # python -m analysis.engine_rates [throws] [--engine NAME ...]
    print(main(sys.argv[1:]))
