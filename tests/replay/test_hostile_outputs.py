"""Hostile logs and output paths (issue #36): ``report``, ``figures`` and ``claims --markdown``
write only the files they name or a folder they own, file names from a log stay one component
inside the output folder, what a log holds is escaped in the report and on the terminal.

The hostile logs are a real stick_3step run (~0.3 s) copied with its /scenario message changed
(the loader refuses such names, so only a forged log carries them)."""

from __future__ import annotations

import hashlib
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from analysis import runs as run_labels
from analysis.figure_files import STEM_LENGTH, file_stem
from analysis.commands import CLAIMS_HEADER
from replay.log import LogReader, LogWriter
from replay.messages import TOPIC_EVENTS, TOPIC_SCENARIO
from analysis.report.folder import MARKER

from cli_checks import invoke, one_error

CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # (newline and tab aside)
SAFE_FILE = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*")


def tree(root: Path) -> dict[str, str]:
    """Every file and folder under ``root`` with a hash of its content: what must not change."""
    out = {}
    for p in sorted(root.rglob("*")):
        rel = p.relative_to(root).as_posix()
        if p.is_symlink():
            out[rel] = "-> " + str(p.readlink())
        elif p.is_file():
            out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
        else:
            out[rel] = "dir"
    return out


def forge(base: Path, out: Path, outcome: dict | None = None, **fields) -> Path:
    """A copy of the log ``base`` whose /scenario message has ``fields`` (name, seed, paper)
    and, with ``outcome``, whose outcome event's data is that."""
    out.parent.mkdir(parents=True, exist_ok=True)
    with LogWriter(out) as w:
        for m in LogReader(base).messages():
            data = m.data
            if m.topic == TOPIC_SCENARIO:
                data = dict(data, **fields)
            elif m.topic == TOPIC_EVENTS and outcome is not None and data["kind"] == "outcome":
                data = dict(data, data=outcome)
            w.write(m.topic, data, m.t_ns)
    return out


ESCAPES = "a\x1b]0;PWNED TITLE\x07\x1b[2J\x1b[1;1Hb\rfigure: /etc/forged\nc"
NAMES = [
    "../../escaped/PWNED",  # the reproducer
    "..",
    ".hidden",
    "-rf",
    "a\\..\\..\\b",
    "nul\x00in\x00it",
    ESCAPES,
    "x' onerror='alert(1)\" <b>",
    "é" * 10 + "/" + "n" * 400,
    "a$\\frac{$b",  # mathtext that does not parse: a title is plain text
]


# -- file names from a log ------------------------------------------------------------------


@pytest.mark.parametrize("name", [*NAMES, "/abs/PWNED", "", "a" * 5000, "\u2028", "ok.name-1"])
def test_a_file_stem_is_one_safe_bounded_component(name):
    stem = file_stem(name)
    assert SAFE_FILE.fullmatch(stem) and len(stem) <= STEM_LENGTH, stem
    assert Path(stem).name == stem and stem not in (".", "..")


def test_a_valid_name_is_kept_and_different_names_never_share_a_file():
    assert file_stem("stick_3step_fig7") == "stick_3step_fig7"
    names = ["a/b", "a_b", "a\\b", "a b", "a" * 300, "a" * 301, "..", "."]
    assert len({file_stem(n) for n in names}) == len(names)


def test_figures_of_hostile_names_stay_in_the_output_folder(stick_3step_log, tmp_path, monkeypatch):
    """`replay figures LOG -o figs/a` for a log named ../../escaped/PWNED (and the others):
    every file inside figs/a, one safe name each; the terminal gets no control character."""
    work = tmp_path / "work" / "deep"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    absolute = tmp_path / "abs" / "PWNED"
    logs = [
        forge(stick_3step_log, tmp_path / "logs" / f"{i}.mcap", name=n) for i, n in enumerate(NAMES)
    ]
    logs.append(forge(stick_3step_log, tmp_path / "logs" / "abs.mcap", name=str(absolute)))
    before = tree(tmp_path)
    r = invoke("figures", *logs, "-o", "figs/a")
    assert r.exit_code == 0, r.output
    new = {k for k in tree(tmp_path).keys() - before.keys()}
    figs = "work/deep/figs/a/"
    assert {"work/deep/figs", "work/deep/figs/a"} <= new
    made = sorted(k for k in new if k.startswith(figs))
    assert len(made) == 2 * len(logs), made  # a PNG and an SVG for every log, none shared
    assert new == {"work/deep/figs", "work/deep/figs/a", *made}, new  # nothing elsewhere
    assert all(SAFE_FILE.fullmatch(k[len(figs) :]) for k in made), made
    assert not (tmp_path / "escaped").exists() and not absolute.parent.exists()
    assert not CONTROL.search(r.output), repr(r.output)
    lines = r.stdout.splitlines()
    assert len(lines) == 2 * len(logs) and all(line.startswith("figure: ") for line in lines)
    assert not any("/etc/forged" in line for line in lines)  # no forged line


def test_figures_do_not_overwrite_a_file_they_did_not_make(stick_3step_log, tmp_path):
    figs = tmp_path / "figs"
    figs.mkdir()
    mine = figs / "stick_3step_fig7.png"
    mine.write_text("my notes, not a figure")
    r = invoke("figures", stick_3step_log, "-o", figs)
    assert "will not overwrite" in one_error(r)
    assert mine.read_text() == "my notes, not a figure"
    mine.unlink()
    assert invoke("figures", stick_3step_log, "-o", figs).exit_code == 0
    assert (
        invoke("figures", stick_3step_log, "-o", figs).exit_code == 0
    )  # its own figures: replaced


def test_info_escapes_what_an_outcome_event_holds(stick_3step_log, tmp_path):
    log = forge(
        stick_3step_log,
        tmp_path / "x.mcap",
        name=ESCAPES,
        outcome={"success": True, "reason": ESCAPES, ESCAPES: ESCAPES},
    )
    r = invoke("info", log)
    assert r.exit_code == 0, r.output
    assert not CONTROL.search(r.output), repr(r.output)
    assert "forged" in r.stdout and "\nfigure: /etc/forged" not in r.stdout


# -- report: the folder it replaces -----------------------------------------------------------


@pytest.fixture
def site(stick_3step_log, tmp_path, monkeypatch):
    """tmp/work (the working folder, with files of its own) and tmp/work/logs with one log;
    the report's content is a stub (the folder is what these tests are about: ms, not s)."""
    import analysis.report.builder as builder

    def stub(out, logs_dir):
        (out / "figures").mkdir()
        (out / "figures" / "a.png").write_bytes(b"\x89PNG\r\n\x1a\n")
        (out / "index.html").write_text(f"report of {sorted(logs_dir.glob('*.mcap'))}")
        (out / "index.md").write_text("report")

    monkeypatch.setattr(builder, "_build", stub)
    work = tmp_path / "work"
    (work / "logs").mkdir(parents=True)
    (work / "main.py").write_text("print('mine')\n")
    (work / "notes").mkdir()
    (work / "notes" / "a.txt").write_text("mine\n")
    forge(stick_3step_log, work / "logs" / "s.mcap", name="stick_3step")
    monkeypatch.chdir(work)
    return work


@pytest.mark.parametrize(
    "out, logs, why",
    [
        (".", "logs", "working folder"),  # the reproducer: `-o .`
        (".", "../empty", "working folder"),  # ... with no logs at all
        ("..", "logs", "working folder"),
        ("{root}", "logs", "working folder"),
        ("logs", "logs", "holds the logs"),  # `--logs L -o L`
        ("logs/", "./logs/../logs", "holds the logs"),
        ("notes", "logs", "not empty"),  # a foreign folder
        ("main.py", "logs", "is a file"),
        ("link", "logs", "symbolic link"),
    ],
)
def test_report_refuses_a_folder_it_does_not_own_before_touching_anything(site, out, logs, why):
    (site / "link").symlink_to(site / "notes")
    (site.parent / "empty").mkdir(exist_ok=True)
    before = tree(site.parent)
    r = invoke("report", "-o", out.format(root=site.anchor), "--logs", logs)
    assert why in one_error(r)
    assert tree(site.parent) == before  # nothing made, nothing removed


def test_report_refuses_a_parent_of_the_logs(stick_3step_log, tmp_path, monkeypatch):
    logs = tmp_path / "data" / "runs" / "logs"
    forge(stick_3step_log, logs / "s.mcap", name="stick_3step")
    (tmp_path / "elsewhere").mkdir()
    monkeypatch.chdir(tmp_path / "elsewhere")
    before = tree(tmp_path)
    r = invoke("report", "-o", tmp_path / "data", "--logs", logs)
    assert "holds the logs" in one_error(r)
    assert tree(tmp_path) == before


def test_report_replaces_its_own_folder_and_keeps_it_when_a_build_fails(site, monkeypatch):
    assert invoke("report", "-o", "rep", "--logs", "logs").exit_code == 0
    assert (site / "rep" / MARKER).is_file() and (site / "rep" / "figures").is_dir()
    stale = site / "rep" / "figures" / "stale.png"
    stale.write_bytes(b"\x89PNG\r\n\x1a\nold")
    r = invoke("report", "-o", "rep", "--logs", "logs")
    assert r.exit_code == 0, r.output
    assert not stale.exists() and (site / "rep" / "index.html").is_file()  # replaced whole
    good = tree(site / "rep")

    import analysis.report.builder as builder

    def broken(out, logs_dir):
        (out / "index.html").write_text("half a report")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(builder, "_build", broken)
    r = invoke("report", "-o", "rep", "--logs", "logs")
    assert r.exit_code == 1 and "No space left" in r.stderr
    assert tree(site / "rep") == good  # the earlier report as it was
    assert sorted(p.name for p in site.iterdir()) == ["logs", "main.py", "notes", "rep"]


def test_report_takes_an_empty_folder_a_new_one_and_never_one_without_its_marker(site):
    (site / "empty").mkdir()
    for out in ("empty", "new/deeper", "logs/report"):  # (a folder inside --logs is no harm)
        r = invoke("report", "-o", out, "--logs", "logs")
        assert r.exit_code == 0, r.output
        assert (site / out / MARKER).is_file() and (site / out / "index.html").is_file()
    old = site / "old"  # looks like a report (a copy of its pages, or one from before the marker)
    old.mkdir()
    (old / "figures").mkdir()
    (old / "index.html").write_text(
        "<!doctype html>\n<html lang='en'><head><meta charset='utf-8'>\n"
        "<title>paper-replay: reproduction report</title>\n"
    )
    assert "not empty" in one_error(invoke("report", "-o", "old", "--logs", "logs"))
    assert (old / "index.html").is_file() and not (old / MARKER).exists()
    (site / "notes" / "index.html").write_text(
        "<title>paper-replay: reproduction report</title>"
    )  # ... nor with a file of the user's beside it
    assert "not empty" in one_error(invoke("report", "-o", "notes", "--logs", "logs"))
    assert (site / "notes" / "a.txt").read_text() == "mine\n"


# -- report: what a log holds is data ---------------------------------------------------------


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links: list[str] = []
        self.tags: list[str] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.links += [v for k, v in attrs if k in ("src", "href") and v is not None]
        for k, v in attrs:
            assert not k.startswith("on"), (tag, k, v)  # no event handler attribute


PAYLOADS = {
    "name": [
        "../../escaped/PWNED",
        'run<iframe style=display:none srcdoc="<script>alert(1)</script>"></iframe>',
        "x' onerror='alert(1)' y",
        'y" onerror="alert(2)" z',
        "javascript:alert(3)",
        "a`<script>alert(4)</script>`b\n\n<script>alert(5)</script>",
        "```\n<script>alert(6)</script>",
        "[link](javascript:alert(7))",
        "evil\u202egnp.exe\x1b]0;TITLE\x07\x1b[2J",  # bidi override, OSC, clear screen
    ],
    "seed": ["<script>alert(1)</script>", "1; rm -rf ~", {"a": "<b>"}],
}


@pytest.fixture(scope="module")
def hostile_report(stick_3step_log, tmp_path_factory):
    root = tmp_path_factory.mktemp("hostile")
    logs = root / "logs"
    for i, name in enumerate(PAYLOADS["name"]):
        seed = PAYLOADS["seed"][i % len(PAYLOADS["seed"])]
        forge(stick_3step_log, logs / f"{i}.mcap", name=name, seed=seed)
    before = tree(root)
    r = invoke("report", "-o", root / "report", "--logs", logs)
    assert r.exit_code == 0, r.output
    assert not CONTROL.search(r.output)
    made = tree(root).keys() - before.keys()
    assert all(k == "report" or k.startswith("report/") for k in made), made
    return root / "report"


def test_report_escapes_every_payload_in_html(hostile_report):
    text = (hostile_report / "index.html").read_text(encoding="utf-8")
    parser = _Links()
    parser.feed(text)
    assert "script" not in parser.tags and "iframe" not in parser.tags
    assert "<script" not in text.lower() and "<iframe" not in text.lower()
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in text  # shown, as text
    assert "x&#x27; onerror=&#x27;alert(1)&#x27; y" in text
    figures = [link for link in parser.links if link.startswith("figures/")]
    assert len(figures) >= 2 * len(PAYLOADS["name"]), parser.links
    for link in parser.links:  # every link: an anchor or a file inside the report
        if link.startswith("#"):
            continue
        assert ":" not in link and not link.startswith("/") and ".." not in link.split("/")
        assert (hostile_report / link).resolve().is_relative_to(hostile_report.resolve())
        assert (hostile_report / link).is_file(), link


def test_report_html_holds_no_control_or_format_character(hostile_report):
    """A name's ESC, BEL and U+202E are shown escaped in the page (the run list too), never
    raw: they would reorder the text around them or reach a terminal that prints the page."""
    text = (hostile_report / "index.html").read_text(encoding="utf-8")
    raw = re.findall(r"[\x00-\x08\x0b-\x1f\x7f-\x9f\u200b-\u200f\u202a-\u202e\u2066-\u2069]", text)
    assert not raw, raw
    assert "<code>evil\\u202egnp.exe\\x1b]0;TITLE\\x07\\x1b[2J</code>" in text


def test_report_escapes_every_payload_in_markdown(hostile_report):
    text = (hostile_report / "index.md").read_text(encoding="utf-8")
    body, commands = text.split("## Commands", 1)
    outside_code = re.sub(r"(`+)(?!`).*?(?<!`)\1(?!`)", "", body)  # (code shows text)
    assert "<script" not in outside_code.lower() and "<iframe" not in outside_code.lower()
    # a seed that is no integer is left out by the reader (LogReader.scenario): "?"
    assert "(seed ?)" in text and "alert(1)</script>)" not in text
    assert "](javascript:" not in outside_code
    assert "\n\n<" not in text  # no HTML block from a name's blank line
    fence = re.match(r"\s*(`{3,})sh\n", commands)
    assert fence, commands[:200]
    inner = commands[fence.end() :]
    assert inner.count(fence.group(1)) == 1  # the payload's ``` does not close the block
    for line in inner.splitlines():  # a name and a seed are one shell word each
        if line.startswith("replay run "):
            assert "rm -rf ~'" in line or "rm -rf" not in line, line
            log = line.split(" -o ", 1)[1].partition("   # ")[0]  # (then what it differs in)
            assert log.startswith("out/logs/") and SAFE_FILE.fullmatch(log[len("out/logs/") :])
    block = inner[: inner.index(fence.group(1))].splitlines()
    assert all(line.startswith("replay ") for line in block if line), block  # no line broken off


# -- claims --markdown ------------------------------------------------------------------------


def test_claims_markdown_overwrites_only_an_earlier_table(stick_3step_log, tmp_path):
    main_py = tmp_path / "main.py"
    main_py.write_text("print('mine')\n")
    (tmp_path / "empty.md").write_text("")
    (tmp_path / "folder").mkdir()
    for target in (main_py, tmp_path / "empty.md", tmp_path / "folder", stick_3step_log):
        r = invoke("claims", stick_3step_log, "--markdown", target)
        assert one_error(r)
    assert main_py.read_text() == "print('mine')\n" and (tmp_path / "empty.md").read_text() == ""
    table = tmp_path / "claims.md"
    assert invoke("claims", stick_3step_log, "--markdown", table).exit_code == 0
    first = table.read_text()
    assert first.startswith(CLAIMS_HEADER + "\n") and "| quantity |" in first
    assert (
        invoke("claims", stick_3step_log, "--markdown", table).exit_code == 0
    )  # its own: rewritten


def test_claims_escapes_a_hostile_name_in_markdown_and_on_the_terminal(stick_3step_log, tmp_path):
    name = "<script>alert(1)</script>" + ESCAPES
    log = forge(stick_3step_log, tmp_path / "x.mcap", name=name)
    data = log.read_bytes()
    log.write_bytes(data[: len(data) * 9 // 10])  # truncated: the table names it
    table = tmp_path / "claims.md"
    r = invoke("claims", log, "--markdown", table)
    assert r.exit_code == 0, r.output
    assert not CONTROL.search(r.output), repr(r.output)
    text = table.read_text()
    assert "&lt;script&gt;" in text and "<script" not in text
    assert not CONTROL.search(text)


def test_validate_names_a_hostile_file_name_without_its_escapes(tmp_path):
    path = tmp_path / "a\x1b]0;PWNED\x07\rb.yaml"
    path.write_text("extends: stick_3step\n", encoding="utf-8")
    r = invoke("validate", "--static", path)
    assert r.exit_code == 0, r.output
    assert r.stdout.startswith("ok: ") and not CONTROL.search(r.stdout.rstrip("\n")), repr(r.stdout)


def test_the_report_removes_only_what_it_made(tmp_path):
    """swap_in checks the old folder again (it may change during a build): a folder that became
    foreign is not removed; discard removes a staging folder only (its marker inside)."""
    from analysis.report.folder import MARKER, ReportFolderError, discard, staging, swap_in

    target = tmp_path / "report"
    target.mkdir()
    (target / "thesis.tex").write_text("mine")
    work = staging(target)
    with pytest.raises(ReportFolderError, match="changed during the build"):
        swap_in(work, target)
    assert (target / "thesis.tex").read_text() == "mine"
    discard(work)
    assert not work.exists()
    foreign = tmp_path / "foreign"
    foreign.mkdir()
    (foreign / "data.csv").write_text("1")
    discard(foreign)  # no marker: left alone
    assert (foreign / "data.csv").is_file() and not (foreign / MARKER).exists()
    # a folder that only looks like a report (its pages copied, no marker) is not replaced
    copy = tmp_path / "pages"
    copy.mkdir()
    (copy / "index.html").write_text("<title>paper-replay: reproduction report</title>")
    with pytest.raises(ReportFolderError, match="changed during the build"):
        swap_in(staging(copy), copy)
    assert (copy / "index.html").is_file()
    # a marker that is a link to a file, or a file of other text, makes no folder a report
    elsewhere = tmp_path / "note.txt"
    elsewhere.write_text("made by `replay report`, which replaces this folder whole\n")
    for name, make in (
        (".linked.part", lambda m: m.symlink_to(elsewhere)),
        (".forged.part", lambda m: m.write_text("anything")),
    ):
        fake = tmp_path / name
        fake.mkdir()
        (fake / "thesis.tex").write_text("mine")
        make(fake / MARKER)
        discard(fake)
        assert (fake / "thesis.tex").read_text() == "mine"
        with pytest.raises(ReportFolderError, match="changed during the build"):
            swap_in(staging(fake), fake)
        assert (fake / "thesis.tex").read_text() == "mine"


def test_a_stored_name_no_scenario_may_have_does_not_sink_the_paper(stick_3step_log, tmp_path):
    """A colleague's log whose stored YAML names the run '<img ...>/../../pwn' (a name no
    scenario here may have) and a controller not installed here: figures, claims and report
    read it (its name as data) beside a good log; nothing written outside, no markup."""
    import yaml

    stored = yaml.safe_load(LogReader(stick_3step_log).scenario()["yaml"])
    stored.update(name="<img src=x onerror=alert(1)>/../../pwn")
    stored["controller"]["type"] = "their_pkg:Magic"
    bad = forge(stick_3step_log, tmp_path / "logs" / "bad.mcap", yaml=yaml.safe_dump(stored))
    good = forge(stick_3step_log, tmp_path / "logs" / "good.mcap")
    r = invoke("figures", bad, good, "-o", tmp_path / "figs")
    assert r.exit_code == 0 and "Traceback" not in r.output, r.output
    assert len(list((tmp_path / "figs").glob("*fig7*.png"))) == 2, r.output  # one each
    assert not list(tmp_path.rglob("pwn*")) and not CONTROL.search(r.stdout)
    r = invoke("claims", bad, good)
    assert r.exit_code == 0, r.output
    r = invoke("report", "-o", tmp_path / "report", "--logs", tmp_path / "logs")
    assert r.exit_code == 0, r.output
    html = (tmp_path / "report" / "index.html").read_text(encoding="utf-8")
    assert "<img src=x" not in html and "Log left out" not in html


@pytest.mark.parametrize("what", ["a value of the wrong type", "another machine's engine"])
def test_a_stored_scenario_that_does_not_load_here_is_left_out_alone(
    stick_3step_log, tmp_path, what
):
    """One log whose stored scenario does not type here (tampered, or run with an engine
    plug-in this machine lacks) is left out with one line naming why; the paper's other logs
    are still analysed (before, the paper's figures and claims failed whole, exit 1)."""
    import yaml

    from replay.api import run

    if what == "a value of the wrong type":
        base = stick_3step_log
        stored = yaml.safe_load(LogReader(base).scenario()["yaml"])
        stored["plant"]["params"]["initial"]["vy"] = "fast"
    else:
        base = tmp_path / "catch.mcap"
        run("catch_optimised", set={"timing.duration": 0.02}, log=base)
        stored = yaml.safe_load(LogReader(base).scenario()["yaml"])
        stored["plant"]["params"]["engine"] = {"type": "their_engine", "their_setting": 1}
    bad = forge(base, tmp_path / "logs" / "bad.mcap", yaml=yaml.safe_dump(stored))
    good = forge(base, tmp_path / "logs" / "good.mcap")
    for command in (["claims"], ["figures", "-o", tmp_path / "figs"]):
        r = invoke(*command, bad, good)
        assert r.exit_code == 0 and "Traceback" not in r.output, r.output
        left = [line for line in r.stderr.splitlines() if "bad.mcap" in line]
        assert len(left) == 1 and left[0].startswith("warning: left out: "), r.stderr
        assert ("fast" if what.startswith("a value") else "their_engine") in left[0]
    assert list((tmp_path / "figs").glob("*.png")), "the good log's figures"


# -- a log's event count does not set a figure's cost ----------------------------------------


def _with_events(base: Path, out: Path, kind: str, n: int, t0: float, t1: float) -> Path:
    """A copy of the log ``base`` with ``n`` more events of ``kind`` between ``t0`` and ``t1``."""
    with LogWriter(out) as w:
        for m in LogReader(base).messages():
            w.write(m.topic, m.data, m.t_ns)
        for i in range(n):
            t = t0 + (t1 - t0) * i / n
            w.write(TOPIC_EVENTS, {"t": t, "kind": kind, "data": {"index": i}}, int(t * 1e9))
    return out


def test_a_log_full_of_collisions_draws_a_bounded_fig7(stick_3step_log, tmp_path):
    """A log of 3,000 forged collision events: every one was a dashed line on both panels and
    a label placed against all others (~190 s, quadratic); now the first MAX_MARKS are drawn
    and the footer says so, and `figures` stays quick."""
    from analysis.stick import figures as stick_figures
    from analysis.line_labels import MAX_MARKS, MORE

    log = _with_events(stick_3step_log, tmp_path / "many.mcap", "collision", 3000, 0.1, 1.8)
    fig = stick_figures.fig7(LogReader(log))
    for ax in fig.axes:
        assert len([x for x in ax.lines if x.get_linestyle() == "--"]) == MAX_MARKS
    assert len(fig.axes[0].texts) <= MAX_MARKS
    assert any(MORE in t.get_text() for t in fig.texts)
    r = invoke("figures", log, "-o", tmp_path / "figs")
    assert r.exit_code == 0, r.output
    assert len(list((tmp_path / "figs").glob("*fig7*"))) == 2
    doc = (Path(__file__).resolve().parents[2] / "docs" / "security.md").read_text("utf-8")
    assert f"draws at most {MAX_MARKS} event marks of a kind" in doc


def test_a_good_runs_fig7_is_not_capped(stick_3step_log):
    from analysis.stick import figures as stick_figures
    from analysis.line_labels import MORE

    fig = stick_figures.fig7(LogReader(stick_3step_log))
    collisions = [e for e in LogReader(stick_3step_log).events() if e["kind"] == "collision"]
    dashed = [x for x in fig.axes[0].lines if x.get_linestyle() == "--"]
    assert 0 < len(dashed) == len(collisions)
    assert not any(MORE in t.get_text() for t in fig.texts)


def test_catch_and_grasp_marks_are_bounded_too():
    """Catch figures' catch/miss/drop lines, grasp Fig. 9's phases, events and slip ticks: at
    most MAX_MARKS of a kind, and the footer says so."""
    from types import SimpleNamespace

    import matplotlib.pyplot as plt

    from analysis.catching import figures as catch_figures
    from analysis.grasping import figures as grasp_figures
    from analysis.grasping.run import RELEASING, REACHING, Phase
    from analysis.line_labels import MAX_MARKS, MORE

    n = 5 * MAX_MARKS
    evs = [{"t": 0.2 + 0.5 * i / n, "kind": k, "data": {}} for i in range(n) for k in ("miss",)]
    catch = SimpleNamespace(t0=0.1, t_c=0.15, events=evs, first_event=lambda kind: None)
    fig, ax = plt.subplots()
    ax.set_xlim(0.0, 1.0)
    drawn: set[str] = set()
    marks = catch_figures._marks(ax, catch, {}, drawn)
    assert len(marks) == len(ax.lines) == 2 + MAX_MARKS
    assert MORE in catch_figures._lines_said(drawn)
    plt.close(fig)

    names = [REACHING, RELEASING] * n
    phases = [Phase(name, i * 0.01, (i + 1) * 0.01) for i, name in enumerate(names)]
    kinds = [{"t": i * 0.01, "kind": k, "data": {}} for i in range(n) for k in ("grasp", "slip")]
    grasp = SimpleNamespace(phases=phases, events=kinds)
    fig, ax = plt.subplots()
    drawn = grasp_figures._shade(ax, grasp)
    assert len(ax.patches) == MAX_MARKS  # the shaded phases
    assert len(ax.lines) == MAX_MARKS + 1  # grasp events, one rug of slips
    assert len(ax.lines[-1].get_xdata()) == MAX_MARKS
    assert MORE in grasp_figures._footer(drawn)
    plt.close(fig)


def test_a_figure_title_shows_a_names_control_characters_escaped(stick_3step_log, tmp_path):
    """Fig. 7's title of a run named with ESC/OSC/CR: escaped text, no raw control character
    (matplotlib had none of their glyphs and warned once for each)."""
    from analysis.stick import figures as stick_figures

    log = forge(stick_3step_log, tmp_path / "esc.mcap", name=ESCAPES)
    r = invoke("figures", log, "-o", tmp_path / "figs")
    assert r.exit_code == 0 and "Glyph" not in r.output, r.output
    title = stick_figures.fig7(LogReader(log), run_labels.titled(ESCAPES, LogReader(log)))
    text = title.axes[0].get_title()
    assert not CONTROL.search(text) and "\\x1b]0;PWNED TITLE" in text
