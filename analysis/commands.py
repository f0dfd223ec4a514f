"""The analysis commands: ``replay figures``, ``claims``, ``compare``, ``theses``, ``falsify``
and ``report``. The core's command line (replay/cli.py) knows nothing of the papers' analysis:
it adds these through the ``paper_replay.commands`` entry point (pyproject.toml), as any
package may add its own. Bad input gets one line and exit code 2, never a traceback.

Each command imports the analysis it needs when it runs: this module is imported by every
``replay`` process (a ``replay run`` too), where the analysis modules (matplotlib among them)
added ~0.6 s."""

from __future__ import annotations

import sys
from pathlib import Path

import click

from replay import registry
from replay.console import exit_code, fail, note, quoted_warnings, read_log, say, warn, write_text
from replay.log import LogError, LogReader
from replay.log.errors import LogLimitError
from replay.log.output import check_output
from replay.papers import papers as registered
from replay.resources import DEFAULT_LOG_DIR
from replay.scenario import ScenarioError
from replay.scenario.yamlio import one_line

DEFAULT_FIGURE_DIR = Path("out/figures")
# the first line of a `claims --markdown` file: what it may overwrite (an earlier claims table)
CLAIMS_HEADER = "<!-- paper-replay claims table -->"
DEFAULT_COMPARE_DIR = Path("out/compare")
# the first line of a `compare --markdown` file: what it may overwrite (an earlier comparison)
COMPARE_HEADER = "<!-- paper-replay comparison -->"


def _logs_by_paper(logs) -> dict[str, dict[str, LogReader]]:
    from analysis import runs

    paths = logs or sorted(str(p) for p in DEFAULT_LOG_DIR.glob("*.mcap"))
    if not paths:
        fail(f"no logs given and none in {DEFAULT_LOG_DIR}/ (run `replay run SCENARIO` first)")
    readers = []
    for p in paths:
        r = read_log(p)
        why = runs.unreadable(r)
        if why:  # (a colleague's log this version cannot type: the others are still analysed)
            warn(f"left out: {p}: {why}")
            continue
        readers.append(r)
    if not readers:
        fail("none of the logs given is a run log this version reads (see the warnings)")
    return runs.by_paper(readers)  # one key per log: two logs of one name are two runs


def _partial(readers: dict[str, LogReader]) -> dict[str, list[str]]:
    """name -> notes, for the logs that are truncated or damaged."""
    out = {}
    for name, r in readers.items():
        notes = r.describe_problems()
        if notes:
            out[name] = notes
    return out


def _analysis_failed(what: str, paper: str, readers, exc: Exception) -> None:
    partial = _partial(readers)
    why = f" (partial logs: {', '.join(partial)})" if partial else ""
    fail(
        f"{what} for {paper} could not be made from {', '.join(readers)}{why}: "
        f"{type(exc).__name__}: {exc}",
        code=1,
    )


@click.command()
@click.argument("logs", nargs=-1, type=click.Path(dir_okay=False))
@click.option(
    "-o",
    "--out",
    type=click.Path(file_okay=False),
    default=str(DEFAULT_FIGURE_DIR),
    show_default=True,
)
def figures(logs, out):
    """Regenerate the papers' figures (PNG and SVG) from LOGS (default: out/logs/*.mcap)."""
    for paper, readers in _logs_by_paper(logs).items():
        for path in _paper_figures(paper, readers, Path(out)):
            say(f"figure: {path}")


def _paper_figures(paper: str, readers: dict[str, LogReader], out: Path) -> list[Path]:
    """``paper``'s figures of ``readers`` written to ``out``; what they leave out warned."""
    from analysis.figure_files import runs_of
    from analysis.needs import figure_notes, skipped_notes

    try:
        make = registry.load("figures", paper)
    except registry.UnknownPlugin:
        warn(f"{paper}: no figures defined yet ({', '.join(readers)})")
        return []
    made = [d for d in (out, *out.parents) if not d.exists()]  # the folders mkdir will make
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        fail(f"cannot write figures to {out}: {exc.strerror or exc}")
    done = False
    try:
        with quoted_warnings(), skipped_notes() as skipped:
            paths = make(readers, out)
        done = True
    except OSError as exc:
        fail(f"cannot write figures to {out}: {exc.strerror or exc}")
    except LogError as exc:  # (a file there that is not an earlier figure)
        fail(str(exc))
    except Exception as exc:  # noqa: BLE001 - analysis of a damaged log: one line
        _analysis_failed("figures", paper, readers, exc)
    finally:
        for d in made if not done else ():  # made for these figures, none made: not kept
            if d.is_dir() and not any(d.iterdir()):
                d.rmdir()
    paths = [p if isinstance(p, Path) else Path(p) for p in paths]
    shown = {k for p in paths for k in runs_of(p, readers)}
    for text in figure_notes(readers, shown, skipped):
        warn(text)
    for name, notes in _partial(readers).items():
        for text in notes:
            warn(f"{name} is not a finished run ({text}): its figures show only what was logged")
    return paths


@click.command()
@click.argument("logs", nargs=-1, type=click.Path(dir_okay=False))
@click.option("--markdown", type=click.Path(dir_okay=False), help="also write the table here")
def claims(logs, markdown):
    """The papers' stated numbers against the runs in LOGS (default: out/logs/*.mcap)."""
    from analysis.claims import falsifiers_of, format_table, shown
    from analysis.engines import evaluate_runs
    from analysis.needs import skipped_notes
    from analysis.report.builder import claims_markdown
    from analysis.report.markup import md

    sections, md_sections = [], []
    by_paper = _logs_by_paper(logs)
    inputs = {Path(r.path).resolve() for readers in by_paper.values() for r in readers.values()}
    if markdown and (
        Path(markdown).resolve() in inputs or Path(markdown).suffix in (".mcap", ".yaml", ".yml")
    ):
        fail(f"will not write the claims table over {markdown} (a log or a scenario)")
    if markdown:  # (before the analysis: only a new file or an earlier claims table)
        try:
            check_output(Path(markdown), kind="claims table", magic=CLAIMS_HEADER.encode())
        except LogError as exc:
            fail(str(exc))
    for paper, readers in by_paper.items():
        try:
            evaluate = registry.load("claims", paper)
        except registry.UnknownPlugin:
            warn(f"{paper}: no claims defined yet")
            continue
        try:
            with skipped_notes() as skipped:  # (rows left out for a topic a log lacks)
                rows, engines_note = evaluate_runs(evaluate, readers)  # both engines, if both ran
        except LogLimitError as exc:  # a log asking for more than a limit: the input's fault
            fail(str(exc))
        except Exception as exc:  # noqa: BLE001 - analysis of a damaged log: one line
            _analysis_failed("claims", paper, readers, exc)
        skipped = [*_variants_read_as_shipped(readers), *skipped]
        for text in skipped:
            warn(text)
        title = registered()[paper].title if paper in registered() else paper
        partial, falsifiers = _partial(readers), falsifiers_of(evaluate)
        record = shown(paper)  # (what `replay falsify --store` showed flipping)
        closing = f"\n\n{engines_note}" if engines_note else ""
        sections.append(format_table(title, rows, partial, falsifiers, record) + closing)
        left = "".join(f"\n\n> {md(t)}" for t in skipped)  # (a topic a log lacks)
        md_sections.append(
            claims_markdown(title, rows, falsifiers, partial, record) + closing + left
        )
    say("\n\n".join(sections))
    if markdown:  # (the log's names escaped: no raw HTML where the Markdown is rendered)
        text = "\n\n".join([CLAIMS_HEADER, *md_sections]) + "\n"
        write_text(Path(markdown), text, kind="claims table", magic=CLAIMS_HEADER.encode())


def _variants_read_as_shipped(readers: dict[str, LogReader]) -> list[str]:
    """A note per log that changes its scenario yet holds its plain name (no run of the
    scenario as shipped among the logs): its rows are the variant's, not the paper's."""
    from analysis.runs import variants_as_shipped

    return [
        f"{key}: this log is a variant ({label}), not the shipped scenario: the rows that read "
        f"{key} describe the variant (other regime, not counted)"
        for key, label in variants_as_shipped(readers).items()
    ]


@click.command()
@click.option("--stored", is_flag=True, help="only the stored tables (data/ablations/)")
@click.option("--markdown", is_flag=True, help="as the Markdown table README.md shows")
def theses(stored, markdown):
    """Each paper's thesis and its verdict, decided by its ablations' tables (this machine's
    runs under out/ablations/ first, else the stored ones)."""
    from analysis import theses as th

    rows = th.verdicts(stored_only=stored)
    if markdown:
        say(th.markdown(rows))
        return
    for v in rows:
        say(f"{v.thesis.paper}: {v.thesis.claim}")
        say(one_line(f"  {v.verdict}: {v.numbers} ({v.figure}, {v.source})"))


@click.command()
@click.argument("logs", nargs=-1, required=True, type=click.Path(dir_okay=False))
@click.option(
    "-o",
    "--out",
    type=click.Path(file_okay=False),
    default=str(DEFAULT_COMPARE_DIR),
    show_default=True,
    help="where the overlaid figures go",
)
@click.option("--no-figures", is_flag=True, help="only the tables (faster: no figures made)")
@click.option("--markdown", type=click.Path(dir_okay=False), help="also write it here")
def compare(logs, out, no_figures, markdown) -> None:
    """Runs side by side, from their LOGS (2 or more; normally runs of one experiment): the
    scenario fields that differ, each run's outcome and metrics, and the papers' figures
    overlaying them (in -o)."""
    from analysis import compare as comparison
    from analysis import runs

    readers, seen = [], set()
    for p in logs:
        try:
            r = LogReader(p).check()
        except LogError as exc:
            warn(f"left out: {exc}")
            continue
        why = runs.unreadable(r)
        if why:
            warn(f"left out: {p}: {why}")
            continue
        if r.path.resolve() in seen:
            warn(f"left out: {p}: given twice")
            continue
        seen.add(r.path.resolve())
        readers.append(r)
    most = comparison.MAX_RUNS
    if len(readers) > most:
        for r in readers[most:]:
            warn(f"left out: {r.path}: at most {most} runs are compared")
        readers = readers[:most]
    if len(readers) < 2:
        fail(
            f"compare needs 2 readable run logs; {len(readers)} of {len(logs)} given could be read"
        )
    md_path = Path(markdown) if markdown else None
    if md_path is not None:  # (before the analysis: only a new file or an earlier comparison)
        if md_path.resolve() in seen or md_path.suffix in (".mcap", ".yaml", ".yml"):
            fail(f"will not write the comparison over {markdown} (a log or a scenario)")
        try:
            check_output(md_path, kind="comparison", magic=COMPARE_HEADER.encode())
        except LogError as exc:
            fail(str(exc))
    c = comparison.compare(readers)
    say(comparison.text(c))
    for t in c.notes:
        warn(t)
    made: list[Path] = []
    if not no_figures:
        for paper, keyed in runs.by_paper(readers).items():
            made += _paper_figures(paper, keyed, Path(out))
        for path in made:
            say(f"figure: {path}")
    if md_path is not None:
        import os

        base = md_path.resolve().parent
        shown = [
            (p.stem, Path(os.path.relpath(p.resolve(), base)).as_posix())
            for p in made
            if p.suffix == ".png"
        ]
        body = comparison.markdown(c, shown)
        write_text(
            md_path, f"{COMPARE_HEADER}\n{body}", kind="comparison", magic=COMPARE_HEADER.encode()
        )
        say(f"markdown: {md_path}")


@click.command()
@click.argument("papers", nargs=-1)
@click.option(
    "--logs",
    "logs_dir",
    type=click.Path(file_okay=False, exists=True),
    help="baseline logs from this folder (e.g. out/logs), not fresh runs (left out: a variant, a "
    "log not whole, a second log of one name)",
)
@click.option(
    "--keep",
    type=click.Path(file_okay=False),
    help="write the runs here and keep them (default: a temporary folder)",
)
@click.option(
    "--store",
    is_flag=True,
    help="record the verdicts (when, code version, rows flipped) in data/claims/falsified.json",
)
def falsify(papers, logs_dir, keep, store):
    """Run each claims row's falsifier (a variant under which the paper's claim is false) and
    require its row to read "differs"; one line per falsifier (row | variant | verdict). Exits 1
    if a measured reproduced row has no falsifier or is not flipped by it. PAPERS default to
    every paper with a claims table. With --store the result is kept, and the claims table
    counts a reproduced row only if it is recorded as flipped."""
    from analysis import falsify as fz

    import tempfile

    names = list(papers) or [p for p in registered() if _has_claims(p)]
    for p in names:
        if not _has_claims(p):
            known = ", ".join(q for q in registered() if _has_claims(q))
            fail(f"{p}: no claims table (known: {known})")
    failed = 0
    with tempfile.TemporaryDirectory(prefix="replay-falsify-") as tmp:
        work = Path(keep) if keep else Path(tmp)
        for paper in names:
            try:
                verdicts = fz.falsify_paper(
                    paper,
                    work / paper,
                    Path(logs_dir) if logs_dir else None,
                    progress=note,
                )
            except (LogError, ScenarioError) as exc:
                fail(f"{paper}: {one_line(str(exc))}", code=1)
            click.echo(f"## {paper}")
            for v in verdicts:
                say(v.line())
            bad = sum(not v.ok for v in verdicts)
            ran = sum(bool(v.status) for v in verdicts)
            click.echo(f"{paper}: {ran} falsifiers run, {bad} failing")
            if store:
                how = f" --logs {logs_dir}" if logs_dir else ""
                path = fz.store(paper, verdicts, f"replay falsify {paper}{how} --store")
                note(f"{paper}: stored in {path}")
            failed += bad
    if failed:
        sys.exit(1)


def _has_claims(paper: str) -> bool:
    try:
        registry.load("claims", paper)
    except registry.UnknownPlugin:
        return False
    return True


@click.command()
@click.option(
    "-o", "--out", type=click.Path(file_okay=False), default="out/report", show_default=True
)
@click.option(
    "--logs",
    type=click.Path(file_okay=False),
    default="out/logs",
    show_default=True,
    help="the runs whose figures and claims go in",
)
def report(out, logs):
    """Write the reproduction report (index.html and index.md): per paper the regenerated
    figures, the claims table and the ablation plots; versions, seeds and commands."""
    from analysis.report import ReportFolderError, build_report

    if not Path(logs).is_dir():
        note(f"no {logs}/: the report has no figures or claims (run `make run`)")
    try:
        with quoted_warnings():
            path = build_report(out, logs)
    except ReportFolderError as exc:  # (nothing touched)
        fail(str(exc))
    except OSError as exc:  # a read-only or full disk: one line (1: the disk, 2: the folder)
        where = f" ({exc.filename})" if exc.filename else ""
        fail(f"cannot write the report to {out}{where}: {exc.strerror or exc}", code=exit_code(exc))
    say(f"report: {path} (and {path.with_suffix('.md')})")


def register(group: click.Group) -> None:
    """Add the analysis commands to the ``replay`` group (the ``paper_replay.commands`` entry
    point)."""
    for command in (figures, claims, theses, compare, falsify, report):
        group.add_command(command)
