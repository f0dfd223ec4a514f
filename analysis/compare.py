"""Runs side by side (``replay compare``): what their stored scenarios set differently, their
outcomes and the metrics their outcome events hold, one row per field, one column per run.

Each run is its log's key (:func:`analysis.runs.keyed`: the scenario name, a second log of that
name with what differs) and its label (what differs from its experiment, the shipped scenario).
Everything shown comes from a log: each cell is one line (control characters escaped), at most
:data:`CELL` characters; at most :data:`MAX_ROWS` rows per table, the rest counted.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from analysis import runs
from replay.log import LogError, LogReader
from replay.scenario.yamlio import one_line

MAX_RUNS = 12  # columns: the runs compared (the others named and left out)
MAX_ROWS = 40  # rows of one table (the others counted)
CELL = 40  # characters of one cell
_TEXT_FIELDS = {"description", "notes"}  # prose: not compared


@dataclass
class Comparison:
    keys: list[str]  # each run's key (runs.keyed), in the order given
    names: list[str]  # each run's scenario name
    paths: list[str]
    labels: list[str]  # what each run sets differently from its experiment
    experiments: list[str]
    fields: list[tuple[str, list[str]]]  # (scenario field, its value per run): those that differ
    fields_left: int  # differing fields beyond MAX_ROWS
    outcome: list[tuple[str, list[str]]]  # success, reason, then each metric
    outcome_left: int
    notes: list[str] = field(default_factory=list)


def cell(value: Any) -> str:
    """A value as one bounded line (``-`` when a run has no such field)."""
    if value is None:
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    text = one_line(runs._short(value))
    return text if len(text) <= CELL else text[: CELL - 1] + "…"


def _rows(
    per_run: list[dict[str, Any]], only_differing: bool
) -> tuple[list[tuple[str, list[str]]], int]:
    # the plug-ins' params after the rest (a name, a type, a rate read first)
    names = sorted({k for d in per_run for k in d}, key=lambda k: (".params." in k, k))
    rows = []
    for name in names:
        values = [d.get(name) for d in per_run]
        if only_differing and all(v == values[0] for v in values[1:]):
            continue
        rows.append((cell(name), [cell(v) for v in values]))
    return rows[:MAX_ROWS], max(0, len(rows) - MAX_ROWS)


def _scenario(reader: LogReader) -> dict[str, Any]:
    try:
        flat = runs._flat(runs.current_config(reader))
    except (LogError, AttributeError):
        return {}
    return {k: v for k, v in flat.items() if k.split(".")[0] not in _TEXT_FIELDS}


def _outcome(reader: LogReader) -> dict[str, Any]:
    """success, reason and the metrics (nested ones flattened: ``a.b``), or {} when none."""
    try:
        event = reader.outcome()
    except LogError:  # (its events over a limit: said by the reader's problems)
        event = None
    data = event.get("data") if event else None
    if not isinstance(data, dict):
        return {}
    metrics = runs._flat({k: v for k, v in data.items() if k not in ("success", "reason")})
    return {"success": bool(data.get("success")), "reason": data.get("reason", ""), **metrics}


def compare(readers: Sequence[LogReader]) -> Comparison:
    """The comparison of ``readers`` (2 or more, at most :data:`MAX_RUNS`)."""
    keyed = runs.keyed(readers)
    keys = list(keyed)
    described = [runs.describe(keyed[k], k) for k in keys]
    fields, fields_left = _rows([_scenario(keyed[k]) for k in keys], only_differing=True)
    outcomes = [_outcome(keyed[k]) for k in keys]
    head = [
        ("success", [cell(o.get("success")) if o else "(no outcome)" for o in outcomes]),
        ("reason", [cell(o.get("reason")) if o else "-" for o in outcomes]),
    ]
    metrics, outcome_left = _rows(
        [{k: v for k, v in o.items() if k not in ("success", "reason")} for o in outcomes],
        only_differing=False,
    )
    notes = []
    for k in keys:
        notes += [f"{k}: {n}" for n in keyed[k].describe_problems()]
    if not fields:
        notes.append("the runs' stored scenarios set every field alike (seed included)")
    return Comparison(
        keys=keys,
        names=[d.name for d in described],
        paths=[str(keyed[k].path) for k in keys],
        labels=[d.label for d in described],
        experiments=[d.experiment for d in described],
        fields=fields,
        fields_left=fields_left,
        outcome=head + metrics,
        outcome_left=outcome_left,
        notes=notes,
    )


def _table(header: str, rows: list[tuple[str, list[str]]], n: int) -> list[str]:
    """Aligned plain-text rows: the row name, then one column per run (#1, #2, ...)."""
    cols = [f"#{i + 1}" for i in range(n)]
    first = max([len(header), *(len(r[0]) for r in rows)])
    widths = [max([len(c), *(len(r[1][i]) for r in rows)]) for i, c in enumerate(cols)]

    def line(name: str, cells: list[str]) -> str:
        return "  " + "  ".join([name.ljust(first), *(c.ljust(w) for c, w in zip(cells, widths))])

    return [line(header, cols).rstrip(), *(line(r[0], r[1]).rstrip() for r in rows)]


def _run_said(c: Comparison, i: int) -> str:
    """Run ``i``: its key, what differs (when the key does not say it) and from what."""
    key, lab, exp = c.keys[i], c.labels[i], c.experiments[i]
    text = f"{key} ({lab})" if lab and lab not in key else key
    if not lab and exp == c.names[i]:
        return f"{text} (as shipped)"
    return f"{text} (vs {exp})" if exp and exp != c.names[i] else text


def _runs_said(c: Comparison) -> list[str]:
    return [f"  #{i + 1}  {_run_said(c, i)}  [{c.paths[i]}]" for i in range(len(c.keys))]


def text(c: Comparison) -> str:
    """The comparison for a terminal (aligned plain text; :func:`replay.console.say` escapes)."""
    n = len(c.keys)
    out = ["runs:", *(one_line(x) for x in _runs_said(c)), ""]
    if c.fields:
        out += ["scenario fields that differ:", *_table("field", c.fields, n)]
        if c.fields_left:
            out.append(f"  (+{c.fields_left} more fields differ)")
        out.append("")
    out += ["outcome:", *_table("", c.outcome, n)]
    if c.outcome_left:
        out.append(f"  (+{c.outcome_left} more metrics)")
    return "\n".join(out)


def markdown(c: Comparison, figures: Sequence[tuple[str, str]] = ()) -> str:
    """The comparison as Markdown, every cell escaped (:func:`analysis.report.markup.md`);
    ``figures``: (caption, link) of the overlaid figures, links relative to the file."""
    from urllib.parse import quote

    from analysis.report.markup import md

    n = len(c.keys)
    cols = [f"#{i + 1}" for i in range(n)]

    def table(header: str, rows: list[tuple[str, list[str]]]) -> list[str]:
        return [
            "| " + " | ".join([md(header) or " ", *cols]) + " |",
            "|" + "---|" * (n + 1),
            *("| " + " | ".join([md(r[0]), *(md(x) for x in r[1])]) + " |" for r in rows),
        ]

    out = ["# Runs compared", ""]
    for i in range(n):
        out.append(f"- **#{i + 1}** {md(_run_said(c, i))} ({md(c.paths[i])})")
    if c.fields:
        out += ["", "## Scenario fields that differ", "", *table("field", c.fields)]
        if c.fields_left:
            out.append(f"\n(+{c.fields_left} more fields differ)")
    out += ["", "## Outcome", "", *table("", c.outcome)]
    if c.outcome_left:
        out.append(f"\n(+{c.outcome_left} more metrics)")
    if figures:
        out += ["", "## Figures", ""]
        out += [f"![{md(cap)}]({quote(link, safe='/')})" for cap, link in figures]
    if c.notes:
        out += ["", *(f"> {md(t)}" for t in c.notes)]
    return "\n".join(out) + "\n"
