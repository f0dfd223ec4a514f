"""The claims table: each number a paper states against the same quantity measured in a run.

A row has a kind (what decides it, and whether it counts):

- ``measured``: a claim the paper states, read from the truth topics of runs of the paper's own
  experiment (its stated conditions: e.g. the catch at 8-10 m/s with the paper's mapping). Only
  these count toward "N of M reproduced", and a reproduced one only when ``replay falsify
  --store`` ran its falsifier (a named variant under which the claim is false in the
  simulation) and the row read "differs" then (``data/claims/falsified.json``): a row that was
  not shown to fail proves nothing, and is shown as "reproduced, falsifier not shown".
- ``other regime``: the same question outside the paper's stated conditions (another throw
  speed, a what-if parameter): shown, never counted.
- ``extension``: a method or a test the paper does not have (an added cost term, a robustness
  rate against a project target): shown, never counted.
- ``configuration``: what the scenario sets, or what a scenario parameter or the method's own
  state determines (a rate, a resolution, a release speed, a finger speed, a label): shown,
  never counted.
- ``paper``: the paper's own numbers checked against each other; the verdict is computed.

One row per finding: a row names what decides it (``measures``: ``run:observable`` strings);
no observable decides two rows of one table (a claim measured on several runs is one row,
:func:`merge`). "paper states" holds only what the paper states; a project target or our
tolerance goes in the note.

A paper's claims module (its registration's ``claims``, replay.papers) lists its falsifiers
in ``FALSIFIERS``; ``replay falsify`` runs each variant and checks that its row then "differs".
"""

from __future__ import annotations

import inspect
import json
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

KINDS = ("measured", "configuration", "paper", "other regime", "extension")
# rows of their own kind, outside the paper's experiment: shown (with a verdict), never counted
SHOWN = ("other regime", "extension")
ASSESSED = ("measured", *SHOWN)  # the kinds whose rows may read "reproduced"
FALSIFIED = "falsified.json"  # data/claims/: what `replay falsify --store` showed
NOT_SHOWN = "reproduced, falsifier not shown"


@dataclass
class Claim:
    quantity: str
    stated: str  # as the paper states it (with its unit)
    measured: str  # from the run's log, or a computation from the paper's own numbers
    status: str  # reproduced | differs | tie | inconsistent | consistent | note | not run
    note: str = ""
    kind: str = "measured"  # one of KINDS (see the module docstring)
    measures: tuple[str, ...] = ()  # what decides it: "run:observable" (one row per finding)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.quantity!r}: kind {self.kind!r} is not one of {KINDS}")
        if self.kind not in ASSESSED and self.status == "reproduced":
            raise ValueError(
                f"claim {self.quantity!r}: a {self.kind} row is never 'reproduced' (only a "
                "measured one is; say 'consistent' or 'differs')"
            )


@dataclass(frozen=True)
class Falsifier:
    """A variant under which a measured row's claim is false in the simulation.

    ``replaces`` names the log (by scenario name) that the variant's run stands in for when the
    paper's rows are evaluated; the variant is that scenario (or ``scenario``, if given) with
    ``overrides`` (``--set`` paths to values) applied."""

    row: str  # the Claim.quantity it must turn to "differs"
    name: str  # a short name for the variant
    replaces: str  # the scenario name of the log it replaces
    overrides: Mapping[str, Any] = field(default_factory=dict)
    why: str = ""  # why the paper's claim is false under it
    scenario: str | None = None  # the scenario run (default: ``replaces``)


def within(measured: float, stated: float, rel: float = 0.0, abs_: float = 0.0) -> str:
    return "reproduced" if abs(measured - stated) <= abs_ + rel * abs(stated) else "differs"


def agrees(ok: bool) -> str:
    """A configuration or paper row's verdict: 'consistent' or 'differs'."""
    return "consistent" if ok else "differs"


def smaller(a: float, b: float, tol: float) -> str:
    """'a is smaller than b' with a tolerance: "reproduced" when b - a > tol, "tie" when
    |a - b| <= tol (what the paper's figure cannot tell apart), else "differs"."""
    if abs(a - b) <= tol:
        return "tie"
    return "reproduced" if a < b else "differs"


def falsifiers_of(evaluate: Callable) -> tuple[Falsifier, ...]:
    """The falsifiers declared beside a paper's ``evaluate`` (its module's ``FALSIFIERS``)."""
    return tuple(getattr(inspect.getmodule(evaluate), "FALSIFIERS", ()))


def merge(quantity: str, per_run: Sequence[tuple[str, Claim]]) -> Claim:
    """One claim measured on several runs as one row (one finding): each run's measurement,
    "differs" if any run differs, "tie" if any ties and none differs, "reproduced" if every run
    that has the quantity reproduces it (runs where it is "not run" are said, not judged)."""
    judged = [(n, c) for n, c in per_run if c.status != "not run"] or list(per_run)
    statuses = {c.status for _, c in judged}
    status = next(
        (s for s in ("differs", "inconsistent", "tie", "note", "not run") if s in statuses),
        judged[0][1].status,
    )
    ref = per_run[0][1]
    notes = list(dict.fromkeys(c.note for _, c in per_run if c.note))
    return Claim(
        quantity,
        ref.stated,
        "; ".join(f"{n}: {c.measured}" for n, c in per_run),
        status,
        " / ".join(notes),
        kind=ref.kind,
        measures=tuple(dict.fromkeys(m for _, c in per_run for m in c.measures)),
    )


# ------------------------------------------------------------------ what replay falsify showed
@dataclass(frozen=True)
class Shown:
    """A paper's stored ``replay falsify --store`` result (data/claims/falsified.json)."""

    when: str  # UTC, ISO 8601
    code: str  # replay.version.code_version() of the run
    command: str
    rows: tuple[dict, ...]  # row, variant, replaces, baseline, status, flipped

    @property
    def flipped(self) -> frozenset[str]:
        """The rows a falsifier turned to "differs"."""
        return frozenset(r["row"] for r in self.rows if r.get("flipped"))

    def line(self) -> str:
        return (
            f"falsifiers last run {self.when} on code {self.code} ({self.command}): "
            f"{len(self.flipped)} rows flipped"
        )


def falsified_path() -> Path:
    from replay.resources import data_path

    return data_path("claims", FALSIFIED)


def shown(paper: str, path: Path | None = None) -> Shown | None:
    """What ``replay falsify --store`` last recorded for ``paper``; None if it never ran."""
    path = path or falsified_path()
    try:
        data = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    rec = data.get(paper) if isinstance(data, dict) else None
    if not isinstance(rec, dict):
        return None
    return Shown(
        str(rec.get("when", "?")),
        str(rec.get("code", "?")),
        str(rec.get("command", "")),
        tuple(r for r in rec.get("rows", ()) if isinstance(r, dict) and "row" in r),
    )


def _flipped(record: Shown | None) -> frozenset[str]:
    return record.flipped if record is not None else frozenset()


def variants_apart(rows: Iterable[Claim], variants: Mapping[str, str]) -> list[Claim]:
    """The rows with every measured one that a variant decides (``variants``: run key ->
    what it changes; ``analysis.runs.variants_as_shipped``) shown as "other regime": a run
    that changes the paper's conditions is not the paper's experiment, so its rows keep their
    verdict and are never counted."""
    out = []
    for r in rows:
        runs = {run for m in r.measures for run in m.split(":", 1)[0].split("/")}
        hit = sorted(runs & set(variants))
        if r.kind == "measured" and hit:
            why = "; ".join(f"{k} is a variant ({variants[k]}), not the paper's run" for k in hit)
            r = replace(r, kind="other regime", note=f"{r.note}; {why}" if r.note else why)
        out.append(r)
    return out


def counted(rows: Iterable[Claim], record: Shown | None = None) -> tuple[int, int]:
    """(reproduced, of): measured rows only (the paper's own experiment); a reproduced row
    counts only if ``replay falsify --store`` showed its falsifier flipping it (``record``)."""
    rows = [r for r in rows if r.kind == "measured"]
    flipped = _flipped(record)
    n_ok = sum(r.status == "reproduced" and r.quantity in flipped for r in rows)
    return n_ok, len(rows)


def shown_status(r: Claim, record: Shown | None = None) -> str:
    """The status as the table shows it: a measured "reproduced" row whose falsifier was not
    shown flipping it reads "reproduced, falsifier not shown"."""
    if r.kind == "measured" and r.status == "reproduced" and r.quantity not in _flipped(record):
        return NOT_SHOWN
    return r.status


def summary(rows: list[Claim], record: Shown | None = None) -> str:
    """One line: the measured count, and how many rows of each other kind there are."""
    n_ok, n = counted(rows, record)
    bare = sum(shown_status(r, record) == NOT_SHOWN for r in rows)
    ties = sum(r.kind == "measured" and r.status == "tie" for r in rows)
    other = {k: sum(r.kind == k for r in rows) for k in KINDS[1:]}
    parts = [
        f"{n_ok} of {n} measured rows (the paper's own experiment) reproduced with a falsifier "
        "shown flipping them"
    ]
    if bare:
        parts.append(f"{bare} more agree, falsifier not shown (not counted)")
    if ties:
        parts.append(f"{ties} tie{'s' if ties > 1 else ''}")
    parts += [f"{v} {k} row{'s' if v != 1 else ''}" for k, v in other.items() if v]
    when = record.line() if record else "falsifiers never stored (replay falsify --store)"
    return "; ".join(parts) + f". {when[0].upper()}{when[1:]}."


def format_table(
    title: str,
    rows: list[Claim],
    partial: dict[str, list[str]] | None = None,
    falsifiers: Iterable[Falsifier] = (),
    record: Shown | None = None,
) -> str:
    """The table in Markdown; ``partial`` (log name -> notes) lists the logs that are not
    finished runs, so their rows are never read as a finished run's."""
    lines = [f"## {title}", ""]
    for name, notes in (partial or {}).items():
        lines.append(
            f"> **{name} is not a finished run**: {'; '.join(notes)}. Rows from it "
            "describe only the logged part."
        )
    if partial:
        lines.append("")
    lines += [
        "| quantity | kind | paper states | this run | status | note |",
        "|---|---|---|---|---|---|",
    ]
    falsifiers = tuple(falsifiers)
    for r in rows:
        lines.append(
            f"| {r.quantity} | {r.kind} | {r.stated} | {r.measured} | "
            f"**{shown_status(r, record)}** | {row_note(r, falsifiers, record)} |"
        )
    lines += ["", summary(rows, record)]
    return "\n".join(lines)


def row_note(r: Claim, falsifiers: Iterable[Falsifier], record: Shown | None = None) -> str:
    """The row's note, and for a reproduced row its falsifier(s) and whether `replay falsify`
    showed them flipping it; a row outside the paper's experiment says it is not counted."""
    tag = ""
    if r.kind in SHOWN:
        tag = f"{r.kind}: shown, not counted"
    elif r.kind == "measured" and r.status == "reproduced":
        names = [f.name for f in falsifiers if f.row == r.quantity]
        if r.quantity in _flipped(record):
            tag = f"falsifier {', '.join(names) or '?'} flipped it (replay falsify)"
        elif names:
            tag = f"falsifier {', '.join(names)} not shown flipping it: not counted"
        else:
            tag = "no falsifier: not counted"
    if not tag:
        return r.note
    return f"{r.note} [{tag}]" if r.note else f"[{tag}]"


def format_falsifiers(falsifiers: Iterable[Falsifier]) -> str:
    """The declared falsifiers as a Markdown table (what `replay falsify` runs)."""
    lines = [
        "| row | variant | replaces | overrides | why the claim is false under it |",
        "|---|---|---|---|---|",
    ]
    for f in falsifiers:
        sets = ", ".join(f"`{k}={v}`" for k, v in f.overrides.items())
        run = f"{f.scenario} " if f.scenario else ""
        lines.append(f"| {f.row} | {f.name} | {f.replaces} | {run}{sets} | {f.why} |")
    return "\n".join(lines)


def paper_counts(logs_dir: str | Path = "out/logs") -> dict[str, dict]:
    """Per paper, the claims table's counts on the logs in ``logs_dir`` (``make run``'s) with
    the stored ``replay falsify --store`` record: measured rows reproduced with a falsifier
    shown flipping them, of all measured rows; those reproduced with none shown; ties; rows of
    other regimes and extensions (shown, not counted); configuration and paper rows; and when
    and on which code the falsifiers last ran. For the README's summary and the report."""
    from analysis import runs
    from analysis.engines import evaluate_runs
    from replay import registry
    from replay.log import LogReader

    logs = [LogReader(p) for p in sorted(Path(logs_dir).glob("*.mcap"))]
    out: dict[str, dict] = {}
    for paper, readers in runs.by_paper(logs).items():
        try:
            evaluate = registry.load("claims", paper)
        except registry.UnknownPlugin:
            continue
        rows, _ = evaluate_runs(evaluate, readers)
        record = shown(paper)
        n_ok, n = counted(rows, record)
        out[paper] = {
            "reproduced": n_ok,
            "of": n,
            "falsifier not shown": sum(shown_status(r, record) == NOT_SHOWN for r in rows),
            "ties": sum(r.kind == "measured" and r.status == "tie" for r in rows),
            **{k: sum(r.kind == k for r in rows) for k in KINDS[1:]},
            "falsifiers last run": f"{record.when}, code {record.code}" if record else "never",
        }
    return out
