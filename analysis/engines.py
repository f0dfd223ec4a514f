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
from functools import cache
from pathlib import Path
from typing import Any

from analysis.claims import ASSESSED, Claim, variants_apart
from analysis.runs import variants_as_shipped

# each engine's name in a scenario (plant.params.engine.type) and its label in the tables, the
# first the reference every other engine's runs are matched to; an engine not listed is shown
# by its name
LABELS = {"pybullet": "PyBullet", "mujoco": "MuJoCo", "drake": "Drake"}
REFERENCE = next(iter(LABELS))
_PLANT_ENGINES = {"mujoco_arm": "mujoco", "mujoco_grasp": "mujoco"}  # before the engine field


def label(engine: str) -> str:
    """An engine's label in the tables (``LABELS``; else its name)."""
    return LABELS.get(engine, engine)


@cache
def registered() -> tuple[str, ...]:
    """Every registered engine's name (plants/arm_rig/engine.py ``engines``: entry points read,
    never loaded, so the analysis imports no simulator), the reference first, then ``LABELS``'
    order, then by name."""
    from plants.arm_rig.engine import engines

    names = set(engines()) | {REFERENCE}
    known = list(LABELS)
    return tuple(sorted(names, key=lambda e: (known.index(e) if e in known else len(known), e)))


def rank(engine_label: str) -> int:
    """Where an engine's label goes in a row: the registered engines' order, any other last."""
    order = [label(e) for e in registered()]
    return order.index(engine_label) if engine_label in order else len(order)


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
        return _PLANT_ENGINES.get(str(plant.get("type")), REFERENCE)
    return next((e for e in (*LABELS, *registered()) if name.endswith(f"_{e}")), REFERENCE)


def split_logs(logs: Mapping[str, Any]) -> dict[str, dict[str, Any]]:
    """The logs per engine label (the registered engines' order, ``registered``, then any
    other), each named as its reference twin (by the scenario's name less ``_<engine>``: a key
    may carry a label after it, analysis/runs.py; a run that differs from its scenario by the
    engine alone, ``--set plant.params.engine.type=…``, by the scenario's name)."""
    out: dict[str, dict[str, Any]] = {label(REFERENCE): {}}
    for key, log in logs.items():
        name = _read(log, "scenario").get("name")
        name = name if isinstance(name, str) and name else key
        engine = engine_of(_read(log, "scenario_config"), name)
        suffix = f"_{engine}"
        if engine != REFERENCE and name.endswith(suffix) and key.startswith(name):
            key = name[: -len(suffix)] + key[len(name) :]
        elif engine != REFERENCE and key == f"{name} (engine {engine})":  # --set its engine
            key = name
        out.setdefault(label(engine), {})[key] = log
    order = [label(e) for e in registered()]
    return {e: out[e] for e in order + sorted(set(out) - set(order)) if e in out}


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
    measured = " ‖ ".join(f"{e}: {_measured(c)}" for e, c in claims.items())
    return Claim(
        ref.quantity, ref.stated, measured, final, note, kind=ref.kind, measures=ref.measures
    )


def _measured(claim: Claim | None) -> str:
    """An engine's part of a joined row: its measurement, or "not run" first (and why, where
    its rows say), which ``closing_note`` reads as no verdict of that engine."""
    if claim is None or (claim.status == "not run" and not claim.measured):
        return "not run"
    if claim.status != "not run":
        return claim.measured
    why = claim.measured if claim.measured.startswith("(") else f"({claim.measured})"
    return f"not run {why}"


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
    variants = variants_as_shipped(logs)  # (their rows: not the paper's experiment)
    if len(split_logs(logs)) == 1:
        return variants_apart(evaluate(dict(logs)), variants), ""
    papers = {log.scenario()["paper"] for log in logs.values() if hasattr(log, "scenario")}
    ran = list(split_logs(logs))
    rows = variants_apart(engine_rows(evaluate, logs), variants)
    rows += [r for p in sorted(papers) for r in stored_rate_rows(p, engines=ran)]
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
    interval. "reproduced" (the target met) when every engine run reaches :data:`TARGET`; where
    the engines part the note says so (and whether their intervals overlap), then each engine's
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
            passed[engine] = k >= TARGET * n
        else:  # (no verdict: the closing note does not compare the row)
            parts.append(f"{engine}: not run")
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
    status = "reproduced" if passed and all(passed.values()) else "differs"
    return Claim(label, stated, " ‖ ".join(parts), status, "; ".join(notes), kind=kind)


def stored_rate_rows(
    paper: str, path: Path | None = None, engines: Sequence[str] = ()
) -> list[Claim]:
    """``paper``'s robustness rate rows from the stored runs of every engine on the same inputs
    (data/ablations/engine_rates.csv, made by ``python -m analysis.engine_rates``): one per
    set, each engine the table holds side by side (the reference and ``engines``, labels of the
    engines whose logs are analysed, always: "not run" without rows), then each probe's rate in
    the note; none when the table has no runs of the paper."""
    from analysis.engine_rates import COMMAND, TABLE, is_probe, read
    from replay.resources import data_path

    path = path or data_path("ablations", f"{TABLE}.csv")
    rows = [r for r in read(path) if r["paper"] == paper]
    source = f"stored runs: data/ablations/{path.name} ({COMMAND})"
    out = []
    for s in dict.fromkeys(r["set"] for r in rows):
        by_label: dict[str, list[dict]] = {e: [] for e in (label(REFERENCE), *engines)}
        for r in rows:
            if r["set"] == s:
                by_label.setdefault(r["engine"], []).append(r)
        shown = {e: v for e, v in by_label.items() if not is_probe(e)}
        ranked = {e: shown[e] for e in sorted(shown, key=rank)}
        row = rate_row(s, RATE_STATED.get(paper, "no rate stated"), ranked)
        why = [  # an engine's scenario with one setting changed, on the same inputs
            "probe " + rate_row(s, "", {p: res}).measured
            for p, res in by_label.items()
            if is_probe(p)
        ]
        row.note = "; ".join(x for x in (row.note, *why, TARGET_NOTE, source) if x)
        out.append(row)
    return out


def closing_note(rows: Sequence[Claim]) -> str:
    """Which assessed rows (measured, other regime, extension: those with a verdict) hold in
    every engine, which in some (and why: the row's note, ``_why``), which in none."""
    every, some, neither, single, n = [], [], [], 0, 2
    for r in rows:
        if r.kind not in ASSESSED:
            continue
        parts = r.measured.split(" ‖ ")
        n = max(n, len(parts))
        if any(p.partition(": ")[2].startswith("not run") for p in parts):
            single += 1  # not run in every engine: no cross-engine verdict
            continue
        if r.status == "reproduced":
            every.append(r.quantity)
        elif "engines part" in r.note:
            some.append(f"{r.quantity} ({_why(r.note)})")
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


def _why(note: str) -> str:
    """Why a row holds in some engines only, from its note: each engine's verdict and, where a
    probe ran (a rate row), each probe's rate: what decides the difference, measured."""
    parts = note.split("; ")
    probes = [p for p in parts if p.startswith("probe ")]
    return "; ".join([parts[0].removeprefix("engines part: "), *probes])
