"""One reproduction report: ``out/report/index.html`` and ``index.md``, made from logs and tables.

Per paper: the regenerated figures (from the runs' logs, with the paper's captions), the claims
table, the ablation plots (each redrawn from its sweep table: this machine's run under
out/ablations/, else the stored one under data/ablations/) with one sentence of what each shows,
computed from the same table; above them a headline across papers (measured rows of the paper's
own experiment reproduced with a falsifier that the stored ``replay falsify --store`` result
shows flipping them, and when that ran; the report lists the falsifiers, it does not run them).
Then the versions, seeds and commands that made it.
Everything the page links to is copied under the report directory, so it is self-contained.

What comes from a log (a run's name, its seed, a caption quoting the name) is data: escaped in
both pages (``markup``), and the report links only files inside its own folder (``folder``).
"""

from __future__ import annotations

import copy

import platform
import re
import shlex
import shutil
from collections.abc import Collection, Sequence
from dataclasses import dataclass, field, replace
from importlib import metadata
from pathlib import Path
from typing import Any

import yaml

from analysis.figure_files import file_stem, runs_of
from analysis.needs import figure_notes, skipped_notes
from replay import registry
from replay.log import LogError, LogReader
from replay.papers import Paper, papers
from analysis.report.folder import check_folder, discard, staging, swap_in
from analysis.report.markup import e as _e
from analysis.report.markup import md, md_code, md_fence, pre, url
from replay.scenario.yamlio import one_line

PACKAGES = (
    "numpy",
    "scipy",
    "pymunk",
    "pybullet",
    "mujoco",
    "opencv-python-headless",
    "mcap",
    "foxglove-sdk",
    "matplotlib",
    "click",
    "pyyaml",
    "viser",
    "ray",
    "tqdm",
)


@dataclass
class Figure:
    png: str  # path relative to the report
    svg: str
    caption: str


@dataclass
class Ablation:
    name: str
    png: str
    svg: str
    caption: str
    shows: str
    table: str
    sweep: str
    source: str  # "run here" | "stored"
    command: str


@dataclass
class PaperSection:
    key: str
    title: str
    authors: str
    runs: list = field(default_factory=list)  # (run key, seed, log path)
    # run key -> (scenario name, its label, the shipped scenario the label is against)
    scenarios: dict = field(default_factory=dict)
    figures: list = field(default_factory=list)
    claims: list = field(default_factory=list)
    claims_md: str = ""
    claims_summary: str = ""
    falsifiers: tuple = ()
    shown: Any = None  # analysis.claims.Shown: the stored `replay falsify --store` result
    ablations: list = field(default_factory=list)
    notes: list = field(default_factory=list)


def _readers(logs: list[Path]) -> tuple[dict[str, dict[str, LogReader]], list[str]]:
    """The readable run logs per paper, one key per log (analysis/runs.py), and a note for
    each log left out."""
    from analysis import runs

    readers, dropped = [], []
    for p in logs:
        try:
            r = LogReader(p)
        except LogError as exc:
            dropped.append(f"{p.name}: not read ({exc})")
            continue
        why = runs.unreadable(r)
        if why:
            dropped.append(f"{p.name}: {why}")
        else:
            readers.append(r)
    return runs.by_paper(readers), dropped


def _shows(runs: Sequence[str], readers: dict[str, LogReader]) -> str:
    """'the run 'a' (label)' / 'the runs 'a', 'b' (label)': each run with what differs."""
    from analysis.runs import describe

    said = []
    for key in runs:
        r = readers.get(key)
        label = describe(r, key).label if r is not None else ""
        said.append(f"{key!r}" + (f" ({label})" if label and label not in key else ""))
    if not said:
        return ""
    return f" Regenerated from the run{'s' if len(said) > 1 else ''} {', '.join(said)}."


def _caption(paper: str, stem: str, shows: str, controllers: Collection[str] = ()) -> str:
    """The paper's caption of the figure ``stem`` draws again (for a figure that draws none,
    what it shows: ``NAMED``), and the runs it ``shows``; "cf." when a run's ``controllers`` are
    not the method the paper's figure is drawn for."""
    m = re.search(r"fig(\d+)", stem)
    num = int(m.group(1)) if m else 0
    registered = papers().get(paper) or Paper(paper, paper, "", "", 0)
    quoted = registered.captions.get(num)
    named = next((t for end, t in registered.named.items() if stem.endswith(end)), stem)
    base = f"Fig. {num}" if num else named
    drawn_for = registered.drawn_for.get(num)
    others = sorted(c for c in controllers if c != drawn_for)
    if quoted and drawn_for and others:
        return (
            f"Cf. {base}, which the paper draws for {drawn_for} (paper: “{quoted}”); this "
            f"figure shows {', '.join(others)}.{shows}"
        )
    return f"{base} (paper: “{quoted}”).{shows}" if quoted else f"{base}.{shows}"


def _controllers(runs, readers) -> set[str]:
    """The controller types of the runs ``runs`` (keys of ``readers``), from their logs."""
    types = set()
    for key in runs:
        r = readers.get(key)
        if r is None:
            continue
        try:
            kind = copy.deepcopy(r.scenario_config())["controller"]["type"]
        except (LogError, yaml.YAMLError, KeyError, TypeError):
            continue
        if isinstance(kind, str):
            types.add(kind)
    return types


def build_report(out: str | Path = "out/report", logs_dir: str | Path = "out/logs") -> Path:
    """Write the report to the folder ``out`` (replaced whole once the new report is complete:
    only a folder the report made, an empty or a new one, else :class:`ReportFolderError`
    before anything is touched); returns its ``index.html``."""
    out = Path(out)
    check_folder(out, Path(logs_dir))
    work = staging(out)
    try:
        _build(work, Path(logs_dir))
        swap_in(work, out)
    except BaseException:
        discard(work)
        raise
    return out / "index.html"


def _inside(path: Path, folder: Path) -> bool:
    """Whether ``path`` is a file inside ``folder`` (what the report may link to)."""
    try:
        return path.resolve().is_relative_to(folder.resolve()) and path.is_file()
    except (OSError, RuntimeError):
        return False


def _build(out: Path, logs_dir: Path) -> None:
    from replay.sweep import ablations
    from replay.sweep.variants import code_version

    (out / "figures").mkdir(parents=True)
    logs = sorted(logs_dir.glob("*.mcap"))
    by_paper, dropped = _readers(logs)
    sections = []
    for key, paper in papers().items():
        sec = PaperSection(key, paper.title, paper.authors)
        readers = by_paper.get(key, {})
        if readers:
            _section_runs(sec, readers)
            _section_figures(sec, key, readers, out)
            _section_claims(sec, key, paper, readers)
        for name in ablations.names():
            sf = ablations.load(name)
            if sf.paper != key:
                continue
            sec.ablations.append(_ablation(sf, out, ablations))
        sections.append(sec)
    info = _provenance(code_version())
    commands = _commands(sections, logs)
    from analysis.engine_rates import COMMAND, TABLE
    from replay.resources import data_path

    if any(COMMAND in c.note for sec in sections for c in sec.claims):  # the stored rate rows'
        (out / "tables").mkdir(exist_ok=True)
        shutil.copy(data_path("ablations", f"{TABLE}.csv"), out / "tables" / f"{TABLE}.csv")
    left = [f"Log left out: {d}" for d in dropped]  # (a log that is no run's is said, not lost)
    said = _theses(left)
    (out / "index.md").write_text(_markdown(sections, info, commands, left, said), encoding="utf-8")
    (out / "index.html").write_text(_html(sections, info, commands, left, said), encoding="utf-8")


def _section_runs(sec: PaperSection, readers: dict) -> None:
    """The section's runs (name, seed, log) and what each is (analysis/runs.py)."""
    from analysis.runs import describe

    for name, r in sorted(readers.items()):
        sc = r.scenario()
        sec.runs.append((name, sc.get("seed", "?"), str(getattr(r, "path", name))))
        run = describe(r, name)
        sec.scenarios[name] = (run.name, run.label, run.experiment)


def _section_figures(sec: PaperSection, key: str, readers: dict, out: Path) -> None:
    """The paper's figures of ``readers`` into ``out/figures``, captioned by the runs they show;
    a figure that cannot be made is said in the section's notes, not fatal."""
    figure_skips: list[str] = []
    try:
        make = registry.load("figures", key)
        with skipped_notes() as figure_skips:
            paths = make(readers, out / "figures")
    except registry.UnknownPlugin:
        paths = []
    except OSError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged or hostile log: said, not fatal
        sec.notes.append(f"No figures: they could not be made from these logs: {exc!r}")
        paths = []
    paths = [p if isinstance(p, Path) else Path(p) for p in paths]
    paths = [p for p in paths if _inside(p, out / "figures")]
    shown: set[str] = set()
    for png in (p for p in paths if p.suffix == ".png"):
        svg = png.with_suffix(".svg")
        runs = runs_of(png, readers)
        shown.update(runs)
        sec.figures.append(
            Figure(
                png.relative_to(out).as_posix(),
                svg.relative_to(out).as_posix() if svg.is_file() else "",
                _caption(key, png.stem, _shows(runs, readers), _controllers(runs, readers)),
            )
        )
    sec.notes += figure_notes(readers, shown, figure_skips)


def _section_claims(sec: PaperSection, key: str, paper, readers: dict) -> None:
    """The paper's claims table over ``readers`` (every engine's side by side), its falsifiers
    and what ``replay falsify --store`` last showed; a table that cannot be made is said."""
    try:
        evaluate = registry.load("claims", key)
        from analysis.claims import falsifiers_of, format_table, summary
        from analysis.claims import shown as falsified
        from analysis.engines import evaluate_runs, split_logs

        with skipped_notes() as skipped:
            sec.claims, engines_note = evaluate_runs(evaluate, readers)
        sec.notes += skipped
        if engines_note:  # the engines of the logs present
            names = ", ".join(split_logs(readers))
            sec.notes.append(f"Physics engines {names} (docs/mujoco.md): {engines_note}")

        sec.falsifiers = falsifiers_of(evaluate)
        sec.shown = falsified(key)  # (what `replay falsify --store` last showed)
        sec.claims_md = format_table(
            paper.title, sec.claims, falsifiers=sec.falsifiers, record=sec.shown
        )
        sec.claims_summary = summary(sec.claims, sec.shown)
    except registry.UnknownPlugin:
        sec.notes.append("No claims table defined yet.")
    except OSError:
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged or hostile log: said, not fatal
        sec.notes.append(f"No claims: they could not be evaluated on these logs: {exc!r}")


def _theses(notes: list[str]) -> list:
    """Each paper's thesis with its verdict from the ablation tables (analysis/theses.py); a
    table that cannot be read is a note, not a failed report."""
    from analysis import theses

    try:
        return theses.verdicts()
    except Exception as exc:  # noqa: BLE001 - a damaged table: said, not fatal
        notes.append(f"No theses: their tables could not be read: {exc!r}")
        return []


THESES_NOTE = (
    "Each verdict is computed from the ablation tables named in its row (this machine's "
    "replay ablate runs, else the stored ones), drawn below under Ablations."
)


def _ablation(sf, out: Path, ablations) -> Ablation:
    from replay.sweep.table import read_table
    from replay.sweep.worker import load_function

    (out / "ablations").mkdir(exist_ok=True)
    (out / "tables").mkdir(exist_ok=True)
    (out / "sweeps").mkdir(exist_ok=True)
    shutil.copy(sf.path, out / "sweeps" / sf.path.name)
    table, source = ablations.table_path(sf.name)
    command = f"replay ablate {sf.name}"
    if table is None or not read_table(table):
        return Ablation(
            sf.name,
            "",
            "",
            sf.caption,
            f"Not run yet: `{command}`.",
            "",
            f"sweeps/{sf.path.name}",
            "not run",
            command,
        )
    shutil.copy(table, out / "tables" / f"{sf.name}.csv")
    paths = ablations.plot(sf, table, out / "ablations")
    png = next(p for p in paths if p.suffix == ".png")
    svg = png.with_suffix(".svg")
    rows = read_table(table)
    shows = load_function(sf.summary)(rows) if sf.summary else ""
    return Ablation(
        sf.name,
        png.relative_to(out).as_posix(),
        svg.relative_to(out).as_posix() if svg.is_file() else "",
        sf.caption,
        shows,
        f"tables/{sf.name}.csv",
        f"sweeps/{sf.path.name}",
        source,
        command,
    )


def _provenance(version: str) -> dict[str, str]:
    info = {
        "paper-replay": version,
        "python": platform.python_version(),
        "platform": platform.platform(),
    }
    from analysis.engines import registered

    for pkg in dict.fromkeys((*PACKAGES, *registered())):  # an engine's name is its package's
        try:
            info[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            info[pkg] = "(not installed)"
    return info


def _shipped_run(name: str, label: str, shipped: str) -> tuple[str, str]:
    """The shipped scenario to run for a run of scenario ``name`` (its nearest, ``shipped``, when
    no shipped scenario has that name) and a comment saying what the run sets differently."""
    if not shipped:
        return name, f"   # {name} is not shipped; its scenario is in its log (replay info)"
    if shipped == name:
        return name, f"   # differs from the shipped {name}: {label}" if label else ""
    what = f"differs from it: {label}" if label else "sets nothing differently"
    return shipped, f"   # {name} is not shipped, its nearest is {shipped}; it {what}"


def _commands(sections, logs) -> list[str]:
    cmds = []
    for sec in sections:
        for key, seed, _ in sec.runs:  # (a log's name and seed quoted for the shell)
            log = f"out/logs/{file_stem(key)}.mcap"
            name, why = _shipped_run(*sec.scenarios.get(key, (key, "", key)))
            why = one_line(why)  # (a log's name and values: a line break would end the comment)
            cmds.append(
                f"replay run {shlex.quote(name)} --seed {shlex.quote(str(seed))} -o {log}{why}"
            )
    if logs:
        cmds += [
            "replay figures out/logs/*.mcap -o out/figures",
            "replay claims out/logs/*.mcap --markdown out/claims.md",
        ]
    papers = [sec.key for sec in sections if sec.falsifiers]
    if papers:
        cmds.append(f"replay falsify {' '.join(papers)} --logs out/logs --store")
    for sec in sections:
        for a in sec.ablations:
            cmds.append(f"{a.command} --store   # table: {a.source}")
    from analysis.engine_rates import COMMAND, TABLE

    if any(COMMAND in c.note for sec in sections for c in sec.claims):
        cmds.append(f"{COMMAND}   # both engines' rates: tables/{TABLE}.csv (stored)")
    cmds.append("replay report")
    return cmds


def _differs(sec: PaperSection, key: str) -> str:
    """'; LABEL' for a run that differs from its shipped scenario, unless its key says it."""
    label = sec.scenarios.get(key, (key, "", key))[1]
    return f"; {label}" if label and label not in key else ""


# -- the headline across papers ---------------------------------------------------------------

HEADLINE = (
    "paper",
    "measured rows reproduced (falsifier shown)",
    "ties",
    "reproduced, falsifier not shown",
    "other regime / extension rows",
    "configuration rows",
    "paper rows",
    "falsifiers last run",
)


def _headline(sections) -> list[tuple[str, ...]]:
    """Per paper with a claims table: its counts (as the table's summary line counts them:
    measured rows of the paper's own experiment, a reproduced one only where the stored
    ``replay falsify --store`` result shows its falsifier flipping it) and when that ran."""
    from analysis.claims import NOT_SHOWN, SHOWN, counted, shown_status

    rows: list[tuple[str, ...]] = []
    for sec in sections:
        if not sec.claims:
            continue
        n_ok, n = counted(sec.claims, sec.shown)
        kinds = [c.kind for c in sec.claims]
        ties = sum(c.kind == "measured" and c.status == "tie" for c in sec.claims)
        bare = sum(shown_status(c, sec.shown) == NOT_SHOWN for c in sec.claims)
        if sec.shown is not None:
            ran = f"{sec.shown.when}, code {sec.shown.code} ({sec.shown.command})"
        elif sec.falsifiers:
            ran = f"never stored: replay falsify {sec.key} --logs out/logs --store"
        else:
            ran = "none declared"
        rows.append(
            (
                sec.title,
                f"{n_ok} / {n}",
                str(ties),
                str(bare),
                str(sum(k in SHOWN for k in kinds)),
                str(kinds.count("configuration")),
                str(kinds.count("paper")),
                ran,
            )
        )
    return rows


HEADLINE_NOTE = (
    "Only measured rows count: claims the paper states, measured on runs of the paper's own "
    "experiment (its stated conditions); rows of other regimes and extensions are shown in the "
    "tables, not counted. A measured row counts as reproduced only if its falsifier (a variant "
    "under which the claim is false in the simulation) was run by replay falsify --store and "
    "turned it to 'differs'; that stored result (data/claims/falsified.json) is what is read "
    "here, with when and on which code version it ran. This report does not run the falsifiers."
)


# -- Markdown --------------------------------------------------------------------------------


def _markdown(sections, info, commands, notes=(), said=()) -> str:
    lines = [
        "# paper-replay: reproduction report",
        "",
        "Every figure below is regenerated from a run's MCAP log; every ablation plot from "
        "its sweep table.",
        "",
    ]
    lines += [x for n in notes for x in (f"> {md(n)}", "")]
    if said:
        from analysis.theses import markdown as theses_markdown

        lines += ["## Theses", "", theses_markdown(list(said)), "", md(THESES_NOTE), ""]
    headline = _headline(sections)
    if headline:
        lines += ["## Summary", "", "| " + " | ".join(HEADLINE) + " |"]
        lines += ["|" + "---|" * len(HEADLINE)]
        lines += ["| " + " | ".join(md(x) for x in row) + " |" for row in headline]
        lines += ["", md(HEADLINE_NOTE), ""]
    for sec in sections:
        lines += [f"## {sec.title}", "", f"*{sec.authors}* (`{sec.key}`)", ""]
        if sec.runs:
            runs = (f"{md_code(n)} (seed {md(s)}{md(_differs(sec, n))})" for n, s, _ in sec.runs)
            lines += ["Runs: " + ", ".join(runs), ""]
        for note in sec.notes:  # every line of a note quoted (the engines' note has three)
            lines += ["\n>\n".join(f"> {md(x)}" for x in note.splitlines()), ""]
        if sec.figures:
            lines += ["### Figures", ""]
            for f in sec.figures:
                cap = md(f.caption)
                lines += [f"![{cap}]({url(f.png)})", "", f"*{cap}*", ""]
        if sec.claims_md:
            table = claims_markdown(sec.title, sec.claims, sec.falsifiers, record=sec.shown)
            lines += ["### Claims", "", table.split("\n", 2)[2], ""]
        if sec.falsifiers:
            from analysis.claims import format_falsifiers

            lines += [
                "#### Falsifiers",
                "",
                "Each reproduced measured row counts only with a variant under which the paper's "
                "claim is false in the simulation; `replay falsify --store` runs them, requires "
                "the row to read *differs* and records it. This report lists them and reads the "
                "record: " + md(_ran(sec)),
                "",
                format_falsifiers(sec.falsifiers),
                "",
            ]
        if sec.ablations:
            lines += ["### Ablations", ""]
            for a in sec.ablations:
                lines += [f"#### {a.name}", ""]
                if a.png:
                    lines += [f"![{a.caption}]({a.png})", ""]
                table = f"Table: [{a.table}]({a.table}) ({a.source}); " if a.table else ""
                lines += [
                    f"*{a.caption}* {a.shows}",
                    "",
                    f"{table}sweep: [{a.sweep}]({a.sweep}); `{a.command}`",
                    "",
                ]
    lines += ["## Versions", "", "| package | version |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in info.items()]
    commands = [one_line(c) for c in commands]
    fence = md_fence(commands)
    lines += ["", "## Commands", "", f"{fence}sh", *commands, fence, ""]
    return "\n".join(lines)


def _ran(sec) -> str:
    """When the falsifiers were last run (the stored record), or that they never were."""
    if sec.shown is None:
        return f"never stored (replay falsify {sec.key} --logs out/logs --store)."
    return sec.shown.line() + "."


def claims_markdown(title: str, rows, falsifiers=(), partial=None, record=None) -> str:
    """``analysis.claims.format_table`` with every cell and log name escaped for Markdown (a
    quantity can name a run): the claims table in index.md and in ``claims --markdown``."""
    from analysis.claims import format_table

    rows = [
        replace(
            c,
            quantity=md(c.quantity),
            stated=md(c.stated),
            measured=md(c.measured),
            note=md(c.note),
        )
        for c in rows
    ]
    falsifiers = [replace(f, row=md(f.row)) for f in falsifiers]
    partial = {md(k): [md(n) for n in v] for k, v in (partial or {}).items()}
    return format_table(title, rows, partial=partial, falsifiers=falsifiers, record=record)


# -- HTML ------------------------------------------------------------------------------------

_STYLE = """
body { font-family: system-ui, sans-serif; max-width: 60rem; margin: 2rem auto; padding: 0 1rem;
       color: #222; line-height: 1.45; }
figure { margin: 1.2rem 0; } figure img { max-width: 100%; border: 1px solid #ddd; }
figcaption { font-size: 0.9rem; color: #444; }
table { border-collapse: collapse; font-size: 0.85rem; margin: 0.8rem 0; }
td, th { border: 1px solid #ccc; padding: 0.25rem 0.5rem; vertical-align: top; }
.reproduced { color: #176317; } .differs { color: #a33; } .inconsistent { color: #a60; }
pre { background: #f5f5f5; padding: 0.6rem; overflow-x: auto; font-size: 0.8rem; }
.note { background: #fff8e0; padding: 0.5rem 0.8rem; border-left: 4px solid #e0b000; }
table.falsifiers { table-layout: fixed; width: 100%; }
table.falsifiers col.row { width: 24%; } table.falsifiers col.variant { width: 30%; }
table.falsifiers col.why { width: 46%; }
table.falsifiers td { overflow-wrap: anywhere; }
table.headline td:nth-child(n+2):nth-child(-n+5) { text-align: right; }
"""

# no script, frame, form or remote resource whatever the page holds: its own images, inline style
_CSP = (
    "default-src 'none'; img-src 'self' file: data:; style-src 'unsafe-inline'; "
    "base-uri 'none'; form-action 'none'"
)


def _html(sections, info, commands, notes=(), said=()) -> str:
    h = [
        "<!doctype html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f'<meta http-equiv="Content-Security-Policy" content="{_CSP}">',
        "<title>paper-replay: reproduction report</title>",
        f"<style>{_STYLE}</style>",
        "</head><body>",
        "<h1>paper-replay: reproduction report</h1>",
        "<p>Every figure below is regenerated from a run's MCAP log; every ablation plot from "
        'its sweep table. <a href="index.md">Markdown version</a>.</p>',
        *(f'<p class="note">{_e(n)}</p>' for n in notes),
        "<nav><ul>",
    ]
    headline = _headline(sections)
    if said:
        h.append('<li><a href="#theses">Theses</a></li>')
    if headline:
        h.append('<li><a href="#summary">Summary</a></li>')
    h += [f'<li><a href="#{_e(s.key)}">{_e(s.title)}</a></li>' for s in sections]
    h += [
        '<li><a href="#versions">Versions</a></li>',
        '<li><a href="#commands">Commands</a></li>',
        "</ul></nav>",
    ]
    if said:
        from analysis.theses import html as theses_html

        h += ['<h2 id="theses">Theses</h2>', theses_html(list(said)), f"<p>{_e(THESES_NOTE)}</p>"]
    if headline:
        h += [
            '<h2 id="summary">Summary</h2>',
            '<table class="headline"><tr>' + "".join(f"<th>{_e(x)}</th>" for x in HEADLINE),
            "</tr>",
        ]
        h += ["<tr>" + "".join(f"<td>{_e(x)}</td>" for x in row) + "</tr>" for row in headline]
        h += ["</table>", f"<p>{_e(HEADLINE_NOTE)}</p>"]
    for sec in sections:
        h += _html_section(sec)
    h += ['<h2 id="versions">Versions</h2>', "<table><tr><th>package</th><th>version</th></tr>"]
    h += [f"<tr><td>{_e(k)}</td><td>{_e(v)}</td></tr>" for k, v in info.items()]
    h += [
        "</table>",
        '<h2 id="commands">Commands</h2>',
        pre(commands),  # (each command on its one line: no forged line from a name)
        "</body></html>",
    ]
    return "\n".join(h) + "\n"


def _html_section(sec) -> list[str]:
    """A paper's section: its runs, notes, figures, claims and ablations."""
    h: list[str] = []
    h += [
        f'<section id="{_e(sec.key)}">',
        f"<h2>{_e(sec.title)}</h2>",
        f"<p><em>{_e(sec.authors)}</em> (<code>{_e(sec.key)}</code>)</p>",
    ]
    if sec.runs:
        h.append(
            "<p>Runs: "
            + ", ".join(
                f"<code>{_e(one_line(n))}</code> (seed {_e(s)}{_e(_differs(sec, n))})"
                for n, s, _ in sec.runs
            )
            + "</p>"
        )
    h += [f'<p class="note">{"<br>".join(map(_e, n.splitlines()))}</p>' for n in sec.notes]
    if sec.figures:
        h.append("<h3>Figures</h3>")
        for f in sec.figures:
            svg = f' <a href="{url(f.svg)}">SVG</a>' if f.svg else ""
            h.append(
                f'<figure><img src="{url(f.png)}" alt="{_e(f.caption)}">'
                f"<figcaption>{_e(f.caption)}{svg}</figcaption></figure>"
            )
    h += _html_claims(sec) + _html_ablations(sec)
    h.append("</section>")
    return h


def _html_claims(sec) -> list[str]:
    """The claims table and, when the paper has them, its falsifiers."""
    h: list[str] = []
    if sec.claims:
        h += [
            "<h3>Claims</h3>",
            "<table><tr><th>quantity</th><th>kind</th><th>paper states</th>"
            "<th>this run</th><th>status</th><th>note</th></tr>",
        ]
        from analysis.claims import row_note, shown_status

        for c in sec.claims:
            status = shown_status(c, sec.shown)
            h.append(
                f"<tr><td>{_e(c.quantity)}</td><td>{_e(c.kind)}</td><td>{_e(c.stated)}</td>"
                f'<td>{_e(c.measured)}</td><td class="{_e(c.status)}"><b>'
                f"{_e(status)}</b></td><td>{_e(row_note(c, sec.falsifiers, sec.shown))}"
                "</td></tr>"
            )
        h += ["</table>", f"<p>{_e(sec.claims_summary)}</p>"]
        if sec.falsifiers:
            h += [
                "<h4>Falsifiers</h4>",
                "<p>Each reproduced measured row counts only with a variant under which the "
                "paper's claim is false in the simulation; <code>replay falsify --store"
                "</code> runs them, requires the row to read <i>differs</i> and records it. "
                f"This report lists them and reads the record: {_e(_ran(sec))}</p>",
                '<table class="falsifiers"><colgroup><col class="row"><col class="variant">'
                '<col class="why"></colgroup><tr><th>row</th><th>variant (the run it '
                "replaces: overrides)</th><th>why the claim is false under it</th></tr>",
            ]
            for f in sec.falsifiers:
                sets = ", ".join(f"{k}={v}" for k, v in f.overrides.items())
                run = f"{f.scenario} " if f.scenario else ""
                h.append(
                    f"<tr><td>{_e(f.row)}</td><td><b>{_e(f.name)}</b><br>replaces "
                    f"{_e(f.replaces)}: <code>{_e(run + sets)}</code></td>"
                    f"<td>{_e(f.why)}</td></tr>"
                )
            h.append("</table>")
    return h


def _html_ablations(sec) -> list[str]:
    """The paper's ablation plots with their tables and sweep files."""
    h: list[str] = []
    if sec.ablations:
        h.append("<h3>Ablations</h3>")
        for a in sec.ablations:
            h.append(f'<h4 id="ablation-{_e(a.name)}">{_e(a.name)}</h4>')
            if a.png:
                svg = f' <a href="{url(a.svg)}">SVG</a>' if a.svg else ""
                h.append(
                    f'<figure><img src="{url(a.png)}" alt="{_e(a.caption)}"><figcaption>'
                    f"{_e(a.caption)} <strong>{_e(a.shows)}</strong>{svg}</figcaption>"
                    "</figure>"
                )
            else:
                h.append(f"<p>{_e(a.caption)} {_e(a.shows)}</p>")
            table = f'<a href="{url(a.table)}">table</a> ({_e(a.source)}), ' if a.table else ""
            h.append(
                f'<p>{table}<a href="{url(a.sweep)}">sweep file</a>; '
                f"<code>{_e(a.command)}</code></p>"
            )
    return h
