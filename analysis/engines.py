"""Claims per physics engine: each arm claim's row with every engine's value side by side
(docs/mujoco.md), the catch (or grasp) rates of the engines on the same throws (or human paths),
and the closing note (which claims hold in every engine, which in some).

A log's engine is its resolved scenario's (``engine_of``): ``plant.params.engine.type`` where the
plant names one, else its plant type (``mujoco_arm``, ``mujoco_grasp``: MuJoCo; any other arm
plant: PyBullet). A run in another engine than PyBullet is matched to its PyBullet twin by the
scenario's name, less a ``_<engine>`` suffix (``catch_optimised_mujoco`` is ``catch_optimised``
in MuJoCo). The paper's own ``evaluate`` (``analysis.catching.claims.evaluate``,
``analysis.grasping.claims.evaluate``: a log's typed params are its plant's, analysis/grasping/run.py)
is run once on each engine's logs, named without the suffix, so all give the same rows; the rows
are then joined by quantity. Every verdict stays the paper module's, from each engine's truth
topics.

Wiring (for the claims table and the report): ``engine_rows(evaluate, logs)`` in place of
``evaluate(logs)`` when ``logs`` holds runs of another engine; ``closing_note(rows)`` below the
table.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

from analysis.claims import ASSESSED, Claim

# each engine's name in a scenario (plant.params.engine.type) and its label in the tables, the
# first the reference every other engine's runs are matched to; an engine not listed is shown
# by its name
LABELS = {"pybullet": "PyBullet", "mujoco": "MuJoCo", "drake": "Drake"}
ENGINES = tuple(LABELS.values())
SUFFIX = "_mujoco"  # the MuJoCo twins' scenario names (analysis/engine_rates.py)
_PLANT_ENGINES = {"mujoco_arm": "mujoco", "mujoco_grasp": "mujoco"}  # before the engine field


def engine_of(config: Mapping[str, Any], name: str = "") -> str:
    """The engine (its name, ``LABELS``' key) of a resolved scenario (``config``, a log's
    ``scenario_config()``); where it has no plant (an unreadable one) the engine its ``name``
    ends with (``_mujoco``), else the reference."""
    plant = config.get("plant")
    if isinstance(plant, Mapping):
        params = plant.get("params")
        engine = params.get("engine") if isinstance(params, Mapping) else None
        if isinstance(engine, Mapping) and isinstance(engine.get("type"), str):
            return engine["type"]
        return _PLANT_ENGINES.get(str(plant.get("type")), "pybullet")
    return next((e for e in LABELS if name.endswith(f"_{e}")), "pybullet")


def split_logs(logs: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The logs per engine label (the reference engine first, then the others in ``LABELS``'
    order), each named as its reference twin (by the scenario's name less ``_<engine>``: a key
    may carry a label after it, analysis/runs.py)."""
    out: dict[str, dict[str, Any]] = {ENGINES[0]: {}}
    for key, log in logs.items():
        name = _read(log, "scenario").get("name")
        name = name if isinstance(name, str) and name else key
        engine = engine_of(_read(log, "scenario_config"), name)
        label = LABELS.get(engine, engine)
        suffix = f"_{engine}"
        if label != ENGINES[0] and name.endswith(suffix) and key.startswith(name):
            key = name[: -len(suffix)] + key[len(name) :]
        out.setdefault(label, {})[key] = log
    order = list(ENGINES) + sorted(set(out) - set(ENGINES))
    return {e: out[e] for e in order if e in out}


def _read(log: Any, what: str) -> Mapping[str, Any]:
    """``log.scenario()`` or ``log.scenario_config()``; {} where unreadable."""
    try:
        got = getattr(log, what)()
    except Exception:  # noqa: BLE001 - no readable scenario: the key is the name
        return {}
    return got if isinstance(got, Mapping) else {}


def join(groups: Mapping[str, Sequence[Claim]]) -> list[Claim]:
    """One row per quantity: every engine's measurement (``groups``: engine label -> its rows);
    the status all share, else ``differs`` (the claim does not hold in every engine) with each
    engine's status."""
    by_q = {e: {r.quantity: r for r in rows} for e, rows in groups.items()}
    quantities = dict.fromkeys(r.quantity for rows in groups.values() for r in rows)
    return [_row({e: by_q[e].get(q) for e in groups}) for q in quantities]


def _row(claims: Mapping[str, Claim | None]) -> Claim:
    ref = next(c for c in claims.values() if c is not None)
    status = {e: c.status if c else "not run" for e, c in claims.items()}
    ran = [s for s in status.values() if s != "not run"]
    parted = ""
    if len(set(status.values())) == 1:
        final = ran[0] if ran else "not run"
    elif len(set(ran)) == 1:  # an engine without a run: the others' verdict stands
        final = ran[0]
    else:
        final = "differs" if "reproduced" in ran else ran[-1]
        parted = "engines part: " + ", ".join(f"{e} {s}" for e, s in status.items())
    note = "; ".join(x for x in (parted, ref.note) if x)
    measured = " ‖ ".join(f"{e}: {c.measured if c else 'not run'}" for e, c in claims.items())
    return Claim(
        ref.quantity, ref.stated, measured, final, note, kind=ref.kind, measures=ref.measures
    )


def engine_rows(evaluate: Callable[[dict], list[Claim]], logs: Mapping[str, Any]) -> list[Claim]:
    """The paper's rows per engine, joined (``join``)."""
    return join({e: evaluate(g) if g else [] for e, g in split_logs(logs).items()})


def evaluate_runs(
    evaluate: Callable[[dict], list[Claim]], logs: Mapping[str, Any]
) -> tuple[list[Claim], str]:
    """(rows, note) as the claims table and the report show them: with runs of another engine
    than the reference among ``logs`` every engine side by side, then the stored robustness
    rates of each on the same inputs (``stored_rate_rows``), and the closing note over them;
    else the paper's rows alone."""
    if len(split_logs(logs)) == 1:
        return evaluate(dict(logs)), ""
    papers = {log.scenario()["paper"] for log in logs.values() if hasattr(log, "scenario")}
    rows = engine_rows(evaluate, logs) + [r for p in sorted(papers) for r in stored_rate_rows(p)]
    return rows, closing_note(rows)


# the robustness rates are a test the papers did not make (each shows its runs one by one), held
# to a project target: rows of kind "extension", the target in the note, never in "paper states"
TARGET = 0.9  # the share of runs that must succeed in each engine
TARGET_NOTE = "project target (issue #24, not the paper's): ≥ 90 % in each engine"
RATE_STATED = {
    "namiki2003": "no rate stated (Sec. IV-B, Figs. 10, 11: the catch of single throws)",
    "namiki1999": "no rate stated (Figs. 7, 8: one grasp of each object)",
}


def rate_row(
    label: str, stated: str, outcomes: Mapping[str, Sequence[Mapping]], kind: str = "extension"
) -> Claim:
    """A catch (or grasp) rate per engine on the same perturbed set: ``outcomes`` maps an
    engine to its runs' verdicts (``success``, ``reason``), each rate with its Wilson 95 %
    interval. "reproduced" (the target met) when every engine reaches :data:`TARGET`; where the
    engines part the note says so (and whether their intervals overlap), then each engine's
    failures with their reasons."""
    from analysis.catching.ablations import wilson

    parts, notes, passed, spans = [], [], {}, []
    for engine, res in outcomes.items():
        n = len(res)
        k = sum(bool(o["success"]) for o in res)
        if n:
            lo, hi = wilson(k, n)
            spans.append((lo, hi))
            parts.append(
                f"{engine}: {k}/{n} = {100 * k / n:.0f} % [{100 * lo:.0f}–{100 * hi:.0f} %]"
            )
        else:
            parts.append(f"{engine}: not run")
        passed[engine] = n > 0 and k >= TARGET * n
        why = Counter(str(o["reason"]) for o in res if not o["success"])
        if why:
            fails = "; ".join(f"{v}× {x}" for x, v in why.most_common())
            notes.append(f"{engine} failures: {fails}")
    if len(set(passed.values())) > 1:
        verdicts = ", ".join(f"{e} {'reproduced' if v else 'differs'}" for e, v in passed.items())
        overlap = len(spans) == len(passed) and max(s[0] for s in spans) <= min(s[1] for s in spans)
        notes.insert(
            0,
            f"engines part: {verdicts}"
            + (" (their intervals overlap: within the sampling error)" if overlap else ""),
        )
    status = "reproduced" if all(passed.values()) else "differs"
    return Claim(label, stated, " ‖ ".join(parts), status, "; ".join(notes), kind=kind)


def stored_rate_rows(paper: str, path: Path | None = None) -> list[Claim]:
    """``paper``'s robustness rate rows from the stored runs of both engines on the same inputs
    (data/ablations/engine_rates.csv, made by ``python -m analysis.engine_rates``): one per
    set; none when the table has no runs of the paper."""
    from analysis.engine_rates import COMMAND, TABLE, read
    from replay.resources import data_path

    path = path or data_path("ablations", f"{TABLE}.csv")
    rows = [r for r in read(path) if r["paper"] == paper]
    source = f"stored runs: data/ablations/{path.name} ({COMMAND})"
    out = []
    for s in dict.fromkeys(r["set"] for r in rows):
        # the engines of the set (the reference always: "not run" without rows), the rest probes
        labels = {r["engine"] for r in rows if r["set"] == s}
        engines = [e for e in ENGINES if e == ENGINES[0] or e in labels]
        by_engine = {e: [r for r in rows if r["set"] == s and r["engine"] == e] for e in engines}
        row = rate_row(s, RATE_STATED.get(paper, "no rate stated"), by_engine)
        probes: dict[str, list[dict]] = {
            r["engine"]: [] for r in rows if r["set"] == s and r["engine"] not in ENGINES
        }
        for r in rows:
            if r["engine"] in probes and r["set"] == s:
                probes[r["engine"]].append(r)
        why = [
            "probe " + rate_row(s, "", {label: res}).measured for label, res in probes.items()
        ]  # the twin with one setting changed, on the same inputs (analysis/engine_rates.py)
        row.note = "; ".join(x for x in (row.note, *why, TARGET_NOTE, source) if x)
        out.append(row)
    return out


def closing_note(rows: Sequence[Claim]) -> str:
    """Which assessed rows (measured, other regime, extension: those with a verdict) hold in
    every engine, which in some (and why: the row's note)."""
    every, some, neither, single, n = [], [], [], 0, 2
    for r in rows:
        if r.kind not in ASSESSED:
            continue
        parts = r.measured.split(" ‖ ")
        n = max(n, len(parts))
        if any(p.endswith(": not run") for p in parts):
            single += 1  # not run in every engine: no cross-engine verdict
            continue
        if r.status == "reproduced":
            every.append(r.quantity)
        elif "engines part" in r.note:
            some.append(f"{r.quantity} ({r.note.split(';')[0].removeprefix('engines part: ')})")
        elif r.status == "differs":  # (ties, notes and rows not run in either: no verdict)
            neither.append(r.quantity)
    all_n, part = ("both", "one engine only") if n == 2 else (f"all {n}", "some engines only")
    lines = [f"Hold in {all_n} engines ({len(every)}): {', '.join(every) or 'none'}."]
    lines.append(f"Hold in {part} ({len(some)}): {', '.join(some) or 'none'}.")
    lines.append(f"Hold in {'neither' if n == 2 else 'none'} ({len(neither)}): ")
    lines[-1] += f"{', '.join(neither) or 'none'}."
    if single:
        lines.append(f"Run in {'one engine only' if n == 2 else 'some engines only'}, ")
        lines[-1] += f"not compared: {single} rows."
    return "\n".join(lines)
