"""The claims table: each number a paper states against the same quantity measured in a run.

A row has a kind (what decides it):

- ``measured``: read from the run's truth topics; only these count toward "N of M reproduced",
  and only when a falsifier (a named variant under which the paper's claim is false in the
  simulation) is declared for the row: a row that cannot be shown to fail proves nothing.
- ``configuration``: what the scenario sets (a rate, a resolution, a release speed): shown, never
  counted.
- ``paper``: the paper's own numbers checked against each other; the verdict is computed.

A paper's claims module (the ``paper_replay.claims`` entry point's module) lists its falsifiers
in ``FALSIFIERS``; ``replay falsify`` runs each variant and checks that its row then "differs".
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

KINDS = ("measured", "configuration", "paper")


@dataclass
class Claim:
    quantity: str
    stated: str  # as the paper states it (with its unit)
    measured: str  # from the run's log, or a computation from the paper's own numbers
    status: str  # reproduced | differs | tie | inconsistent | consistent | note | not run
    note: str = ""
    kind: str = "measured"  # measured | configuration | paper (see the module docstring)

    def __post_init__(self) -> None:
        if self.kind not in KINDS:
            raise ValueError(f"claim {self.quantity!r}: kind {self.kind!r} is not one of {KINDS}")
        if self.kind != "measured" and self.status == "reproduced":
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


def counted(rows: Iterable[Claim], falsifiers: Iterable[Falsifier]) -> tuple[int, int]:
    """(reproduced, of): measured rows only; a reproduced row counts only with a falsifier."""
    rows = [r for r in rows if r.kind == "measured"]
    covered = {f.row for f in falsifiers}
    n_ok = sum(r.status == "reproduced" and r.quantity in covered for r in rows)
    return n_ok, len(rows)


def summary(rows: list[Claim], falsifiers: Iterable[Falsifier] = ()) -> str:
    """One line: the measured count and how many rows of each other kind there are."""
    falsifiers = tuple(falsifiers)
    n_ok, n = counted(rows, falsifiers)
    covered = {f.row for f in falsifiers}
    bare = sum(
        r.kind == "measured" and r.status == "reproduced" and r.quantity not in covered
        for r in rows
    )
    ties = sum(r.kind == "measured" and r.status == "tie" for r in rows)
    other = {k: sum(r.kind == k for r in rows) for k in KINDS[1:]}
    parts = [f"{n_ok} of {n} measured rows reproduced"]
    if bare:
        parts.append(f"{bare} more agree but have no falsifier (not counted)")
    if ties:
        parts.append(f"{ties} tie{'s' if ties > 1 else ''}")
    parts += [f"{v} {k} row{'s' if v != 1 else ''}" for k, v in other.items() if v]
    return "; ".join(parts) + "."


def format_table(
    title: str,
    rows: list[Claim],
    partial: dict[str, list[str]] | None = None,
    falsifiers: Iterable[Falsifier] = (),
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
            f"| {r.quantity} | {r.kind} | {r.stated} | {r.measured} | **{r.status}** | "
            f"{row_note(r, falsifiers)} |"
        )
    lines += ["", summary(rows, falsifiers)]
    return "\n".join(lines)


def row_note(r: Claim, falsifiers: Iterable[Falsifier]) -> str:
    """The row's note, and for a reproduced measured row the falsifier(s) that must flip it
    (`replay falsify`), or that it has none and is not counted."""
    if r.kind != "measured" or r.status != "reproduced":
        return r.note
    names = [f.name for f in falsifiers if f.row == r.quantity]
    tag = f"falsifier: {', '.join(names)}" if names else "no falsifier: not counted"
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
