"""The papers' theses, each with a verdict computed from its ablation tables.

A thesis is one sentence a paper argues for; its verdict ("holds", "holds only when ...", "does
not hold") is decided by a function of the sweep tables that test it (``verdict``:
``module:function`` taking ``{sweep name: rows}``, returning a dict with ``verdict``, ``numbers``
and ``figure``), never written by hand. The report puts them at its top, README.md shows the
stored tables' verdicts (``replay theses --markdown``; a test keeps README equal to it).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

NOT_RUN = "not run"
UNREAD = "not decided"


@dataclass(frozen=True)
class Thesis:
    paper: str  # a registered paper's key (replay.papers)
    claim: str  # the thesis in one sentence
    tables: tuple[str, ...]  # the sweeps (sweeps/NAME.yaml) whose tables decide it
    verdict: str  # module:function({name: rows}) -> {"verdict", "numbers", "figure"}


@dataclass(frozen=True)
class Verdict:
    thesis: Thesis
    verdict: str
    numbers: str
    figure: str  # the ablation whose plot shows it
    source: str  # "stored" | "run here" | "not run"


THESES: tuple[Thesis, ...] = (
    Thesis(
        "namiki2003",
        "Vision at ~1 kHz steering a direct mapping to joint commands catches a ball thrown at "
        "8-10 m/s, without predicting its path.",
        ("catch_rate",),
        "analysis.catching.ablations:thesis",
    ),
    Thesis(
        "namiki2003",
        "Optimising the mapping's polynomial offline under torque and velocity limits reduces "
        "the joints' torque and travel (Figs. 6, 8, 9).",
        ("catch_optimisation",),
        "analysis.catching.ablation_opt:thesis",
    ),
    Thesis(
        "namiki1999",
        "Closing every loop (vision, head, arm, hand) at 1 ms lets the hand grasp an object a "
        "human moves irregularly, without predicting its motion.",
        ("grasp_loops", "grasp_components"),
        "analysis.grasping.ablations:thesis",
    ),
    Thesis(
        "higashimori2007",
        "The 2-step and 3-step strategies stop a sliding, spinning stick whatever the "
        "fingertip-stick friction.",
        ("stick_conditions", "stick_factors", "stick_workspace", "stick_vision"),
        "analysis.stick.ablations:thesis",
    ),
)


def _tables(names: tuple[str, ...], stored_only: bool) -> tuple[dict[str, list[dict]], str]:
    from replay.sweep import ablations
    from replay.sweep.table import read_table

    tables, sources = {}, set()
    for name in names:
        if stored_only:
            path = ablations.STORED_DIR / f"{name}.csv"
            found: tuple[Path | None, str] = (path, "stored") if path.is_file() else (None, "")
        else:
            found = ablations.table_path(name)
        if found[0] is None:
            return {}, NOT_RUN
        tables[name] = read_table(found[0])
        sources.add(found[1])
    return tables, " + ".join(sorted(sources))


def decide(thesis: Thesis, stored_only: bool = False) -> Verdict:
    """The thesis's verdict from its tables (this machine's runs first, unless ``stored_only``)."""
    from replay.sweep.worker import load_function

    tables, source = _tables(thesis.tables, stored_only)
    if source == NOT_RUN:
        run = "; ".join(f"replay ablate {n}" for n in thesis.tables)
        return Verdict(thesis, NOT_RUN, f"run `{run}`", thesis.tables[0], NOT_RUN)
    try:
        said = load_function(thesis.verdict)(tables)
        return Verdict(
            thesis, str(said["verdict"]), _text(said["numbers"]), str(said["figure"]), source
        )
    except Exception as exc:  # noqa: BLE001 - a damaged or foreign table: said, not fatal
        why = f"its table ({source}) could not be read: {type(exc).__name__}: {exc}"
        return Verdict(thesis, UNREAD, why, thesis.tables[0], source)


def _text(numbers) -> str:
    """A verdict's numbers as one line: a mapping as ``key: value; ...`` (nested in parentheses)."""
    if isinstance(numbers, dict):
        inner = [
            f"{k}: {_text(v) if not isinstance(v, dict) else '(' + _text(v) + ')'}"
            for k, v in numbers.items()
        ]
        return "; ".join(inner)
    if isinstance(numbers, bool):
        return "yes" if numbers else "no"
    return str(numbers)


def verdicts(stored_only: bool = False) -> list[Verdict]:
    return [decide(t, stored_only) for t in THESES]


def markdown(rows: list[Verdict]) -> str:
    """The theses as a Markdown table (cells escaped: a table's text is data)."""
    from replay.papers import papers
    from analysis.report.markup import md

    lines = [
        "| paper | thesis | verdict | the numbers that decide it | figure |",
        "|---|---|---|---|---|",
    ]
    for v in rows:
        known = papers()
        paper = known[v.thesis.paper].title if v.thesis.paper in known else v.thesis.paper
        cells = (paper, v.thesis.claim, v.verdict, v.numbers, v.figure)
        lines.append("| " + " | ".join(md(c) for c in cells) + " |")
    return "\n".join(lines)


def html(rows: list[Verdict]) -> str:
    """The theses as an HTML table (every cell escaped)."""
    from replay.papers import papers
    from analysis.report.markup import e

    head = (
        "<tr><th>paper</th><th>thesis</th><th>verdict</th><th>the numbers</th><th>figure</th></tr>"
    )
    body = []
    for v in rows:
        known = papers()
        paper = known[v.thesis.paper].title if v.thesis.paper in known else v.thesis.paper
        cells = (paper, v.thesis.claim, v.verdict, v.numbers, v.figure)
        body.append("<tr>" + "".join(f"<td>{e(c)}</td>" for c in cells) + "</tr>")
    return f'<table class="theses">{head}{"".join(body)}</table>'
