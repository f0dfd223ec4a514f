"""The claims table: each number a paper states against the same quantity measured in a run."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass
class Claim:
    quantity: str
    stated: str  # as the paper states it (with its unit)
    measured: str  # from the run's log, or a computation from the paper's own numbers
    status: str  # reproduced | differs | inconsistent (the paper's numbers disagree)
    note: str = ""


def within(measured: float, stated: float, rel: float = 0.0, abs_: float = 0.0) -> str:
    return "reproduced" if abs(measured - stated) <= abs_ + rel * abs(stated) else "differs"


def format_table(title: str, rows: list[Claim], partial: dict[str, list[str]] | None = None) -> str:
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
    lines += ["| quantity | paper states | this run | status | note |", "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r.quantity} | {r.stated} | {r.measured} | **{r.status}** | {r.note} |")
    n_ok = sum(r.status == "reproduced" for r in rows)
    lines += ["", f"{n_ok} of {len(rows)} reproduced."]
    return "\n".join(lines)
